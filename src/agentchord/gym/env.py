"""A Gymnasium environment per simulated task: ALOHA-style observations and joint-position actions.

The same seeded scenes as ``agentchord run`` (``reset(seed=s)`` opens trial ``s``), the same
disturbance kinds on the paper's protocol schedule (one or two at seeded moments), success from
the task's own check. One ``step`` is one 50 Hz control tick.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from agentchord.features.extractors import make_extractor
from agentchord.gym.aloha import JOINT_NAMES, arm_commands, environment_state, joint_state
from agentchord.gym.cameras import RgbCameras
from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX
from agentchord.worlds.protocol import CONTROL_HZ
from agentchord.harness import PRESETS, PROTOCOL_WINDOW, Disturbance, DisturbanceSetting
from agentchord.sim.disturbances import schedule
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world

#: Observation types: ``state`` (joint state and the objects' poses) and ``pixels_state`` (and camera images).
OBS_TYPES = ("state", "pixels_state")
#: Bound of the state entries' boxes (rad, m, quaternion components: all far inside it).
STATE_BOUND = 10.0


def disturbance_setting(disturb, window: tuple[int, int] = PROTOCOL_WINDOW) -> DisturbanceSetting | None:
    """``None`` -> None (undisturbed); a preset (``real``, ``stress``), ``"drop,shift"`` or a sequence of
    kinds -> the protocol setting (1-2 disturbances per trial within ``window``), as ``--protocol`` makes it.

    Raises:
        ValueError: An unknown kind.
    """
    if not disturb:
        return None
    if isinstance(disturb, str) and disturb in PRESETS:
        return DisturbanceSetting.from_options(protocol=disturb, window=window)
    return DisturbanceSetting.from_options(disturb=disturb, protocol="custom", window=window)


#: The largest image side (pixels) the environments render: a bigger frame is a mistake, not a camera.
MAX_IMAGE_SIDE = 4096


class AgentChordEnv(gym.Env):
    """One simulated task as a Gymnasium environment.

    Observation (a dict): ``agent_pos`` (14,) float32, the ALOHA joint state (see ``gym.aloha``);
    ``environment_state`` (7 per object,) float32, the objects' positions and quaternions; with
    ``obs_type="pixels_state"`` also ``pixels``: one (H, W, 3) uint8 image per camera.
    Action: (14,) float32 joint-position targets (rad) and gripper openings (0 closed, 1 open).
    Reward 1 on the tick the task's success check first holds, which ends the episode.

    Args:
        task: A simulated task (``agentchord tasks``).
        disturb: Disturbance kinds on the protocol schedule: None (undisturbed), a preset
            (``real``, ``stress``), ``"shift"``, ``"drop,pull"`` ... The moments are drawn from
            the reset seed, as ``agentchord run --protocol`` draws them.
        window: Range of ticks the disturbance moments are drawn from.
        obs_type: ``state`` or ``pixels_state``.
        cameras: Scene cameras of ``pixels`` (and the first one renders ``render()``).
        image_size: (height, width) of the images.
        max_steps: Ticks before the episode is truncated.
        render_mode: None or ``rgb_array``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": CONTROL_HZ}

    def __init__(self, task: str, disturb=None, window: tuple[int, int] = PROTOCOL_WINDOW, obs_type: str = "state",
                 cameras: tuple[str, ...] = ("top",), image_size: tuple[int, int] = (240, 320), max_steps: int = 2000,
                 render_mode: str | None = None) -> None:
        if task not in SIM_TASKS:
            raise KeyError(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})")
        if obs_type not in OBS_TYPES:
            raise ValueError(f"unknown obs_type {obs_type!r} (choose from: {', '.join(OBS_TYPES)})")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"unknown render_mode {render_mode!r} (rgb_array or None)")
        # What a careless caller passes fails here, named, not at the first step (issue 58).
        if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
            raise ValueError(f"max_steps: expected a whole number of ticks >= 1, got {max_steps!r}")
        if (not isinstance(image_size, (tuple, list)) or len(image_size) != 2
                or not all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= MAX_IMAGE_SIDE for v in image_size)):
            raise ValueError(f"image_size: expected (height, width) in pixels, each from 1 to {MAX_IMAGE_SIDE}, got {image_size!r}")
        if isinstance(cameras, str) or not isinstance(cameras, (tuple, list)) or not all(isinstance(c, str) for c in cameras):
            raise ValueError(f"cameras: expected a tuple of camera names, e.g. ('top',), got {cameras!r}")
        if disturb is not None and (not isinstance(disturb, str) or not disturb.strip()):
            raise ValueError(f"disturb: expected None, a protocol ('real', 'stress') or kinds ('drop,pull'), got {disturb!r}")
        if (obs_type == "pixels_state" or render_mode is not None) and hasattr(SIM_TASKS[task], "open_world"):
            # Its dm_control physics keeps its own GL context: rendering it through ours crashes the process.
            raise ValueError(f"{task} runs in gym-aloha's own physics, whose cameras cannot be rendered here yet: "
                             "use obs_type='state' and render_mode=None (or gym-aloha's own environment for images)")
        self.task = task
        self.disturbances = disturbance_setting(disturb, window)
        self.obs_type = obs_type
        self.cameras = tuple(cameras)
        self.image_size = image_size
        self.max_steps = max_steps
        self.render_mode = render_mode
        self.world = open_world(task, 0)
        self.world_seed = 0
        self._images: RgbCameras | None = None
        self._render_camera: RgbCameras | None = None
        self.disturbance: Disturbance | None = None
        self.tracker = None
        self.extractor = None
        self.success = False
        ranges = self.world.model.jnt_range
        low, high = [], []
        for prefix in ARM_PREFIX.values():
            for joint in ARM_JOINTS:
                lo, hi = ranges[self.world.model.joint(f"{prefix}/{joint}").id]
                low.append(lo)
                high.append(hi)
            low.append(0.0)
            high.append(1.0)
        self.action_space = spaces.Box(np.asarray(low, np.float32), np.asarray(high, np.float32), dtype=np.float32)
        n_env = 7 * len(self.world.object_names)
        observation = {
            "agent_pos": spaces.Box(-STATE_BOUND, STATE_BOUND, (len(JOINT_NAMES),), np.float32),
            "environment_state": spaces.Box(-STATE_BOUND, STATE_BOUND, (n_env,), np.float32),
        }
        if obs_type == "pixels_state":
            h, w = image_size
            observation["pixels"] = spaces.Dict({c: spaces.Box(0, 255, (h, w, 3), np.uint8) for c in self.cameras})
        self.observation_space = spaces.Dict(observation)

    # ------------------------------------------------------------------ episode
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Open trial ``seed`` of the task (no seed: one drawn from the environment's generator)."""
        super().reset(seed=seed)
        trial = int(seed) if seed is not None else int(self.np_random.integers(0, 2**31 - 1))
        self._close_cameras()
        self.world = open_world(self.task, trial)
        self.world_seed = trial
        world = self.world
        self.extractor = make_extractor("oracle", world, lambda arm: world.commands[arm].grip >= 0.5)
        self.tracker = SIM_TASKS[self.task].success_tracker()
        self.disturbance = schedule(self.disturbances, trial) if self.disturbances is not None else None
        if self.disturbance is not None:
            for arm in ARM_PREFIX:  # no atomic actions here: either arm may be the one disturbed
                self.disturbance.action_started(arm, None, 0, 0)
        self.success = False
        self.events = []
        self.extractor.update()
        return self._observation(), self._info()

    def step(self, action):
        """One control tick with ``action`` as the arms' targets."""
        if self.extractor is None:
            raise RuntimeError("call reset() before step()")
        action = self._checked(action)
        for arm, command in arm_commands(action).items():
            self.world.command(arm, command)
        self.world.step()
        frame = self.extractor.update()
        self.tracker.observe(frame)
        if self.disturbance is not None:
            event = self.disturbance.apply(self.world, frame)
            if event is not None:
                self.events.append(event)
        was = self.success
        self.success = bool(self.tracker.verdict(frame, self.world).success)
        reward = 1.0 if self.success and not was else 0.0
        terminated = self.success
        truncated = not terminated and self.world.tick >= self.max_steps
        return self._observation(), reward, terminated, truncated, self._info()

    def _checked(self, action) -> np.ndarray:
        """``action`` as the space's float32 array (values beyond the bounds are passed on, as before).

        Raises:
            ValueError: Not numbers, another shape than the action space's, or NaN/infinite entries
                (which would make every later observation NaN).
        """
        shape = self.action_space.shape
        space = f"Box{shape} of float32, the arms' joint targets and grips"  # its repr lists every bound
        try:
            array = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"action must be {shape[0]} numbers (the action space: {space}), "
                             f"got {action!r:.80}") from None
        if array.shape != shape:
            raise ValueError(f"action must have shape {shape} (the action space: {space}), got shape "
                             f"{array.shape}")
        bad = ~np.isfinite(array)
        if bad.any():
            names = [JOINT_NAMES[k] for k in np.flatnonzero(bad)]
            more = f" and {len(names) - 3} more" if len(names) > 3 else ""
            raise ValueError(f"action must be finite: {', '.join(names[:3])}{more} {'is' if len(names) == 1 else 'are'} "
                             f"{array[bad][0]}")
        return np.asarray(action, dtype=np.float32)

    def _observation(self) -> dict:
        obs = {"agent_pos": joint_state(self.world), "environment_state": environment_state(self.world)}
        if self.obs_type == "pixels_state":
            if self._images is None:
                self._images = RgbCameras(self.world, self.cameras, self.image_size)
            obs["pixels"] = self._images.render()
        return obs

    def _info(self) -> dict:
        return {
            "is_success": self.success,
            "tick": self.world.tick,
            "seed": self.world_seed,
            "disturbances": [{"tick": e.tick, "kind": e.kind, "obj": e.obj, "arm": e.arm} for e in self.events],
        }

    def render(self):
        """An RGB image of the first camera (render_mode ``rgb_array``), else None."""
        if self.render_mode != "rgb_array":
            return None
        if self._render_camera is None:
            self._render_camera = RgbCameras(self.world, self.cameras[:1] or ("front",), self.image_size)
        return next(iter(self._render_camera.render().values()))

    def _close_cameras(self) -> None:
        for cams in (self._images, self._render_camera):
            if cams is not None:
                cams.close()
        self._images = self._render_camera = None

    def close(self) -> None:
        """Free the renderers."""
        self._close_cameras()


def make_env(task: str, render_mode: str | None = None, **kwargs) -> gym.Env:
    """The registered entry point: :class:`AgentChordEnv`, with ``render_mode="human"`` shown in a window.

    A human render is the ``rgb_array`` frames in a pygame window (gymnasium's ``HumanRendering``);
    without pygame it is refused here, at ``make``, not at the first ``reset``.

    Raises:
        gym.error.DependencyNotInstalled: ``render_mode="human"`` without pygame.
    """
    if render_mode != "human":
        return AgentChordEnv(task, render_mode=render_mode, **kwargs)
    try:
        import pygame  # noqa: F401 -- only whether it is there
    except ImportError:
        raise gym.error.DependencyNotInstalled(
            "render_mode='human' shows the frames in a pygame window, and pygame is not installed "
            "(pip install 'gymnasium[classic-control]'); or make the environment with render_mode='rgb_array' "
            "and show env.render()'s frames yourself") from None
    return gym.wrappers.HumanRendering(AgentChordEnv(task, render_mode="rgb_array", **kwargs))
