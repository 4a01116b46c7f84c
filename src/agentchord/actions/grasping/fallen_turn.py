"""Turning a fallen tall object upright in hand: the grasp across it, where it turns, and the turn.

A bottle or a cup lying on its side is taken from above across its middle (the fingers close
across its axis), lifted clear of the table and away from the arm's own base, then swung about
the vertical so its top points away from the robot and pitched up about the fingers' axis at
once. The tool ends in the usual side-grasp frame with the object upright between the fingers.
These are the poses; :class:`~agentchord.actions.grasp.Grasp` moves through them.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions.motion import grasp_frame
from agentchord.actions.grasping.top_grasp import FINGERTIP_REACH
from agentchord.features.frame import ObjectFeatures
from agentchord.solvers.poses import top_down_rotation

#: A fallen object is turned upright at least this far (m, horizontally) from the arm's own
#: shoulder: its ends sweep a circle as it turns, and beside the base they strike the arm.
TURN_FROM_BASE = 0.30


def fallen_grasp_frame(feats: ObjectFeatures) -> tuple[np.ndarray, np.ndarray]:
    """The tool rotation (approach down, fingers across the axis, the tool's z along the axis
    towards the object's top) and the grasp point over the object's middle, before any slide."""
    top_dir = np.array([feats.axis[0], feats.axis[1], 0.0])
    top_dir /= max(np.linalg.norm(top_dir), 1e-9)
    radius = 0.5 * float(feats.extent[0])
    # The finger tips reach ~4 cm past the tool centre: stay high enough to miss the table.
    point = np.r_[feats.pos[:2], max(feats.pos[2] + 0.35 * radius, FINGERTIP_REACH + 0.006)]
    return top_down_rotation(top_dir), point


def turn_pose(
    feats: ObjectFeatures, point: np.ndarray, rotation: np.ndarray, slide: float, base: np.ndarray
) -> tuple[np.ndarray, float]:
    """Where a fallen object grasped at ``point`` (tool ``rotation``, slid ``slide`` m towards its
    top) is turned upright by the arm whose shoulder is at ``base``.

    Returns:
        ``(lifted, yaw)``: the tool's position, lifted clear of the table and away from the arm's
        base, and the swing (rad, about the vertical) that points the object's top away from the robot.
    """
    half_length = 0.5 * float(np.linalg.norm(feats.top - feats.bottom))
    # Grasped nearer the top (a slide clear of a neighbour), the bottom hangs that much lower.
    lifted = point + np.array([0.0, 0.0, half_length + max(slide, 0.0) + 0.06])
    out = lifted[:2] - base[:2]
    if 1e-6 < float(np.linalg.norm(out)) < TURN_FROM_BASE:
        lifted[:2] = base[:2] + TURN_FROM_BASE * out / np.linalg.norm(out)
    outward = grasp_frame(lifted - base)[:, 0]
    top_dir = rotation[:, 2]
    return lifted, float(np.arctan2(np.cross(top_dir, outward)[2], float(np.dot(top_dir, outward))))


def turned(rotation: np.ndarray, yaw: float, share: float) -> np.ndarray:
    """A fallen grasp's tool ``rotation`` turned ``share`` of the way upright: the swing ``yaw`` about the
    vertical and the pitch about the fingers' axis at once, so the object's top only rises. All the
    way, the tool is in the usual side-grasp frame with the object upright between the fingers."""
    return Rotation.from_euler("z", share * yaw).as_matrix() @ rotation @ Rotation.from_euler("y", share * (-0.5 * np.pi)).as_matrix()
