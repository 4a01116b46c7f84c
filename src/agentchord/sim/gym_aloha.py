"""LeRobot's gym-aloha as a World: its environment unmodified, stepped as its own ``env.step`` steps it.

gym-aloha (the simulation ACT and LeRobot's ALOHA policies are measured on) builds its physics from
its own MJCF with dm_control, draws each episode's object poses from the seed with its own sampler,
and judges success by its own reward (4 = done). :class:`GymAlohaWorld` drives that very physics:

- **reset** as ``AlohaEnv.reset(seed)`` does (its task's random state seeded, its sampler's pose
  in its ``BOX_POSE``, its task's ``initialize_episode``), without the three camera renders its
  observation makes;
- **step** as ``dm_control``'s ``Environment.step`` does: the task's ``before_step`` with the
  14-number action (absolute joint targets and its normalised gripper, 1 = open), the physics
  stepped its 10 substeps of 2 ms, ``after_step``, then its reward. The substeps are stepped one
  by one (the same ``mj_step1``/``mj_step2`` sequence) so that a person's hand can act between them.

Nothing of its model is edited: its gains, joint friction, integrator and cones stay its own
(:mod:`agentchord.robot.model` edits a copy of the same arm files for our own simulator). The
world reports the robot's signals our executor reads (tool poses from the gripper link, finger
gap, contact grasps) and the objects' true poses, under our names for them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX, FINGER_GAP_OFFSET, FINGER_RANGE, HOME_Q, TCP_OFFSET
from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.sim.world import SimWorld
from agentchord.worlds.protocol import ArmCommand

#: gym-aloha's normalised gripper: position = normalised * (OPEN - CLOSE) + CLOSE (m), 1 = open.
PUPPET_GRIPPER_OPEN = 0.058
PUPPET_GRIPPER_CLOSE = 0.01844
#: Its reward when the task is done.
SUCCESS_REWARD = 4
#: Steps LeRobot evaluates a policy for (8 s at 50 Hz); gymnasium's registered limit is 300.
LEROBOT_EVAL_STEPS = 400


@dataclass(frozen=True)
class GymAlohaTask:
    """One of gym-aloha's tasks, as this world sees it.

    Attributes:
        env_task: The task's name in ``gym_aloha.env.AlohaEnv`` (``transfer_cube``, ``insertion``).
        gym_id: Its gymnasium id.
        objects: Our name of each object -> its body in gym-aloha's model.
        notes: What the agents are told of its scene beyond poses and sizes (``Scene.notes``).
    """

    env_task: str
    gym_id: str
    objects: dict[str, str]
    notes: str = ""


TRANSFER_CUBE = GymAlohaTask(
    "transfer_cube", "gym_aloha/AlohaTransferCube-v0", {"cube": "box"},
    notes="gym-aloha's Transfer Cube: its own reward judges the episode: the cube counts as handed to the left arm once a "
          "left finger touches it while it is off the table, within 400 steps (8 s at 50 Hz).",
)
INSERTION = GymAlohaTask(
    "insertion", "gym_aloha/AlohaInsertion-v0", {"peg": "peg", "socket": "socket"},
    notes="gym-aloha's Insertion: the socket is a square tube 12 cm long along its long axis (extent[0]), open at both "
          "ends, a 3.6 cm bore around a red pin 8 cm long at its middle; the 2 x 2 cm peg goes in along that axis, in "
          "mid-air, each held by one arm, and counts as inserted once it touches the pin (2 cm past an opening).",
)


def gripper_normalised(grip: float) -> float:
    """gym-aloha's normalised gripper action (1 = open) of our gripper command (0 = open, 1 = closed).

    Both end at the same finger joint target: ours maps the command onto the finger range, its
    action is a puppet-gripper position that its actuator clips to that range.
    """
    lo, hi = FINGER_RANGE
    q = hi - float(grip) * (hi - lo)
    return (q - PUPPET_GRIPPER_CLOSE) / (PUPPET_GRIPPER_OPEN - PUPPET_GRIPPER_CLOSE)


def gym_action(commands: dict[str, ArmCommand]) -> np.ndarray:
    """The 14-number action of gym-aloha (left arm's 6 joints and gripper, then the right arm's)."""
    parts: list[float] = []
    for arm in ("left", "right"):
        parts += [float(v) for v in commands[arm].q]
        parts.append(gripper_normalised(commands[arm].grip))
    return np.asarray(parts, dtype=np.float64)


def assets_dir() -> Path:
    """The folder of gym-aloha's model files, as installed."""
    import gym_aloha

    return Path(gym_aloha.__file__).parent / "assets"


