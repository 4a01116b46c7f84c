"""What a straight joint-space move of one arm would do, checked before it is made.

A joint-space move interpolates the joints, not the tool: the tool's path between the ends
can dip, swing sideways and pass near the other arm. Sampling the move's forward kinematics
on a scratch solver tells the lowest the tool (and anything it holds) goes, how close the two
arms' collision proxies come, and where the tool passes, which the finger-sweep check
(:func:`agentchord.actions.grasping.finger_clearance.swept_hits`) reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.actions.controller import RobotController
from agentchord.solvers.poses import quat_to_rotation

#: Joint-path samples checked (tool height, the fingers' and the held object's sweep, the other arm).
PATH_SAMPLES = 24


@dataclass(frozen=True)
class JointPath:
    """What a straight joint-space move would do, from samples of its forward kinematics.

    Attributes:
        lowest_tool: The tool centre's lowest height (m) along the move.
        lowest_held: The lowest height (m) of the held points along the move (inf: none given).
        clearance: The smallest distance (m) between the two arms' collision proxies.
        tool_poses: The sampled tool poses (position, rotation matrix).
    """

    lowest_tool: float
    lowest_held: float
    clearance: float
    tool_poses: tuple[tuple[np.ndarray, np.ndarray], ...] = ()


def joint_path(
    robot: RobotController, arm: str, q_goal: np.ndarray, held: np.ndarray | None = None, q_start: np.ndarray | None = None
) -> JointPath:
    """Check the straight joint-space move of ``arm`` from ``q_start`` (its current joints) to ``q_goal``.

    Args:
        robot: The robot (read only: the check runs on a scratch solver; the other arm stays
            where the live solution has it).
        arm: The moving arm.
        q_goal: Its six goal joints.
        held: Points (n x 3, m) rigidly held by the tool, in the tool frame: the lowest of them
            along the move is reported.
        q_start: Its six start joints.
    """
    ik = robot.scratch_ik()
    ik.reset(robot.ik.configuration.q.copy())
    q0 = robot.ik.arm_q(arm) if q_start is None else np.asarray(q_start, dtype=float)
    lowest_tool, lowest_held, clearance = np.inf, np.inf, np.inf
    poses = []
    for s in np.linspace(0.0, 1.0, PATH_SAMPLES + 1):
        ik.set_arm_q(arm, q0 + s * (np.asarray(q_goal) - q0))
        pose = ik.tcp_pose(arm)
        rotation = quat_to_rotation(pose.quat).as_matrix()
        poses.append((pose.pos.copy(), rotation))
        lowest_tool = min(lowest_tool, float(pose.pos[2]))
        if held is not None and len(held):
            lowest_held = min(lowest_held, float(np.min((pose.pos + held @ rotation.T)[:, 2])))
        clearance = min(clearance, ik.arm_clearance())
    return JointPath(lowest_tool=lowest_tool, lowest_held=lowest_held, clearance=clearance, tool_poses=tuple(poses))
