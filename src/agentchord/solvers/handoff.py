"""Where to set an object down so that the other arm can take it (an arm-switching recovery).

A recovery that the busy arm cannot reach is one the other arm can: it picks the
object up and sets it down where both arms reach, then the busy arm takes it. The
spot is chosen when the recovery runs, from the latest feature frame: inside both
arms' reach shells with a margin, clear of the other objects and of the receiving
arm's tool, out of the way either arm's hand comes to grasp another object where such
a spot exists, and as near to where the object is as possible (a short carry).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.solvers.exceptions import NoHandoffSpotError
from agentchord.solvers.reach import REACH

#: Candidate spots: a grid over the table area in front of the robot (x range, y range, step; m).
SPOT_GRID = ((-0.30, 0.30), (0.30, 0.75), 0.02)
#: Reach slack (m) a spot needs for the arm that will take the object and the arm that sets it down.
TAKER_MARGIN = 0.05
PLACER_MARGIN = 0.03
#: Clearance (m) between the object's footprint and other objects' footprints, and from the taker's tool.
OBJECT_CLEARANCE = 0.04
TOOL_CLEARANCE = 0.12
#: Lowest tool height (m) a side grasp is checked at.
MIN_GRASP_HEIGHT = 0.06
#: An arm's side grasp of an object comes from its shoulder's side (``actions.motion.grasp_frame``): the
#: corridor it sweeps reaches this far (m) beyond the object's footprint (the 8 cm pre-grasp and the hand
#: behind the tool), and this far (m) either side of the line to the shoulder (the open hand with a margin).
APPROACH_CORRIDOR_LENGTH = 0.20
APPROACH_CORRIDOR_HALF_WIDTH = 0.08
#: Clearance (m) between a spot's object and a point the program carries a held object to later (a
#: held cup's footprint with a margin).
CARRIED_CLEARANCE = 0.10


def _footprint(frame: FeatureFrame, name: str) -> float:
    """Radius (m) of the table area an object covers, from its features."""
    feats = frame.objects[name]
    return 0.5 * float(np.hypot(*np.sort(feats.extent)[-2:])) if feats.extent[2] < 0.5 * max(feats.extent[:2]) \
        else 0.5 * float(max(feats.extent[0], feats.extent[1]))


def handoff_spot(
    frame: FeatureFrame, obj: str, placer: str, taker: str, taker_margin: float = TAKER_MARGIN,
    carried_to: Sequence[np.ndarray] = (),
) -> np.ndarray:
    """The table spot (x, y) where ``placer`` sets ``obj`` down for ``taker``.

    Args:
        frame: The latest features (object poses, the taker's tool).
        obj: The object being handed over (held upright by ``placer``).
        placer: The arm that sets it down.
        taker: The arm that will grasp it there.
        taker_margin: Reach slack (m) the spot needs for ``taker`` (more keeps it nearer the middle
            of the shell, where a top-down tool, which the shell was not measured for, reaches too).
        carried_to: Table points (x, y) the rest of the program carries a held object to (where the
            other arm holds the cup for the pour): a spot keeps clear of them where one can.

    Raises:
        NoHandoffSpotError: No grid spot is reachable by both arms and clear of everything.
    """
    feats = frame.objects[obj]
    height = float(max(feats.extent))
    grasp_z = max(0.5 * height, MIN_GRASP_HEIGHT)
    (x_lo, x_hi), (y_lo, y_hi), step = SPOT_GRID
    xs, ys = np.meshgrid(np.arange(x_lo, x_hi + 1e-9, step), np.arange(y_lo, y_hi + 1e-9, step))
    spots = np.column_stack([xs.ravel(), ys.ravel()])
    points = np.column_stack([spots, np.full(len(spots), grasp_z)])
    ok = (REACH[taker].slack(points) >= taker_margin) & (REACH[placer].slack(points) >= PLACER_MARGIN)
    radius = 0.5 * float(min(feats.extent[0], feats.extent[1])) if height == feats.extent[2] else 0.5 * height
    in_the_way = np.zeros(len(spots), dtype=bool)
    for name in frame.objects:
        other = frame.objects[name]
        if name == obj or other.is_point:  # itself, or a point feature (a cloth corner)
            continue
        gap = np.linalg.norm(spots - other.pos[:2], axis=1)
        ok &= gap >= radius + _footprint(frame, name) + OBJECT_CLEARANCE
        in_the_way |= _in_approach_corridor(spots, other.pos[:2], _footprint(frame, name), radius)
    for point in carried_to:
        # A bottle set down under where the left arm then held the cup was knocked over by it, out
        # of the right arm's reach.
        in_the_way |= np.linalg.norm(spots - np.asarray(point[:2], dtype=float), axis=1) < radius + CARRIED_CLEARANCE
    ok &= np.linalg.norm(spots - frame.arms[taker].ee[:2], axis=1) >= TOOL_CLEARANCE
    if not ok.any():
        raise NoHandoffSpotError(obj, placer, taker)
    # Set down in the way an arm's hand comes to another object, it is knocked over when that object
    # is taken next (a bottle set down 8 cm from the cup, on the left shoulder's side, was struck by
    # the left hand going to take the cup). Such spots only where no other is.
    if (ok & ~in_the_way).any():
        ok &= ~in_the_way
    candidates = spots[ok]
    return candidates[int(np.argmin(np.linalg.norm(candidates - feats.pos[:2], axis=1)))]


def _in_approach_corridor(spots: np.ndarray, centre: np.ndarray, footprint: float, radius: float) -> np.ndarray:
    """Which ``spots`` put an object of ``radius`` in the way of either arm's side grasp of the object
    whose footprint (radius ``footprint``) is centred at ``centre``."""
    inside = np.zeros(len(spots), dtype=bool)
    for reach in REACH.values():
        towards = reach.shoulder[:2] - centre
        towards /= max(float(np.linalg.norm(towards)), 1e-9)
        offset = spots - centre
        along = offset @ towards
        across = np.abs(offset[:, 0] * towards[1] - offset[:, 1] * towards[0])
        inside |= (along > 0.0) & (along < footprint + APPROACH_CORRIDOR_LENGTH + radius) \
            & (across < APPROACH_CORRIDOR_HALF_WIDTH + radius)
    return inside
