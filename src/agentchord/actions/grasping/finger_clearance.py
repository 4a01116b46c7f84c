"""Where a grasp's open fingers go: a top grasp's come down, a side grasp's sweep in; and top grasps
whose fingers clear the neighbours.

A top grasp closes its fingers across the object's narrow side. Open, each finger is a
2.4 cm x 6.1 cm plate beside the object, 3.5 cm from the tool centre. An object pushed
against another (a fork against the plate's rim, a capsule against the tray's handle) puts
a finger on the neighbour: it lands there and the tool stops ~1.8 cm above the grasp. Then
the grasp slides along a long object's length, or turns about a short one, to the nearest
choice whose fingers clear what stands beside it.

A side grasp's fingers are followed from the pre-grasp to the grasp point
(:func:`side_approach_blocking`): a bottle lying beside a cup is swept into and pushed, and the cup
caught off centre; the grasp action picks a clear one.

An empty hand's straight move to a pre-grasp that would sweep the open fingers into a neighbour
goes over it instead (:func:`crossing_over`).

Only the feature frame is read (objects as oriented boxes, round ones as cylinders), so the
check works on any world's perception, not on simulator geometry.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions.grasping.geometry import quat_matrix
from agentchord.actions.motion import line_poses
from agentchord.features.frame import UP, FeatureFrame, ObjectFeatures
from agentchord.solvers.ik import PoseTarget
from agentchord.solvers.poses import quat_to_rotation, top_down_rotation

#: The open fingers in the tool frame of a top grasp (m; measured on the ViperX gripper's meshes):
#: along the approach (down), from the palm side to the tips, the tips being at the tool's reach;
#: across, the inner and outer face of each finger; along the object, the half-width.
FINGER_SPAN_DOWN = (-0.0513, 0.0387)
FINGER_ACROSS = (0.0346, 0.059)
FINGER_HALF_WIDTH = 0.0306
#: Clearance (m) kept between a finger and a neighbour's surface.
CLEARANCE = 0.003
#: An object whose horizontal sides are within this ratio is turned about the vertical; a longer
#: one is slid along its length (its narrow side fixes the fingers' direction).
SHORT_RATIO = 1.5
#: Turns (deg) and slides (m) tried, nearest first.
TURN_STEP_DEG = 15.0
SLIDE_STEP = 0.005
#: A slide keeps the fingers' centre this far (m) inside the object's end.
END_MARGIN = 0.02
#: A side grasp's sweep from the pre-grasp is sampled at most this far apart (m).
SWEEP_STEP = 0.01
#: Neighbours read as round (cylinders) when their horizontal sides differ by less than this share.
ROUND_SHARE = 0.1
#: Heights (m) over the higher of a move's ends tried for a crossing above the neighbours, lowest first.
CROSSING_RISES = (0.0, 0.04, 0.08, 0.12, 0.16)
#: Tool poses sampled along each leg of a move whose sweep is checked.
LEG_SAMPLES = 21


@dataclass(frozen=True)
class TopGraspChoice:
    """How a top grasp departs from the plain one (fingers across the narrow side at the centre).

    Attributes:
        turn_deg: Turn of the fingers' direction about the vertical (deg).
        slide: Slide of the grasp point along the object's long horizontal axis (m), signed
            along the axis the object's own orientation gives (so it follows the object).
        blocked_by: Neighbours the fingers still come down on (empty when clear).
    """

    turn_deg: float = 0.0
    slide: float = 0.0
    blocked_by: tuple[str, ...] = ()

    def apply(self, long_dir: np.ndarray, point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The fingers' long direction and the grasp point of this choice, from the plain ones."""
        turned = Rotation.from_euler("z", self.turn_deg, degrees=True).as_matrix() @ long_dir
        return turned, point + self.slide * long_dir


