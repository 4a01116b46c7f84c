"""Drag an object pressed against a neighbour away from it, so that a top grasp's fingers fit.

An object pushed flush against another leaves no room on that side for an open finger: a fork
against the plate's rim. Where no slide or turn of the grasp clears the neighbour
(:mod:`~agentchord.actions.grasping.finger_clearance`), the finger comes down on it and the tool stops
short. Then the tip of one open finger is pressed lightly on the object's top, near its edge on
the neighbour's side, and the hand slides away: the finger's friction (1.5) beats
the table's (at most 1.2 for the objects here), and the object comes along. The grasp then looks
again (:class:`~agentchord.actions.grasp.Grasp`, at most :attr:`~agentchord.actions.grasp.Grasp.DRAGS`
times).

Only the feature frame is read (objects as oriented boxes, round ones as cylinders), as for the
clearance check.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np

from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.finger_clearance import (
    FINGER_ACROSS,
    FINGER_SPAN_DOWN,
    SHORT_RATIO,
    neighbours_hit,
    clear_top_grasp,
    horizontal_sizes,
    is_round,
    open_finger_points,
    swept_hits,
)
from agentchord.actions.grasping.geometry import quat_matrix
from agentchord.actions.motion import approach, move_to, pose_from_matrix, settle, wait_for_rest
from agentchord.actions.grasping.top_grasp import plain_top_grasp
from agentchord.features.frame import UP, FeatureFrame, ObjectFeatures
from agentchord.solvers.poses import top_down_rotation

#: How far (m) the pressing finger's tip is sent below the object's top: a light press (pressed
#: 4-7 mm, the fork rolled over).
PRESS_DEPTH = 0.0015
#: How far (m) inside the object's edge, on the neighbour's side, the pressing tip's outer edge stays.
EDGE_MARGIN = 0.0015
#: A finger's tip, seen from below, is a strip along its inner edge (measured on the ViperX
#: gripper's meshes): 1.5 mm across, 1 cm along, centred on the tool; the finger widens to its full
#: 2.4 cm only higher up. The tip presses; the open-finger plates of the clearance check are a
#: bound on the whole finger.
TIP_THICKNESS = 0.0015
TIP_HALF_WIDTH = 0.005
#: How high (m) above the tip the strip is followed for what it would touch.
TIP_RISE = 0.01
#: Drag lengths (m) tried, shortest first: the shortest after which a top grasp's fingers clear.
DRAG_LENGTHS = (0.02, 0.03, 0.04, 0.05, 0.06)
#: Heights (m): the hand comes down onto the object from this far above the press, and rises as far after.
ABOVE = 0.06
#: Speeds (m/s) of the descent onto the object and of the drag.
PRESS_SPEED = 0.05
DRAG_SPEED = 0.04
#: Tool poses sampled along the drag for the fingers' sweep.
DRAG_SAMPLES = 9


@dataclass(frozen=True)
class DragPlan:
    """Where the hand presses and how far it drags.

    Attributes:
        press: The tool centre with the pressing finger's tip on the object's top.
        rotation: The tool frame (top-down; the fingers close along the drag).
        away: The drag direction (horizontal, unit), away from the neighbours.
        length: How far (m) the hand drags.
    """

    press: np.ndarray
    rotation: np.ndarray
    away: np.ndarray
    length: float

    @property
    def end(self) -> np.ndarray:
        """The tool centre at the end of the drag."""
        return self.press + self.length * self.away


def _away_from(feats: ObjectFeatures, neighbour: ObjectFeatures) -> np.ndarray | None:
    """The horizontal direction (unit) from a neighbour's nearest point to the object's centre."""
    local = (feats.pos - neighbour.pos) @ quat_matrix(neighbour.quat)
    half = 0.5 * np.asarray(neighbour.extent, dtype=float)
    nearest = np.clip(local, -half, half)
    if is_round(neighbour):  # the nearest point of its circle
        radial = np.hypot(local[0], local[1])
        if radial > 1e-9:
            nearest[:2] = local[:2] * min(1.0, 0.5 * float(max(neighbour.extent[:2])) / radial)
    direction = (quat_matrix(neighbour.quat) @ (local - nearest))[:2]
    norm = float(np.linalg.norm(direction))
    return None if norm < 1e-6 else np.r_[direction / norm, 0.0]


def _chord(feats: ObjectFeatures, direction: np.ndarray) -> float:
    """The length (m) of the line through an object's centre along a horizontal ``direction`` to its
    sides (its oriented box, or its circle when round, seen from above)."""
    local = np.abs(direction @ quat_matrix(feats.quat))[:2]
    extent = np.asarray(feats.extent, dtype=float)[:2]
    if is_round(feats):
        return float(max(extent))
    return float(min(extent[i] / local[i] for i in (0, 1) if local[i] > 1e-9))


def _tip_points(tip: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Sample points (n x 3) of the pressing finger's tip strip, its centre at ``tip`` (tool frame
    ``rotation``: the strip lies along the fingers' width axis), up to :data:`TIP_RISE` above it."""
    d, a, w = np.meshgrid(
        np.linspace(-TIP_RISE, 0.0, 3), np.linspace(-0.5, 0.5, 2) * TIP_THICKNESS,
        np.linspace(-TIP_HALF_WIDTH, TIP_HALF_WIDTH, 3), indexing="ij",
    )
    return tip + np.outer(d.ravel(), rotation[:, 0]) + np.outer(a.ravel(), rotation[:, 1]) + np.outer(w.ravel(), rotation[:, 2])


