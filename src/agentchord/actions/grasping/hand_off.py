"""Where a hand takes a small object that the other hand holds, in the air.

A 4 cm cube held by one gripper leaves no face free for another gripper's 6 cm finger pads: the
giver's pads cover two opposite faces and reach past the others. So the taker closes on the same
two faces, below the giver's fingertips: its pads, 6 cm tall, end under the giver's fingers, and
grip the object's lower part. It comes horizontally, across the giver's closing direction, from
its own side of the table, its fingers closing along the giver's.
"""

from __future__ import annotations

import numpy as np

from agentchord.actions.grasping.geometry import quat_matrix
from agentchord.features.frame import FeatureFrame

#: An object no larger than this (m) along every axis is taken from the other hand this way.
SMALL_OBJECT = 0.06
#: A finger pad's extent in the tool frame around the tool centre (m): along the approach (x: palm
#: side to tip), the closing direction (y) and across (z). Measured on the ALOHA finger meshes.
FINGER_BOX = ((-0.051, 0.039), (-0.024, 0.024), (-0.031, 0.031))
#: Vertical gap (m) kept between the taker's pads and the giver's fingertips.
TIP_CLEARANCE = 0.006
#: The taker's pads overlap the object by at least this (m) of its height, or the grip is not tried.
MIN_OVERLAP = 0.008


def giver_of(frame: FeatureFrame, arm: str, obj: str) -> str | None:
    """The other arm, when it holds ``obj`` off the table and ``obj`` is small enough to pass hand to hand."""
    feats = frame.objects.get(obj)
    if feats is None or feats.is_point or float(max(feats.extent)) > SMALL_OBJECT:
        return None
    for other, held in frame.holding:
        if other != arm and held == obj and float(min(feats.bottom[2], feats.top[2])) > 0.01:
            return other
    return None


def lowest_finger_z(tool_pos: np.ndarray, tool_rot: np.ndarray) -> float:
    """The lowest point (z, m) of a gripper's finger pads, from its tool pose."""
    corners = np.array([[x, y, z] for x in FINGER_BOX[0] for y in FINGER_BOX[1] for z in FINGER_BOX[2]])
    return float(tool_pos[2] + (corners @ tool_rot.T)[:, 2].min())


def hand_off_frame(frame: FeatureFrame, arm: str, obj: str, giver: str, base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The taker's tool rotation and the point its tool centre goes to.

    Args:
        frame: The features now (the giver's tool pose, the object).
        arm: The taker.
        obj: The object the giver holds.
        giver: The arm that holds it.
        base: The taker's shoulder (its side of the table).

    Returns:
        ``(rotation, point)``: approach (tool x) horizontal across the giver's closing direction,
        from the taker's side; fingers closing (tool y) along the giver's; the point under the
        giver's fingertips, at the object's centre along the approach.

    Raises:
        ValueError: The giver closes vertically, or its fingertips leave too little of the object below them.
    """
    feats = frame.objects[obj]
    giver_arm = frame.arms[giver]
    giver_rot = quat_matrix(giver_arm.ee_quat)
    closing = np.array([giver_rot[0, 1], giver_rot[1, 1], 0.0])
    if float(np.linalg.norm(closing)) < 0.5:
        raise ValueError(f"the {giver} gripper closes vertically on {obj}: no horizontal way in under its fingers")
    closing /= np.linalg.norm(closing)
    approach = np.array([-closing[1], closing[0], 0.0])
    if float(np.dot(approach[:2], feats.pos[:2] - base[:2])) < 0.0:
        approach = -approach
    up = np.array([0.0, 0.0, 1.0])
    rotation = np.column_stack([approach, np.cross(up, approach), up])
    tips = lowest_finger_z(giver_arm.ee, giver_rot)
    bottom = float(min(feats.bottom[2], feats.top[2], feats.pos[2] - 0.5 * feats.extent[2]))
    top_of_pads = tips - TIP_CLEARANCE
    if top_of_pads - bottom < MIN_OVERLAP:
        raise ValueError(f"the {giver} gripper's fingers reach {100 * (top_of_pads - bottom):.1f} cm from {obj}'s bottom: no room under them")
    point = np.array([feats.pos[0], feats.pos[1], top_of_pads - FINGER_BOX[2][1]])
    return rotation, point
