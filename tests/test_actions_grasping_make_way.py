"""Making way: a free arm steps back towards its shoulder, out of the other arm's way."""

import numpy as np
import pytest

from agentchord.harness import DisturbanceSetting
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.make_way import NEAREST_TO_SHOULDER, STEP_BACK, make_way, step_back_pose
from agentchord.features.oracle import OracleExtractor
from agentchord.solvers.ik import PoseTarget
from agentchord.sim.world import SimWorld


@pytest.fixture
def robot(pour_scene):
    world = SimWorld(pour_scene)
    robot = RobotController(world)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: robot.targets[arm].grip_closed_settled)
    robot.frame = extractor.frame
    robot.extractor = extractor  # the tests step the world through it
    return robot


def _reach(robot, arm):
    pos = robot.commanded_pose(arm).pos
    return float(np.linalg.norm(pos[:2] - robot.world.arm_base(arm)[:2]))


def _command(robot, arm, pos):
    robot.set_pose(arm, PoseTarget(pos=np.asarray(pos, dtype=float), quat=robot.commanded_pose(arm).quat))


def _drive(robot, script):
    """Run a generator to its end, a tick per yield; its return value."""
    while True:
        try:
            next(script)
        except StopIteration as stop:
            return stop.value
        robot.step()
        robot.extractor.update()


def test_the_step_back_goes_towards_the_shoulder_at_the_same_height_and_orientation(robot):
    _command(robot, "left", [-0.06, 0.55, 0.11])
    before = robot.commanded_pose("left")
    goal = step_back_pose(robot, "left")
    assert goal is not None
    assert _reach(robot, "left") - float(np.linalg.norm(goal.pos[:2] - robot.world.arm_base("left")[:2])) == pytest.approx(STEP_BACK)
    assert goal.pos[2] == pytest.approx(before.pos[2])
    np.testing.assert_allclose(goal.quat, before.quat)
    # Straight back: the horizontal move points at the shoulder.
    towards = robot.world.arm_base("left")[:2] - before.pos[:2]
    moved = goal.pos[:2] - before.pos[:2]
    assert float(np.dot(towards, moved)) == pytest.approx(np.linalg.norm(towards) * np.linalg.norm(moved))


def test_the_step_back_stops_short_of_the_shoulder_and_is_skipped_where_it_would_free_nothing(robot):
    base = robot.world.arm_base("left")
    _command(robot, "left", [base[0] + NEAREST_TO_SHOULDER + 0.05, base[1], 0.15])
    goal = step_back_pose(robot, "left")
    assert goal is not None
    assert float(np.linalg.norm(goal.pos[:2] - base[:2])) == pytest.approx(NEAREST_TO_SHOULDER)
    _command(robot, "left", [base[0] + NEAREST_TO_SHOULDER + 0.01, base[1], 0.15])
    assert step_back_pose(robot, "left") is None


def test_an_arm_running_an_action_of_its_own_is_not_moved(robot):
    _command(robot, "left", [-0.06, 0.55, 0.15])
    before = robot.commanded_pose("left").pos.copy()
    robot.free_arms = frozenset({"right"})  # the left arm is busy
    assert _drive(robot, make_way(robot, "right", back_off=robot.commanded_pose("right"))) is False
    np.testing.assert_allclose(robot.commanded_pose("left").pos, before)


def test_an_arm_the_collision_limit_holds_still_is_not_moved(robot, monkeypatch):
    # Proxies already overlapping (a bottle caught on the right hand at home, reached for by the
    # left arm): the collision limit holds both arms still, so a step back would only cost time.
    _command(robot, "left", [-0.06, 0.55, 0.15])
    before = robot.commanded_pose("left").pos.copy()
    robot.free_arms = frozenset({"left"})
    monkeypatch.setattr(robot.ik, "arm_clearance", lambda: -0.04)
    assert _drive(robot, make_way(robot, "right", back_off=robot.commanded_pose("right"))) is False
    np.testing.assert_allclose(robot.commanded_pose("left").pos, before)


def test_a_free_arm_steps_back_after_the_blocked_arm_backs_off(robot):
    _command(robot, "left", [-0.06, 0.55, 0.15])
    for _ in range(150):
        robot.step()
        robot.extractor.update()
    goal = step_back_pose(robot, "left")
    back_off = robot.commanded_pose("right")
    back_off.pos[2] += 0.05
    robot.free_arms = frozenset({"left"})
    assert _drive(robot, make_way(robot, "right", back_off=back_off)) is True
    np.testing.assert_allclose(robot.commanded_pose("left").pos, goal.pos, atol=1e-9)
    np.testing.assert_allclose(robot.commanded_pose("right").pos, back_off.pos, atol=1e-9)
    assert float(np.linalg.norm(robot.frame.arms["left"].ee - goal.pos)) < 0.01


def _episode(task, seed, protocol, monkeypatch, switched_off=None):
    """Run a protocol episode, with a make_way helper (as the grasp calls it) switched off."""
    from agentchord.actions import grasp as grasp_module
    from agentchord.episode import EpisodeSpec, run_episode

    if switched_off is not None:
        def never(*args, **kwargs):
            return False
            yield

        monkeypatch.setattr(grasp_module, switched_off, never)
    return run_episode(EpisodeSpec(task, seed=seed, disturbances=DisturbanceSetting.from_options(protocol=protocol)))


@pytest.mark.usefixtures("numerics_before_lean_solves")
@pytest.mark.parametrize("makes_way", [True, False])
def test_a_regrasp_held_back_by_the_idle_arm_has_it_step_back(makes_way, monkeypatch):
    # Stress protocol, dual-arm pour, seed 26: the bottle knocked over during the first grasp lies
    # beside the cup the left arm holds. The right arm's fallen grasp is held back by the left arm
    # (the collision limit), every attempt. With the left arm's part of the step done, it steps back
    # towards its shoulder, cup in hand, and the right arm takes the bottle.
    result = _episode("dual_arm_pour_water", 26, "stress", monkeypatch, None if makes_way else "make_way")
    if makes_way:
        assert result.success, result.reason
    else:
        assert not result.success and "the other arm was in the way of the grasp of bottle" in result.reason