def _top(feats: ObjectFeatures) -> float:
    """The height (m) of an object's highest point (its oriented box)."""
    return float(feats.pos[2] + 0.5 * np.abs(quat_matrix(feats.quat)[2]) @ np.asarray(feats.extent, dtype=float))


def _moved(frame: FeatureFrame, obj: str, shift: np.ndarray) -> FeatureFrame:
    """The frame with ``obj`` moved by ``shift``."""
    objects = dict(frame.objects)
    objects[obj] = replace(objects[obj], pos=objects[obj].pos + shift)
    return replace(frame, objects=objects)


def plan_drag(frame: FeatureFrame, obj: str, blockers: tuple[str, ...]) -> DragPlan | None:
    """A drag of ``obj`` away from ``blockers`` after which a top grasp's fingers clear them.

    Args:
        frame: The current features.
        obj: The object the grasp is for.
        blockers: The neighbours its open fingers come down on.

    Returns:
        The plan; None where no direction away is known, the pressing tip would come down on
        something else, the hand would sweep into something on the way, or no drag of
        :data:`DRAG_LENGTHS` clears the grasp.
    """
    feats = frame.objects[obj]
    directions = [d for d in (_away_from(feats, frame.objects[b]) for b in blockers if b in frame.objects) if d is not None]
    if not directions:
        return None
    away = np.sum(directions, axis=0)
    if float(np.linalg.norm(away)) < 1e-6:
        return None  # pressed between two neighbours from opposite sides
    away /= float(np.linalg.norm(away))
    long_dir, _ = plain_top_grasp(feats)
    along, across = horizontal_sizes(feats, long_dir)
    if along >= SHORT_RATIO * across:
        # A long object is dragged square to its length: the pressing finger then lies along it.
        narrow = np.cross(UP, long_dir)
        away = narrow if float(narrow @ away) >= 0.0 else -narrow
    # The fingers close along the drag: one presses on the object, the other hangs beyond it, away.
    rotation = top_down_rotation(np.array([-away[1], away[0], 0.0]))
    # The pressing finger's tip (its inner edge) near the object's edge on the neighbour's side: the
    # press then holds the object down against the drag's tipping moment. Pressed on its centre line,
    # a fork 1.6 cm wide and 1.1 cm thick rolled onto its edge instead of sliding (pressed 2-3 mm
    # from its edge it slid 4 cm; 4-5 mm from it, it rolled). Forks and spoons
    # pressed against the plate, 7 places x 4 scenes: all 28 taken after the drag, 26 still flat.
    tip_offset = min(0.0, -0.5 * _chord(feats, away) + EDGE_MARGIN + 0.5 * TIP_THICKNESS)
    press = feats.pos + (tip_offset + FINGER_ACROSS[0] + 0.5 * TIP_THICKNESS) * away
    press[2] = _top(feats) - PRESS_DEPTH + FINGER_SPAN_DOWN[1]  # the tips reach this far below the tool centre
    tip = feats.pos + tip_offset * away
    tip[2] = press[2] - FINGER_SPAN_DOWN[1]
    if neighbours_hit(frame, obj, _tip_points(tip, rotation), 0.0):
        return None  # the tip would come down on something else
    for length in DRAG_LENGTHS:
        sweep = [open_finger_points(press + s * length * away, rotation) for s in np.linspace(0.0, 1.0, DRAG_SAMPLES)]
        if neighbours_hit(frame, obj, np.vstack(sweep), 0.0).keys() - set(blockers):
            return None  # the hand would drag into something on the way (it leaves the blockers)
        moved = _moved(frame, obj, length * away)
        long_dir, point = plain_top_grasp(moved.objects[obj])
        if not clear_top_grasp(moved, obj, point, long_dir).blocked_by:
            return DragPlan(press=press, rotation=rotation, away=away, length=length)
    return None


def drag_clear(robot: RobotController, arm: str, plan: DragPlan, obj: str) -> Iterator[None]:
    """Press one open finger on the object's top, drag it ``plan.length`` away, rise.

    The hand first rises where it is (its fingers may rest on the neighbour), then goes above the
    press point (:func:`~agentchord.actions.motion.approach`: the tool turns on the way, and where
    the live IK loses the line it goes round through home, not down onto the object), and comes
    down until the tip presses.
    """
    robot.set_grip(arm, 0.0)
    here = robot.commanded_pose(arm)
    rise = max(here.pos[2], plan.press[2] + ABOVE)
    yield from move_to(robot, arm, pose_from_matrix(np.r_[here.pos[:2], rise], robot.rotation(arm)))
    above = pose_from_matrix(np.r_[plan.press[:2], rise], plan.rotation)
    press = pose_from_matrix(plan.press, plan.rotation)
    yield from approach(robot, arm, above, then=press, clear=lambda tool_poses: not swept_hits(robot.frame, None, tool_poses))
    yield from move_to(robot, arm, press, speed=PRESS_SPEED)
    yield from settle(robot, arm, max_ticks=15)
    yield from move_to(robot, arm, pose_from_matrix(plan.end, plan.rotation), speed=DRAG_SPEED)
    yield from move_to(robot, arm, pose_from_matrix(plan.end + np.array([0.0, 0.0, ABOVE]), plan.rotation))
    yield from wait_for_rest(robot, obj)
