"""ALOHA conventions (gym-aloha, LeRobot's ``aloha`` datasets): 14-dim joint state and action.

Layout, the same for state and action: the left arm's 6 joints (waist, shoulder, elbow,
forearm_roll, wrist_angle, wrist_rotate; rad, absolute) and its gripper, then the right arm's.
Grippers are normalised 0 = closed, 1 = open (the world's commands say 0 = open, 1 = closed).
"""

from __future__ import annotations

import numpy as np

from agentchord.robot.aloha import ARM_JOINTS, ARMS, FINGER_GAP_OFFSET, FINGER_RANGE
from agentchord.worlds.protocol import ArmCommand, World, gripper_grip, gripper_opening

#: Names of the 14 entries of state and action.
JOINT_NAMES = [f"{arm}_{j}" for arm in ARMS for j in (*ARM_JOINTS, "gripper")]


def gripper_open(world: World, arm: str) -> float:
    """The measured gripper opening of ``arm`` normalised to [0, 1] (0 closed, 1 open)."""
    lo, hi = FINGER_RANGE
    finger_q = 0.5 * (world.gripper_width(arm) + FINGER_GAP_OFFSET)
    return float(np.clip((finger_q - lo) / (hi - lo), 0.0, 1.0))


def joint_state(world: World) -> np.ndarray:
    """The robot's measured 14-dim joint state (float32)."""
    parts = []
    for arm in ARMS:
        parts.extend(world.arm_q(arm).tolist())
        parts.append(gripper_open(world, arm))
    return np.asarray(parts, dtype=np.float32)


def joint_action(commands: dict[str, ArmCommand]) -> np.ndarray:
    """The 14-dim joint-position action of the arms' commands (float32)."""
    parts = []
    for arm in ARMS:
        parts.extend(np.asarray(commands[arm].q, dtype=float).tolist())
        parts.append(gripper_opening(commands[arm].grip))
    return np.asarray(parts, dtype=np.float32)


def arm_commands(action: np.ndarray) -> dict[str, ArmCommand]:
    """The world's commands of a 14-dim action (grippers clipped to [0, 1])."""
    action = np.asarray(action, dtype=float)
    out = {}
    for i, arm in enumerate(ARMS):
        block = action[7 * i : 7 * i + 7]
        out[arm] = ArmCommand(q=block[:6].copy(), grip=gripper_grip(block[6]))
    return out


def environment_names(world) -> list[str]:
    """Names of the entries of :func:`environment_state`: per object its position and quaternion."""
    return [f"{obj}_{c}" for obj in world.object_names for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]


def environment_state(world) -> np.ndarray:
    """The objects' true poses (a simulator's ground truth): per object x, y, z, qw, qx, qy, qz (float32)."""
    parts = []
    for obj in world.object_names:
        pos, _ = world.object_pose(obj)
        parts.extend(pos.tolist())
        parts.extend(world.object_quat(obj).tolist())
    return np.asarray(parts, dtype=np.float32)
