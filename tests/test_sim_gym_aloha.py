"""gym-aloha as a World: its own model, reset, stepping and reward, and our episodes in it."""

from __future__ import annotations

import base64
import hashlib
import os
from pathlib import Path

import mujoco
import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")  # its env.step renders three cameras: headless

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.library import load_task_graph
from agentchord.sim.gym_aloha import (
    INSERTION,
    SUCCESS_REWARD,
    TRANSFER_CUBE,
    GymAlohaWorld,
    assets_dir,
    gripper_normalised,
)
from agentchord.sim.trial import open_world


def _record() -> dict[str, str]:
    """gym-aloha's installed files and their sha256 as its wheel's RECORD lists them."""
    import gym_aloha

    site = Path(gym_aloha.__file__).parents[1]
    record = next(site.glob("gym_aloha-*.dist-info")) / "RECORD"
    rows = (line.split(",") for line in record.read_text().splitlines() if line)
    return {path: digest for path, digest, *_ in rows if digest.startswith("sha256=")}


def test_the_model_files_we_load_are_the_packages_byte_for_byte():
    record = _record()
    files = sorted(assets_dir().iterdir())
    assert any(f.name == "bimanual_viperx_insertion.xml" for f in files)
    for path in files:
        digest = base64.urlsafe_b64encode(hashlib.sha256(path.read_bytes()).digest()).rstrip(b"=").decode()
        assert record[f"gym_aloha/assets/{path.name}"] == f"sha256={digest}", path.name
    # The world's physics is the one its XML compiles to: its gains, friction, integrator, cones.
    world = GymAlohaWorld(TRANSFER_CUBE, 0)
    theirs = mujoco.MjModel.from_xml_path(str(assets_dir() / "bimanual_viperx_transfer_cube.xml"))
    ours = world.model
    for field in ("actuator_gainprm", "actuator_biasprm", "dof_frictionloss", "dof_damping", "body_mass", "geom_friction", "body_gravcomp"):
        assert np.array_equal(getattr(ours, field), getattr(theirs, field)), field
    assert (ours.opt.timestep, ours.opt.integrator, ours.opt.cone) == (theirs.opt.timestep, theirs.opt.integrator, theirs.opt.cone)
    assert world.substeps == 10


@pytest.mark.parametrize("task", [TRANSFER_CUBE, INSERTION])
def test_reset_is_its_own_reset_from_the_seed(task):
    from gym_aloha.env import AlohaEnv

    env = AlohaEnv(task=task.env_task)
    env.reset(seed=7)
    world = GymAlohaWorld(task, 7)
    assert np.array_equal(world.data.qpos, env._env.physics.data.qpos)
    assert world.tick == 0 and world.reward == 0 and world.first_success_tick is None


def test_our_gripper_command_lands_on_the_same_finger_target_as_its_action():
    from gym_aloha.constants import unnormalize_puppet_gripper_position

    assert unnormalize_puppet_gripper_position(gripper_normalised(0.0)) == pytest.approx(0.057)  # open
    assert unnormalize_puppet_gripper_position(gripper_normalised(1.0)) == pytest.approx(0.021)  # closed


def test_the_tasks_open_its_world_and_read_their_scene():
    world = open_world("gym_aloha_insertion", 3)
    assert isinstance(world, GymAlohaWorld) and world.object_names == ["peg", "socket"]
    assert "bore" in world.scene_notes
    socket = world.object_spec("socket")
    assert len(socket.parts) == 5 and socket.size[0] == pytest.approx(0.06)


@pytest.mark.parametrize("task", ["gym_aloha_transfer_cube", "gym_aloha_insertion"])
def test_the_library_graph_succeeds_by_its_reward_within_400_steps(task):
    result = run_episode(EpisodeSpec(task=task, seed=0, graph=load_task_graph(task)))
    assert result.success, result.reason
    assert result.steps <= 400 and f"reward {SUCCESS_REWARD} at step {result.steps}" in result.reason


