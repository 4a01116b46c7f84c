"""The ALOHA bimanual ViperX 300s: names, joints, gripper range, home pose and work cell.

Plain numbers, no MuJoCo: the actions, the solvers and any world (the simulator or a
real robot's driver) share them.
"""

from __future__ import annotations

import numpy as np

#: The two arms, in ALOHA's order (every per-arm vector: actions, observations, joint states).
ARMS = ("left", "right")
#: Arm name -> prefix of its bodies and joints in the model files.
ARM_PREFIX = {"left": "vx300s_left", "right": "vx300s_right"}
#: The six arm joints of each arm, base to wrist.
ARM_JOINTS = ("waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate")
#: Finger joint range; the pad gap is ``2 q - FINGER_GAP_OFFSET``.
FINGER_RANGE = (0.021, 0.057)
FINGER_GAP_OFFSET = 0.0448
#: Tool centre point: between the finger pads, along the gripper's x (approach) axis.
TCP_OFFSET = 0.115
#: The work cell's table: half-sizes (m) and the (x, y) of its centre; its top is at z = 0.
TABLE_HALF = (0.61, 0.381, 0.02)
TABLE_CENTER = (0.0, 0.6)
#: Home configuration of one arm (gym-aloha's keyframe, arm joints only).
HOME_Q = np.array([0.0, -0.96, 1.16, 0.0, -0.3, 0.0])
#: Capsules (body, from, to, radius) that wrap each arm's distal links for the IK's
#: arm-arm collision avoidance: analytic capsule distances are ~20x cheaper than mesh ones.
COLLISION_PROXIES = (
    ("upper_forearm_link", (0.0, 0.0, 0.0), (0.2, 0.0, 0.0), 0.035),
    ("lower_forearm_link", (0.0, 0.0, 0.0), (0.1, 0.0, 0.0), 0.035),
    ("gripper_link", (-0.04, 0.0, 0.0), (0.06, 0.0, 0.0), 0.05),
    ("gripper_link", (0.07, 0.0, 0.0), (0.155, 0.0, 0.0), 0.045),
)


def other_arm(arm: str) -> str:
    """The arm that is not ``arm``."""
    return ARMS[1] if arm == ARMS[0] else ARMS[0]
