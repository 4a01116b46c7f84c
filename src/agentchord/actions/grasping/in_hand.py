"""Where a held object sits in the hand: its axis's offset from the tool centre and the grasp's height.

A side grasp made as planned holds an object's axis through the tool centre at the asked share
of its height. Holds made otherwise are not: a fallen grasp that set a bottle upright in hand
leaves its axis 2-3 cm out along the approach, and a bottle dropped through the open fingers is
caught again wherever they close on it (at 82 % of its height, where 50 % was asked). The
actions that carry the object on read these to keep the carried object where the plan put it.
"""

from __future__ import annotations

import numpy as np

from agentchord.features.frame import FeatureFrame

#: A held object's axis within this angle (deg) of the tool's up axis is side-held.
SIDE_HELD_MAX_ANGLE_DEG = 20.0


def side_held_object(frame: FeatureFrame, arm: str, rotation: np.ndarray) -> str | None:
    """The object ``arm`` holds in a side grasp (its axis along the tool's up axis), or None.

    Args:
        frame: The latest features.
        arm: ``left`` or ``right``.
        rotation: The tool's rotation matrix now (columns: approach, across the fingers, up).
    """
    cos_max = np.cos(np.radians(SIDE_HELD_MAX_ANGLE_DEG))
    for holder, name in sorted(frame.holding):
        feats = frame.objects.get(name)
        if holder != arm or feats is None:
            continue
        length = float(np.linalg.norm(feats.top - feats.bottom))
        if length > 1e-6 and abs(float(np.dot(feats.top - feats.bottom, rotation[:, 2]))) / length >= cos_max:
            return name
    return None


def axis_offset_in_tool(frame: FeatureFrame, arm: str, obj: str, rotation: np.ndarray) -> np.ndarray:
    """The held object's axis relative to the tool centre, in the tool frame, across the axis only.

    The point of the object's axis nearest the tool centre, minus the tool centre, expressed in
    the tool frame with its component along the tool's up axis removed: (along the approach,
    across the fingers, 0). A centred side grasp gives a few millimetres.
    """
    feats = frame.objects[obj]
    ee = frame.arms[arm].ee
    nearest = feats.bottom + grasp_height_share(frame, arm, obj) * (feats.top - feats.bottom)
    offset = rotation.T @ (nearest - ee)
    offset[2] = 0.0
    return offset


def grasp_height_share(frame: FeatureFrame, arm: str, obj: str) -> float:
    """Where along ``obj``'s axis (0 = bottom, 1 = top) the tool centre of ``arm`` is."""
    feats = frame.objects[obj]
    axis = feats.top - feats.bottom
    return float(np.dot(frame.arms[arm].ee - feats.bottom, axis) / max(float(np.dot(axis, axis)), 1e-12))
