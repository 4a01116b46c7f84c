"""Tipping a thin object put down on its edge flat: the open fingers push its top edge over.

A fork or a spoon that fell on its edge is taken from above along its length, across its
thickness, and so is put down on its edge, which the goal reads as "not lying flat (tilt
90 deg)". Turning it flat in the hand does not work with this gripper: with the fingers one
above the other its housing is 7 cm under the tool centre, and a fork let go there tips off
the lower finger and lands on its edge again (the utensils' rolling friction holds one
leaning at 48 deg). So it is set down on its edge, short of its spot by as far as it will
fall, released, and the open fingers, raised until their tips are just under its top edge,
push that edge across. Pushed that high it tips before it slides, and falls on its face.
These are the geometry and the push; :class:`~agentchord.actions.place.Place` moves.
"""

from __future__ import annotations

import numpy as np

from agentchord.actions.grasping.finger_clearance import FINGER_ACROSS, swept_hits
from agentchord.actions.grasping.top_grasp import FINGERTIP_REACH, on_its_edge
from agentchord.features.frame import FeatureFrame, ObjectFeatures

#: The finger tips push this far (m) under the object's top edge: high, so it tips before it slides.
TIP_BELOW_TOP = 0.004
#: The pushing finger's inner face ends this far (m) past where the object's face stood, beyond
#: the object's standing height: a fork must turn 30-60 deg (the wider, the less) before its
#: rolling friction lets it fall, and slides a little as it turns. With 1.5 cm a fork 1.6 cm wide
#: and 1 cm thick turned 40 deg, slid 1.8 cm and stayed leaning at 50 deg; with 3 cm, 40 of 40
#: forks and spoons stood on their edge fell flat.
PUSH_SLACK = 0.03
#: Speed (m/s) of the push.
PUSH_SPEED = 0.05
#: Tool poses sampled along the push for the fingers' sweep check.
PUSH_SAMPLES = 8
#: Shares of :func:`fall_shift` tried, in turn, for how far short of its spot the object is set down.
SHORT_SHARES = (1.0, 0.5, 0.0)
#: The tool must be this close to top-down (the cosine of its approach with straight down).
TOP_DOWN_COS = 0.9


def standing_height(feats: ObjectFeatures) -> float:
    """How high (m) a thin object stands on its edge on the table: its width (the shorter side of
    its face), whatever its pitch in the fingers now.

    The place lowers the object's centre to half this over the table. A fork hanging pitched in the
    fingers (30-40 deg, swung while the place turned it to its yaw) then touches down with one end
    and is pressed level. Lowered only until its lower end touched, it was let go hanging, dropped
    and slid 4-5 cm: 3 of 40 forks and spoons stood on their edge ended more than 3 cm off their
    spot that way, 1 of 40 this way (3.1 cm).
    """
    return float(min(feats.extent[0], feats.extent[1]))


def fall_shift(feats: ObjectFeatures) -> float:
    """How far (m) the centre of an object on its edge moves when it tips onto its face: half its
    thickness to the edge it turns about, then half its width beyond."""
    return 0.5 * (float(feats.extent[2]) + standing_height(feats))


def tip_start(tool: np.ndarray, feats: ObjectFeatures, surface_z: float) -> np.ndarray:
    """The tool centre from which the open fingers push: over ``tool`` (x, y), the tips just under
    the top edge of ``feats`` standing on its edge on the surface at ``surface_z``."""
    return np.r_[tool[:2], surface_z + standing_height(feats) - TIP_BELOW_TOP + FINGERTIP_REACH]


def push_length(tool: np.ndarray, feats: ObjectFeatures, push: np.ndarray) -> float:
    """How far (m) the tool moves along ``push`` for its trailing finger to push the object's top edge
    its standing height and :data:`PUSH_SLACK` beyond where its face stands."""
    ahead = float(np.dot(feats.pos[:2] - tool[:2], push[:2]))
    return ahead - 0.5 * float(feats.extent[2]) + FINGER_ACROSS[0] + standing_height(feats) + PUSH_SLACK


def tip_push(
    frame: FeatureFrame, obj: str, tool: np.ndarray, rotation: np.ndarray, surface_z: float,
) -> tuple[np.ndarray, float] | None:
    """Which way the open fingers of a top-down tool holding ``obj`` on its edge will push it over,
    and how far short of its spot it is set down for that.

    Across the fingers, one way or the other, set down short by :func:`fall_shift` (so it falls onto
    its spot), by half that, or on its spot (where a neighbour is too near: rearrange, a fork beside
    the plate): the first whose fingers, pushing from there, sweep through no neighbour. None when
    the object is not flat and on its edge (:func:`~agentchord.actions.grasping.top_grasp.on_its_edge`), the
    tool is not top-down, or every push is blocked: the object is then put down as it is held.

    Args:
        frame: The latest features, the object held.
        obj: The held object.
        tool: The tool centre now, over the spot.
        rotation: The tool's rotation (columns: approach, across the fingers, along them).
        surface_z: Height (m) of the surface the object is put on.

    Returns:
        ``(push, short)``: the push's unit horizontal direction and how far (m) against it the
        object is set down.
    """
    feats = frame.objects[obj]
    if not on_its_edge(feats) or -float(rotation[2, 0]) < TOP_DOWN_COS:
        return None
    across = np.array([rotation[0, 1], rotation[1, 1], 0.0])
    across /= max(float(np.linalg.norm(across)), 1e-9)
    fall = fall_shift(feats)
    for share in SHORT_SHARES:
        for push in (across, -across):
            start = tip_start(tool - share * fall * push, feats, surface_z)
            length = push_length(tool, feats, push)  # held, the object keeps its place relative to the tool
            poses = [(start + s * push, rotation) for s in np.linspace(0.0, length, PUSH_SAMPLES)]
            if not swept_hits(frame, obj, poses):
                return push, share * fall
    return None