def open_finger_points(point: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Sample points (n x 3) inside both open fingers of a gripper whose tool centre is at ``point``.

    Args:
        point: The tool centre.
        rotation: The tool frame: columns along the approach, the fingers' closing direction, and
            the fingers' width (a top grasp: down, across the object, along it; a side grasp:
            the horizontal approach, across it, up).
    """
    approach, closing, width = rotation[:, 0], rotation[:, 1], rotation[:, 2]
    d, a, w = np.meshgrid(
        np.linspace(*FINGER_SPAN_DOWN, 4),
        np.r_[np.linspace(*FINGER_ACROSS, 3), -np.linspace(*FINGER_ACROSS, 3)],
        np.linspace(-FINGER_HALF_WIDTH, FINGER_HALF_WIDTH, 5),
        indexing="ij",
    )
    return point + np.outer(d.ravel(), approach) + np.outer(a.ravel(), closing) + np.outer(w.ravel(), width)


def finger_points(point: np.ndarray, long_dir: np.ndarray) -> np.ndarray:
    """Sample points (n x 3) inside both open fingers of a top grasp at ``point`` (the tool centre),
    fingers closing across ``long_dir`` (horizontal, unit)."""
    return open_finger_points(point, top_down_rotation(long_dir))


def is_round(feats: ObjectFeatures) -> bool:
    """Whether an object reads as round seen from above (a cylinder: its horizontal sides within
    :data:`ROUND_SHARE` of each other)."""
    ex, ey = float(feats.extent[0]), float(feats.extent[1])
    return abs(ex - ey) <= ROUND_SHARE * max(ex, ey, 1e-9)


def _inside(feats: ObjectFeatures, points: np.ndarray, clearance: float = CLEARANCE) -> np.ndarray:
    """Which points lie within ``clearance`` of an object: its oriented box, or its cylinder when round."""
    local = (points - feats.pos) @ quat_matrix(feats.quat)
    half = 0.5 * np.asarray(feats.extent, dtype=float) + clearance
    if is_round(feats):
        radius = 0.5 * float(max(feats.extent[0], feats.extent[1])) + clearance
        return (np.hypot(local[:, 0], local[:, 1]) <= radius) & (np.abs(local[:, 2]) <= half[2])
    return np.all(np.abs(local) <= half, axis=1)


def blocking(frame: FeatureFrame, obj: str, point: np.ndarray, long_dir: np.ndarray) -> dict[str, int]:
    """The neighbours of ``obj`` that the open fingers of a top grasp at ``point`` come down on,
    with how many of the fingers' sample points lie in each."""
    return neighbours_hit(frame, obj, finger_points(point, long_dir), CLEARANCE)


def side_approach_blocking(
    frame: FeatureFrame, obj: str, pre: np.ndarray, point: np.ndarray, rotation: np.ndarray
) -> dict[str, int]:
    """The neighbours of ``obj`` that the open fingers of a side grasp sweep into on their way in,
    from the pre-grasp ``pre`` to the grasp ``point`` (tool frame ``rotation``), with how many of
    the fingers' sample points lie in each.

    No clearance is kept: a finger passing a neighbour's side at a few millimetres does not move it
    (3 mm beside a standing cup, the grasp holds as planned).
    """
    steps = max(2, int(np.ceil(float(np.linalg.norm(point - pre)) / SWEEP_STEP)) + 1)
    points = np.vstack([open_finger_points(pre + s * (point - pre), rotation) for s in np.linspace(0.0, 1.0, steps)])
    return neighbours_hit(frame, obj, points, 0.0)


def swept_hits(
    frame: FeatureFrame, obj: str | None, tool_poses: list[tuple[np.ndarray, np.ndarray]],
    held: np.ndarray | None = None, held_radius: float = 0.0,
) -> dict[str, int]:
    """The neighbours of ``obj`` (every object where None: an empty hand going away) that the open
    fingers pass through along sampled tool poses (position, rotation), and with ``held`` (points
    along a held object's axis, tool frame) what the held object passes through (within
    ``held_radius`` of those points)."""
    hits: dict[str, int] = {}
    for point, rotation in tool_poses:
        found = [neighbours_hit(frame, obj, open_finger_points(point, rotation), 0.0)]
        if held is not None and len(held):
            found.append(neighbours_hit(frame, obj, point + held @ rotation.T, held_radius))
        for part in found:
            for name, count in part.items():
                hits[name] = hits.get(name, 0) + count
    return hits


def _sweeps(frame: FeatureFrame, obj: str, start: PoseTarget, end: PoseTarget) -> dict[str, int]:
    """What the open fingers pass through on the straight move from ``start`` to ``end``."""
    poses = line_poses(start, end, np.linspace(0.0, 1.0, LEG_SAMPLES))
    return swept_hits(frame, obj, [(p.pos, quat_to_rotation(p.quat).as_matrix()) for p in poses])


