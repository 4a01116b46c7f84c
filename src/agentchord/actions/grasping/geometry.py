"""Tool-frame geometry shared by the atomic actions: a level side-grasp frame, a quaternion's
matrix, and turns of the tool about the vertical that keep the wrist-rotate joint in range."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions.controller import RobotController
from agentchord.actions.motion import grasp_frame
from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX


def level_frame(rotation: np.ndarray) -> np.ndarray:
    """The tool's level side-grasp frame for its current approach; a top-down tool is kept."""
    if abs(rotation[2, 0]) > 0.7:
        return rotation
    return grasp_frame(rotation[:, 0])


def quat_matrix(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = quat
    return Rotation.from_quat([x, y, z, w]).as_matrix()


def yaw_turn(robot: RobotController, arm: str, direction: np.ndarray, yaw_deg: float, goal: np.ndarray) -> np.ndarray:
    """Rotation about world z that brings ``direction``'s yaw to ``yaw_deg``, either way round (mod 180).

    Of the two turns, the smaller one unless it would drive the wrist-rotate joint (whose axis
    is the tool's approach) past its range: a top grasp often leaves that joint at a limit.
    The waist's own turn toward ``goal`` (x, y) is accounted for.
    """
    current = np.degrees(np.arctan2(direction[1], direction[0]))
    delta = (yaw_deg - current + 90.0) % 180.0 - 90.0
    candidates = [delta] if abs(delta) < 1e-6 else [delta, delta - np.copysign(180.0, delta)]
    best = candidates[0]
    if wrist_margin(robot, arm, best, goal) < 0.0:
        best = max(candidates, key=lambda turn: wrist_margin(robot, arm, turn, goal))
    return Rotation.from_euler("z", best, degrees=True).as_matrix()


def wrist_margin(robot: RobotController, arm: str, turn_deg: float, goal: np.ndarray) -> float:
    """Predicted distance (rad) of the wrist-rotate joint to its range after turning the tool
    ``turn_deg`` about world z while moving to ``goal`` (x, y); the waist's own turn is accounted for."""
    lo, hi = robot.ik.model.joint(f"{ARM_PREFIX[arm]}/wrist_rotate").range
    q = robot.ik.arm_q(arm)[ARM_JOINTS.index("wrist_rotate")]
    base = robot.world.arm_base(arm)[:2]
    here, there = robot.commanded_pose(arm).pos[:2] - base, np.asarray(goal)[:2] - base
    waist = np.degrees(np.arctan2(there[1], there[0]) - np.arctan2(here[1], here[0]))
    waist = (waist + 180.0) % 360.0 - 180.0
    # A turn about world z is a turn about the approach axis scaled by its vertical component.
    after = q + np.radians(turn_deg - waist) * robot.rotation(arm)[2, 0]
    return float(min(after - lo, hi - after))
