"""The joint-path check: what a straight joint-space move's sampled forward kinematics report."""

import numpy as np
import pytest

from agentchord.actions.joint_path import joint_path
from agentchord.solvers.poses import quat_to_rotation
from test_actions_library import _setup


def test_a_joint_path_reports_the_lowest_tool_the_held_points_and_the_arms_clearance(pour_scene):
    _, robot, _ = _setup(pour_scene)
    q = robot.ik.arm_q("right")
    tool = robot.ik.tcp_pose("right")
    point = np.array([[0.0, 0.0, -0.1]])  # 10 cm down the tool's up axis
    still = joint_path(robot, "right", q, held=point)
    assert still.lowest_tool == pytest.approx(tool.pos[2], abs=1e-9)
    expected = tool.pos[2] + (quat_to_rotation(tool.quat).as_matrix() @ point[0])[2]
    assert still.lowest_held == pytest.approx(expected, abs=1e-9)
    assert still.clearance == pytest.approx(robot.ik.arm_clearance(), abs=1e-9) and still.clearance > 0.0
    # A move toward a lower posture passes lower than where it starts.
    lower = q.copy()
    lower[1] += 0.4
    assert joint_path(robot, "right", lower).lowest_tool < tool.pos[2]