def crossing_over(frame: FeatureFrame, obj: str, start: PoseTarget, goal: PoseTarget) -> list[PoseTarget] | None:
    """Waypoints over the neighbours of ``obj`` for an empty hand going from ``start`` to ``goal``.

    Where the straight move (the tool turning in step) sweeps the open fingers into a neighbour: up
    from ``start`` in its orientation, then level to over ``goal`` turning to its orientation, from
    where a straight move down ends at ``goal``. The lowest such crossing whose every leg is clear.

    The straight line from where the hand let a bottle go to the fallen bottle's pre-grasp passed
    over a cup standing beside it; the fingers struck its rim and the cup went off the table.

    Args:
        frame: The current features.
        obj: The object the hand is going to (its own fingers may reach it).
        start: The tool pose now.
        goal: The tool pose at the end of the move.

    Returns:
        The waypoints before the last move down to ``goal``; None where the straight move is clear,
        or no crossing is.
    """
    if not _sweeps(frame, obj, start, goal):
        return None
    for rise in CROSSING_RISES:
        height = max(start.pos[2], goal.pos[2]) + rise
        up = PoseTarget(pos=np.r_[start.pos[:2], height], quat=start.quat)
        over = PoseTarget(pos=np.r_[goal.pos[:2], height], quat=goal.quat)
        if not any(_sweeps(frame, obj, a, b) for a, b in ((start, up), (up, over), (over, goal))):
            return [up, over]
    return None


def neighbours_hit(frame: FeatureFrame, obj: str | None, points: np.ndarray, clearance: float) -> dict[str, int]:
    """How many of ``points`` lie within ``clearance`` of each neighbour of ``obj`` (of every object
    where None).

    A neighbour under the object's centre is one it rests on or in: the fingers reach in there.
    """
    centre = None if obj is None else frame.objects[obj].pos
    hits = {}
    for name, feats in frame.objects.items():
        if name == obj or feats.is_point:
            continue  # a point feature (a cloth's corner) lies flat in the cloth: nothing to land on
        if centre is not None and _inside(feats, np.array([[centre[0], centre[1], feats.pos[2]]]))[0]:
            continue  # the object rests on or in it (a fork on the plate, a capsule in the tray): reach in
        count = int(np.count_nonzero(_inside(feats, points, clearance)))
        if count:
            hits[name] = count
    return hits


def horizontal_sizes(feats: ObjectFeatures, long_dir: np.ndarray) -> tuple[float, float]:
    """An object's size (m) along ``long_dir`` and across it on the table: its box seen from above,
    whether it stands (a fork's length) or lies (a bottle's, along its axis)."""
    rotation = quat_matrix(feats.quat)
    extent = np.asarray(feats.extent, dtype=float)
    across_dir = np.cross(UP, long_dir)
    return float(np.abs(long_dir @ rotation) @ extent), float(np.abs(across_dir @ rotation) @ extent)


def clear_top_grasp(frame: FeatureFrame, obj: str, point: np.ndarray, long_dir: np.ndarray) -> TopGraspChoice:
    """The top grasp nearest the plain one whose open fingers clear every neighbour of ``obj``.

    The plain grasp when it is clear (the common case: nothing changes). Else, for a long object,
    slides along its length (keeping the fingers on it); for a short one, turns of the fingers'
    direction; the nearest clear one, or the one the fingers overlap least.

    Args:
        frame: The current feature frame.
        obj: The object to grasp.
        point: The plain grasp's tool centre.
        long_dir: The object's long horizontal direction (unit), along its own orientation.

    Returns:
        The choice; ``blocked_by`` names what its fingers still come down on.
    """
    hits = blocking(frame, obj, point, long_dir)
    if not hits:
        return TopGraspChoice()
    along, across = horizontal_sizes(frame.objects[obj], long_dir)
    candidates: list[TopGraspChoice] = []
    if along >= SHORT_RATIO * across:
        reach = max(0.5 * along - END_MARGIN, 0.0)
        for k in range(1, int(reach / SLIDE_STEP) + 1):
            candidates += [TopGraspChoice(slide=k * SLIDE_STEP), TopGraspChoice(slide=-k * SLIDE_STEP)]
    else:
        for k in range(1, int(90.0 / TURN_STEP_DEG) + 1):
            candidates += [TopGraspChoice(turn_deg=k * TURN_STEP_DEG), TopGraspChoice(turn_deg=-k * TURN_STEP_DEG)]
    best, best_count = TopGraspChoice(blocked_by=tuple(sorted(hits))), sum(hits.values())
    for candidate in candidates:
        turned, moved = candidate.apply(long_dir, point)
        found = blocking(frame, obj, moved, turned)
        count = sum(found.values())
        if count < best_count:
            best, best_count = TopGraspChoice(candidate.turn_deg, candidate.slide, tuple(sorted(found))), count
            if count == 0:
                break
    return best
