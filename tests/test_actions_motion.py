"""Motion primitives: an approach the live IK cannot follow goes round through home."""

import numpy as np
import pytest

from agentchord.actions import motion
from agentchord.actions.controller import RobotController
from agentchord.features.oracle import OracleExtractor
from agentchord.solvers.poses import top_down_rotation
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

#: The left arm's joints after a place's retreat was cut short (rearrange, stress seed 35): the
#: tool tilted 34 deg below level, pointing right and forward.
TILTED = np.array([0.16, -0.35, 0.68, 2.08, -0.88, -0.88])
#: Over the fork, top-down, the fingers across world y: from TILTED the wrist-rotate joint runs
#: into its limit on the way.
ABOVE_FORK = motion.pose_from_matrix(np.array([-0.09, 0.486, 0.127]), top_down_rotation(np.array([-0.02, 1.0, 0.0]) / np.hypot(0.02, 1.0)))


def _approach_from_tilted(clear=None) -> tuple[float, float, RobotController]:
    """Run the approach; returns the live IK's worst distance from the line, the tool's lowest height, the robot."""
    world = SimWorld(SIM_TASKS["rearrange_table"].sample_scene(np.random.default_rng(0)))
    robot = RobotController(world)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: robot.targets[arm].grip_closed_settled)
    robot.frame = extractor.frame

    def run(script):
        worst, lowest = 0.0, np.inf
        for _ in script:
            robot.step()
            extractor.update()
            worst = max(worst, robot.ik.residual("left", robot.commanded_pose("left")))
            lowest = min(lowest, float(robot.ik.tcp_pose("left").pos[2]))
        return worst, lowest

    run(motion.move_joints(robot, "left", TILTED))
    robot.set_pose("left", robot.ik.tcp_pose("left"))
    worst, lowest = run(motion.approach(robot, "left", ABOVE_FORK, clear=clear))
    return worst, lowest, robot


def test_an_approach_the_live_ik_loses_goes_round_through_home_and_ends_at_its_pose():
    worst, lowest, robot = _approach_from_tilted()
    assert worst < motion.LINE_LOST + 0.01  # stopped as soon as the line was lost
    assert lowest > ABOVE_FORK.pos[2] - 0.01  # never under the line (home is higher)
    assert np.linalg.norm(robot.frame.arms["left"].ee - ABOVE_FORK.pos) < motion.APPROACH_TOLERANCE


def test_a_detour_that_would_sweep_the_fingers_through_something_is_not_taken():
    seen = []

    def nothing_is_clear(tool_poses):
        seen.append(len(tool_poses))
        return False

    worst, lowest, _ = _approach_from_tilted(clear=nothing_is_clear)
    assert seen  # the detour was checked ...
    assert lowest < 0.03  # ... refused, and the line went on as it always did


def test_followed_to_the_end_the_lost_line_drives_the_tool_down_to_the_table(monkeypatch):
    # What the guard prevents: the IK trades the tool's height for the turn, down to the fork.
    monkeypatch.setattr(motion, "LINE_LOST", np.inf)
    worst, lowest, _ = _approach_from_tilted()
    assert worst > 0.1
    assert lowest < 0.03


@pytest.mark.parametrize("goal_z", [0.15, 0.25])
def test_an_approach_the_ik_follows_stays_on_its_line(goal_z):
    world = SimWorld(SIM_TASKS["rearrange_table"].sample_scene(np.random.default_rng(0)))
    robot = RobotController(world)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: robot.targets[arm].grip_closed_settled)
    robot.frame = extractor.frame
    goal = motion.pose_from_matrix(np.array([-0.15, 0.5, goal_z]), robot.rotation("left"))
    ticks = 0
    for _ in motion.approach(robot, "left", goal):
        robot.step()
        extractor.update()
        ticks += 1
        assert robot.ik.residual("left", robot.commanded_pose("left")) < 0.01
    assert np.linalg.norm(robot.frame.arms["left"].ee - goal.pos) < motion.APPROACH_TOLERANCE
    assert ticks < 100  # the straight line, no detour
