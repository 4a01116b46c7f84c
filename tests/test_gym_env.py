"""The Gymnasium environments: registered on import, pass gymnasium's checker, same seed same episode."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import agentchord.gym
from agentchord.gym.aloha import joint_action
from agentchord.gym.env import AgentChordEnv, disturbance_setting
from agentchord.sim.tasks import SIM_TASKS


def test_every_task_is_registered() -> None:
    assert sorted(agentchord.gym.ENV_IDS.values()) == sorted(SIM_TASKS)
    assert "agentchord/SingleArmPourWater-v0" in gymnasium.registry


@pytest.mark.parametrize("env_id", sorted(agentchord.gym.ENV_IDS))
def test_env_checker_passes(env_id: str) -> None:
    env = gymnasium.make(env_id, disturb="stress")
    try:
        check_env(env.unwrapped, skip_render_check=True)
    finally:
        env.close()


def test_env_checker_passes_with_images_and_render() -> None:
    env = gymnasium.make("agentchord/SingleArmPourWater-v0", obs_type="pixels_state", cameras=("top", "right_wrist"),
                         image_size=(48, 64), render_mode="rgb_array")
    try:
        check_env(env.unwrapped)
        obs, _ = env.reset(seed=1)
        assert obs["pixels"]["top"].shape == (48, 64, 3) and obs["pixels"]["top"].dtype == np.uint8
        assert obs["pixels"]["top"].std() > 0  # not a blank image
        assert env.render().shape == (48, 64, 3)
    finally:
        env.close()


def _rollout(seed: int, steps: int, disturb=None, window=(60, 650)) -> tuple[np.ndarray, dict]:
    env = AgentChordEnv("single_arm_pour_water", disturb=disturb, window=window)
    obs, info = env.reset(seed=seed)
    hold = obs["agent_pos"].copy()
    states = []
    for _ in range(steps):
        obs, _, _, _, info = env.step(hold)
        states.append(np.concatenate([obs["agent_pos"], obs["environment_state"]]))
    env.close()
    return np.array(states), info


def test_same_seed_same_episode_and_scenes_differ_by_seed() -> None:
    a, _ = _rollout(4, 30)
    b, _ = _rollout(4, 30)
    c, _ = _rollout(5, 30)
    assert np.array_equal(a, b)
    assert not np.allclose(a[:, 14:], c[:, 14:])


def test_a_shift_disturbance_moves_an_object_at_its_seeded_moment() -> None:
    quiet, _ = _rollout(2, 80)
    moved, info = _rollout(2, 80, disturb="shift", window=(10, 20))
    kinds = [e["kind"] for e in info["disturbances"]]
    assert kinds and set(kinds) == {"shift"}  # one or two, as the protocol draws them
    assert np.abs(moved[-1, 14:] - quiet[-1, 14:]).max() > 0.02


def test_disturbance_setting() -> None:
    assert disturbance_setting(None) is None
    real = disturbance_setting("real", (10, 20))
    assert (real.kinds, real.protocol, real.window) == (("perturb", "pull"), "real", (10, 20))
    assert disturbance_setting("drop,shift").kinds == ("drop", "shift") == disturbance_setting(["drop", "shift"]).kinds
    assert disturbance_setting("drop,shift").protocol == "custom"
    with pytest.raises(ValueError):
        disturbance_setting("teleport")


def test_replaying_an_agentchord_episode_succeeds_in_the_env() -> None:
    """The env's scene and physics are the episode's: its commands, replayed, succeed there too."""
    from agentchord.episode import EpisodeSpec, run_episode

    actions = []
    result = run_episode(EpisodeSpec(task="single_arm_pour_water", seed=0),
                         on_tick=lambda ex: actions.append(joint_action(ex.world.commands)))
    assert result.success
    env = AgentChordEnv("single_arm_pour_water", max_steps=len(actions) + 200)
    env.reset(seed=0)
    terminated = False
    for action in actions:
        _, reward, terminated, truncated, info = env.step(action)
        if terminated:
            break
    env.close()
    assert terminated and reward == 1.0 and info["is_success"]


@pytest.mark.parametrize(("action", "message"), [
    (np.zeros(13), r"action must have shape \(14,\) \(the action space: Box\(14,\) of float32"),
    (np.zeros((2, 14)), r"action must have shape \(14,\)"),
    (np.full(14, np.nan), "action must be finite: left_waist, left_shoulder"),
    ([0.0] * 13 + [float("inf")], "action must be finite: right_gripper is inf"),
    (["open"] * 14, "action must be 14 numbers"),
    (None, "action must have shape"),
])
def test_an_action_outside_the_action_space_is_a_clear_error(action, message) -> None:
    env = AgentChordEnv("single_arm_pour_water")
    try:
        env.reset(seed=0)
        with pytest.raises(ValueError, match=message):
            env.step(action)
        assert env.world.tick == 0  # refused before anything moved
        obs, *_ = env.step(np.clip(np.zeros(14), env.action_space.low, env.action_space.high))
        assert np.all(np.isfinite(obs["agent_pos"])) and env.world.tick == 1
    finally:
        env.close()


@pytest.mark.parametrize("kwargs,field", [
    ({"max_steps": None}, "max_steps"), ({"max_steps": "10"}, "max_steps"), ({"max_steps": 0}, "max_steps"),
    ({"max_steps": True}, "max_steps"), ({"image_size": (0, 0)}, "image_size"), ({"image_size": (240,)}, "image_size"),
    ({"disturb": 42}, "disturb"),
])
def test_bad_arguments_are_refused_at_construction_naming_the_argument(kwargs, field):
    """Each used to be accepted and fail later, at the first step or the first image (issue 58)."""
    with pytest.raises(ValueError, match=f"^{field}: expected"):
        AgentChordEnv("single_arm_pour_water", **kwargs)


def test_human_rendering_without_pygame_is_refused_at_make(monkeypatch):
    """Issue 58: ``render_mode="human"`` was accepted by ``make``, then ``reset`` failed for want of pygame."""
    import sys

    import gymnasium

    import agentchord.gym  # noqa: F401 -- registers the ids

    monkeypatch.setitem(sys.modules, "pygame", None)  # as if not installed: importing it raises ImportError
    with pytest.raises(gymnasium.error.DependencyNotInstalled, match="render_mode='rgb_array'"):
        gymnasium.make("agentchord/BlocksAndCup-v0", render_mode="human")


@pytest.mark.parametrize(("kwargs", "message"), [({"cameras": "top"}, "cameras: expected a tuple"),
                                                 ({"image_size": (100_000, 100_000)}, "each from 1 to 4096"),
                                                 ({"disturb": ""}, "disturb: expected")])
def test_more_careless_arguments_are_refused_at_construction(kwargs, message):
    """An adversarial pass (issue 58): a camera name as a string was read letter by letter, a huge image was a
    MemoryError, and an empty disturb was taken as none."""
    from agentchord.gym.env import AgentChordEnv

    with pytest.raises(ValueError, match=message):
        AgentChordEnv("single_arm_pour_water", **kwargs)


def test_one_conversion_between_the_worlds_grip_and_the_gym_opening():
    """Issue 61: docs/world_protocol.md said 0 open .. 1 closed, the Gymnasium environments 0 closed .. 1 open;
    the two now meet in one named conversion, which the environments use both ways."""
    import numpy as np

    from agentchord.gym.aloha import arm_commands, joint_action
    from agentchord.worlds.protocol import ArmCommand, gripper_grip, gripper_opening

    assert gripper_opening(1.0) == 0.0 and gripper_opening(0.0) == 1.0 and gripper_grip(gripper_opening(0.3)) == pytest.approx(0.3)
    assert gripper_grip(1.5) == 0.0 and gripper_grip(-1.0) == 1.0  # clipped
    commands = {"left": ArmCommand(q=np.zeros(6), grip=1.0), "right": ArmCommand(q=np.zeros(6), grip=0.25)}
    action = joint_action(commands)
    assert action[6] == 0.0 and action[13] == 0.75  # closed -> opening 0
    back = arm_commands(action)
    assert back["left"].grip == 1.0 and back["right"].grip == 0.25