@pytest.mark.slow
@pytest.mark.parametrize("task,gym_id", [("gym_aloha_transfer_cube", TRANSFER_CUBE.gym_id), ("gym_aloha_insertion", INSERTION.gym_id)])
def test_our_actions_replayed_through_its_own_env_step_reach_reward_4_at_the_same_step(task, gym_id):
    """The success is real in their environment: our episode's actions, through ``gymnasium.make`` and its
    ``env.step`` (its rendering and all), reach reward 4 on the very step our world did."""
    import gymnasium
    import gym_aloha  # noqa: F401  (registers its environments)

    worlds: list[GymAlohaWorld] = []
    result = run_episode(EpisodeSpec(task=task, seed=2, graph=load_task_graph(task)),
                         on_tick=lambda ex: worlds.append(ex.world) if not worlds else None)
    assert result.success, result.reason
    world = worlds[0]
    env = gymnasium.make(gym_id, max_episode_steps=1000)
    env.reset(seed=2)
    rewards = [env.step(action)[1] for action in world.actions]
    env.close()
    assert rewards.index(SUCCESS_REWARD) + 1 == world.first_success_tick == result.steps


@pytest.mark.parametrize("task,instruction,kinds", [
    ("gym_aloha_transfer_cube", "Pick up the cube with the right arm and hand it to the left arm.", ["handed_over", "placed"]),
    ("gym_aloha_transfer_cube", "Pass the cube from the right hand to the left hand.", ["handed_over", "placed"]),
    ("gym_aloha_transfer_cube", "With the right arm, grab the cube and give it to the left arm.", ["handed_over", "placed"]),
    ("gym_aloha_insertion", "Insert the peg into the socket.", ["inserted"]),
    ("gym_aloha_insertion", "Put the peg in the socket.", ["inserted"]),
    ("gym_aloha_insertion", "Slide the red peg into the blue socket.", ["inserted"]),
])
def test_the_offline_planner_plans_both_tasks_from_plain_instructions(task, instruction, kinds):
    from agentchord.agents.observe import observe
    from agentchord.agents.pipeline import make_reasoner, plan_task

    scene = observe(open_world(task, 0))
    reasoner = make_reasoner("rules")
    result = plan_task(instruction, scene, reasoner, task=task)
    assert [g.kind for g in reasoner.last_goal.goals] == kinds
    actions = [call.fn for edge in result.nominal.edges for _, call in edge.calls]
    assert ("insert" in actions) == (kinds == ["inserted"])


@pytest.mark.parametrize("task,instruction", [
    ("gym_aloha_transfer_cube", "Pick up the cube with the right arm and hand it to the left arm."),
    ("gym_aloha_insertion", "Insert the peg into the socket."),
])
def test_an_offline_plan_succeeds_by_its_reward(task, instruction):
    result = run_episode(EpisodeSpec(task=task, seed=1, instruction=instruction))
    assert result.success, result.reason


def test_a_gym_aloha_task_is_not_served_over_the_world_protocol_which_cannot_carry_its_reward():
    from click.testing import CliRunner

    from agentchord.cli import main

    result = CliRunner().invoke(main, ["run", "gym_aloha_transfer_cube", "--world", "tcp://127.0.0.1:5599"])
    assert result.exit_code == 2 and "judged by gym-aloha's own reward" in result.output
    served = CliRunner().invoke(main, ["serve", "--task", "gym_aloha_insertion"])
    assert served.exit_code == 2 and "the world protocol cannot carry it" in served.output


@pytest.mark.parametrize("args", [
    ["run", "gym_aloha_transfer_cube", "--video", "v.mp4", "--camera", "angle"],
    ["run", "gym_aloha_insertion", "--perception", "rgbd"],
    ["demo", "--task", "gym_aloha_insertion", "--perception", "rgbd"],
    ["record", "gym_aloha_transfer_cube", "--out", "ds"],
    ["run", "gym_aloha_transfer_cube", "--rerun", "x.rrd"],  # it crashed the process (a segfault) in its GL context
])
def test_rendering_its_cameras_is_refused_with_a_reason_not_a_crash(args, tmp_path, monkeypatch):
    from click.testing import CliRunner

    from agentchord.cli import main

    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2 and "cannot render yet" in result.output, result.output


@pytest.mark.parametrize("kwargs", [{"obs_type": "pixels_state"}, {"render_mode": "rgb_array"}])
def test_its_gymnasium_environment_refuses_images_at_make_not_with_a_crash_at_reset(kwargs):
    import gymnasium

    import agentchord.gym  # noqa: F401 -- registers the ids

    with pytest.raises(ValueError, match="cannot be rendered here yet"):
        gymnasium.make("agentchord/GymAlohaTransferCube-v0", **kwargs)
    assert gymnasium.make("agentchord/GymAlohaTransferCube-v0").reset(seed=0)[0]["agent_pos"].shape == (14,)
