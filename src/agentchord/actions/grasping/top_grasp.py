"""Where a top-down grasp takes an object: its long direction and the tool centre.

A top grasp (a short or flat object: a block, a capsule, cutlery) comes straight down with the
fingers closing across the object's narrow horizontal side. This is the plain grasp, before any
clearance of a neighbour (:mod:`~agentchord.actions.grasping.finger_clearance`) or offset the graph asks
for; the place action uses it too, to put an object down where a top grasp can take it again.
"""

from __future__ import annotations

import numpy as np

from agentchord.actions.grasping.geometry import quat_matrix
from agentchord.features.frame import ObjectFeatures, level_tilt_deg

#: Tilt (deg) beyond which an object is treated as lying on its side.
FALLEN_DEG = 60.0
#: An object thinner than this share of its longer side (along its axis: cutlery, a card) is flat;
#: a capsule (0.8) or a block (1.0) is not.
FLAT_SHARE = 0.25
#: The finger tips reach this far past the tool centre (m): keep them off the table.
FINGERTIP_REACH = 0.039


def lies_on_side(feats: ObjectFeatures) -> bool:
    """Whether an object lies on its side (its axis near horizontal), not upright or upside down.

    A fork that flipped over when dropped (tilt 180 deg) was taken for a lying cylinder as tall as
    the fork is long, and the fingers closed 5 cm above it.
    """
    return level_tilt_deg(feats.axis) >= FALLEN_DEG


def on_its_edge(feats: ObjectFeatures) -> bool:
    """Whether a flat object (:data:`FLAT_SHARE`: a fork, a spoon, a card) lies on its side, standing
    on an edge, not flat; a bottle or a capsule lying down (a cylinder on its round side) does not.

    A capsule 2.7 cm tall and 3.3 cm across, lying on its side beside the tray's handle, passed
    the older test (its axis merely its shortest side). It was taken across its flat ends, and a
    finger came down on the handle three times.
    """
    return lies_on_side(feats) and float(feats.extent[2]) < FLAT_SHARE * float(max(feats.extent[0], feats.extent[1]))


def long_axis(feats: ObjectFeatures) -> np.ndarray:
    """An object's long direction: its axis if it lies on its side, else its longer horizontal side.

    A flat object on its edge lies along the longer of its sides, whichever of them is level (a
    fork on its edge against the plate was taken along its thickness, with the fingers across its
    14 cm length).
    """
    rot = quat_matrix(feats.quat)
    if on_its_edge(feats):
        level = [feats.extent[i] * float(np.linalg.norm(rot[:2, i])) for i in (0, 1)]
        return rot[:, 0] if level[0] >= level[1] else rot[:, 1]
    if lies_on_side(feats):
        return feats.axis
    return rot[:, 0] if feats.extent[0] >= feats.extent[1] else rot[:, 1]


def plain_top_grasp(feats: ObjectFeatures) -> tuple[np.ndarray, np.ndarray]:
    """The top-down grasp of an object where it lies, before any clearance or offset is applied.

    Returns:
        ``(long_dir, point)``: the object's long horizontal direction (unit; the fingers close
        across it) and the tool centre, whose finger tips go 70 % down the object (at most 3 cm)
        and never closer than 4 mm to the table.
    """
    lying = lies_on_side(feats)
    long_dir = long_axis(feats)
    long_dir = np.array([long_dir[0], long_dir[1], 0.0])
    if np.linalg.norm(long_dir) < 1e-6:
        long_dir = np.array([1.0, 0.0, 0.0])
    long_dir /= np.linalg.norm(long_dir)
    # Lying, an object is as high as it is across (a bottle's diameter); a flat one on its edge as
    # high as its sides stand.
    across = float(feats.extent[0])
    if on_its_edge(feats):
        across = float(np.abs(quat_matrix(feats.quat)[2]) @ np.asarray(feats.extent, dtype=float))
    top_z = feats.pos[2] + 0.5 * across if lying else max(feats.top[2], feats.bottom[2])
    height = top_z - min(feats.bottom[2], feats.top[2]) if not lying else across
    tips_z = max(top_z - min(0.7 * height, 0.03), 0.004)
    return long_dir, np.r_[feats.pos[:2], tips_z + FINGERTIP_REACH]