class GymAlohaWorld(SimWorld):
    """gym-aloha's environment of one task and seed as a World (with ground truth and disturbances).

    Args:
        task: Which of its tasks.
        seed: The episode's seed, as ``env.reset(seed=seed)`` takes it.

    Attributes:
        reward: Its reward after the last step (0 before the first).
        best_reward: The highest reward so far.
        first_success_tick: The first step after which its reward was 4 (None: not yet).
        disturbed: Whether a disturbance has acted on it this episode.
        actions: Every action sent this episode, in order (what ``env.step`` would be given).
        action: The last 14-number action sent to it.
    """

    def __init__(self, task: GymAlohaTask, seed: int) -> None:
        from gym_aloha.env import AlohaEnv  # its dm_control environment: built here, never rendered

        self.gym_task = task
        self.seed = seed
        self.scene_notes = task.notes
        self.env = AlohaEnv(task=task.env_task)
        self.physics = self.env._env.physics
        self.model = self.physics.model.ptr
        self.data = self.physics.data.ptr
        self.substeps = int(self.env._env._n_sub_steps)
        m = self.model
        self.scene = SceneSpec(objects=[self._object_spec_of(name, body) for name, body in task.objects.items()], timestep=m.opt.timestep)
        self._arm_qadr = {a: np.array([m.joint(f"{p}/{j}").qposadr[0] for j in ARM_JOINTS]) for a, p in ARM_PREFIX.items()}
        self._arm_dofadr = {a: np.array([m.joint(f"{p}/{j}").dofadr[0] for j in ARM_JOINTS]) for a, p in ARM_PREFIX.items()}
        self._finger_qadr = {a: m.joint(f"{p}/left_finger").qposadr[0] for a, p in ARM_PREFIX.items()}
        self._finger_geoms = {
            a: (m.geom(f"{p}/10_left_gripper_finger").id, m.geom(f"{p}/10_right_gripper_finger").id) for a, p in ARM_PREFIX.items()
        }
        self._gripper_body = {a: m.body(f"{p}/gripper_link").id for a, p in ARM_PREFIX.items()}
        self._object_body = {name: m.body(body).id for name, body in task.objects.items()}
        self._object_geoms = {
            name: frozenset(int(g) for g in np.nonzero(m.geom_bodyid == m.body(body).id)[0]) for name, body in task.objects.items()
        }
        self._object_spec = {o.name: o for o in self.scene.objects}
        self._cloth_points = {}
        self._cloth_vert0 = 0
        self._finger_cloth_contacts = {}
        self.reward = 0
        self.action = np.zeros(14)
        self.reset()

    def _object_spec_of(self, name: str, body: str) -> ObjectSpec:
        """What the task knows of an object, read from its model: a box, or a compound of boxes."""
        m = self.model
        body_id = m.body(body).id
        geoms = [int(g) for g in np.nonzero(m.geom_bodyid == body_id)[0]]
        lows = np.min([m.geom_pos[g] - m.geom_size[g] for g in geoms], axis=0)
        highs = np.max([m.geom_pos[g] + m.geom_size[g] for g in geoms], axis=0)
        half = 0.5 * (highs - lows)
        parts = tuple((tuple(m.geom_size[g]), tuple(m.geom_pos[g])) for g in geoms) if len(geoms) > 1 else ()
        rgba = tuple(float(v) for v in m.geom_rgba[geoms[0]])
        return ObjectSpec(name=name, shape="box", size=tuple(float(v) for v in half), mass=float(m.body_mass[body_id]),
                          pos=(0.0, 0.0), rgba=rgba, friction=float(m.geom_friction[geoms[0]][0]), parts=parts)  # type: ignore[arg-type]

    # ------------------------------------------------------------------ set-up
    def reset(self) -> None:
        """Its ``env.reset(seed)``: the task's random state seeded, its sampler's object poses, its start pose."""
        from gym_aloha.tasks import sim as gym_sim
        from gym_aloha.utils import sample_box_pose, sample_insertion_pose

        gym_task = self.env._env.task
        gym_task.random.seed(self.seed)
        gym_task._random = np.random.RandomState(self.seed)
        if self.gym_task.env_task == "transfer_cube":
            gym_sim.BOX_POSE[0] = sample_box_pose(self.seed)
        else:
            gym_sim.BOX_POSE[0] = np.concatenate(sample_insertion_pose(self.seed))
        with self.physics.reset_context():
            gym_task.initialize_episode(self.physics)
        self.env._env._reset_next_step = False
        self.env._env._step_count = 0
        self._fault_until: dict[str, int] = {}
        self._push_until: dict[int, int] = {}
        self._hands = []
        # Its start pose: the arms at home; the grippers, which its reset leaves nearly closed, are
        # commanded open from the first step (our robot's rest state).
        self.commands = {arm: ArmCommand(q=HOME_Q.copy(), grip=0.0) for arm in ARM_PREFIX}
        self.tick = 0
        self.reward = 0
        self.best_reward = 0
        self.first_success_tick: int | None = None
        self.disturbed = False
        self.actions: list[np.ndarray] = []
        self._contacts = {(a, b) for a, b in self.data.contact.geom[: self.data.ncon].tolist()}

    # ----------------------------------------------------------------- control
    def _apply_commands(self) -> None:
        commands = dict(self.commands)
        for arm in commands:
            if self.gripper_faulted(arm):
                commands[arm] = ArmCommand(q=commands[arm].q, grip=0.0)
        self.action = gym_action(commands)

    def step(self) -> None:
        """One of its control steps: ``before_step``, its substeps (a person's hand acting between them), ``after_step``."""
        self._apply_commands()
        gym_task = self.env._env.task
        self.actions.append(self.action.copy())
        gym_task.before_step(self.action, self.physics)
        for _ in range(self.substeps):
            for hand in self._hands:
                hand.apply(self.model.opt.timestep)
            self.physics.step(1)
        gym_task.after_step(self.physics)
        self._after_step()
        self.reward = int(gym_task.get_reward(self.physics))
        self.best_reward = max(self.best_reward, self.reward)
        if self.reward == SUCCESS_REWARD and self.first_success_tick is None:
            self.first_success_tick = self.tick

    # ------------------------------------------------------------ disturbances
    # The protocols' disturbances act on its physics as on ours (forces, a person's hand, a gripper
    # fault); the world notes that one came, for the judge's step limit.
    def inject_gripper_fault(self, arm: str, ticks: int) -> None:
        """Force ``arm``'s gripper open (the drop disturbance)."""
        self.disturbed = True
        super().inject_gripper_fault(arm, ticks)

    def push(self, obj: str, force: np.ndarray, ticks: int) -> None:
        """Slide an object by a force at table height."""
        self.disturbed = True
        super().push(obj, force, ticks)

    def knock(self, obj: str, direction: np.ndarray, ticks: int = 6) -> None:
        """Knock an object over."""
        self.disturbed = True
        super().knock(obj, direction, ticks)

    def hand_carry(self, obj: str, waypoints, out_of: str | None = None):
        """A person's hand takes ``obj`` (out of a gripper) and sets it down elsewhere."""
        self.disturbed = True
        return super().hand_carry(obj, waypoints, out_of)

    # ------------------------------------------------------------------ state
    def tcp_pose(self, arm: str) -> tuple[np.ndarray, np.ndarray]:
        """The tool centre: :data:`TCP_OFFSET` along the gripper link's x axis (where our own model puts its site)."""
        body = self._gripper_body[arm]
        rot = self.data.xmat[body].reshape(3, 3).copy()
        return self.data.xpos[body] + TCP_OFFSET * rot[:, 0], rot

    def gripper_width(self, arm: str) -> float:
        """Gap between the finger pads (m), as in our own model (the same finger geometry)."""
        q = self.data.qpos[self._finger_qadr[arm]] - self.data.qpos[self._finger_qadr[arm] + 1]
        return float(max(q - FINGER_GAP_OFFSET, 0.0))

    def on_table(self, obj: str) -> bool:
        """Whether the object touches its table (a mesh geom named ``table``)."""
        table = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "table")
        return self._touches(table, self._object_geoms[obj])

    @property
    def success(self) -> bool:
        """Its own verdict: reward == :data:`SUCCESS_REWARD`."""
        return self.reward == SUCCESS_REWARD
