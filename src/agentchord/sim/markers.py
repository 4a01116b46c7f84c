"""What a disturbance looks like: a person's hand on a pulled object, a finger pushing or knocking one.

The simulation has no person: a disturbance is a wrench on the object's body
(``data.xfrc_applied``; ``world.push``, ``world.knock``, :class:`hand.PersonHand`). Filmed
as it is, a pulled object floats off by itself. The markers here are read from that wrench,
never written to the model or the data, so a recording shows them and the episode stays the
same (same seed, same episode): they are drawn into the renderer's scene only.

The wrench says which disturbance acts and where:

- a force with a vertical part (the hand carries the weight): a person's hand carries the
  object (a pull); the hand is drawn over its top, the forearm up and away across the table;
- a horizontal force applied below the centre (``world.push``: at table height): a push (the
  ``perturb`` and ``shift`` kinds); above it (``world.knock``: high on the object): a knock.
  A finger and hand are drawn behind the object where the push acts, with an arrow along it.

A push lasts a few ticks: its marker stays a moment longer (:data:`LINGER_TICKS`) so that a
viewer sees it. A carried object leaves a trail along its carry.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise
from typing import Literal

import mujoco
import numpy as np

#: Colours (RGBA, 0-1): skin for the hand and finger, orange for the push's arrow and the carry's trail.
SKIN_RGBA = (0.93, 0.71, 0.56, 1.0)
ARROW_RGBA = (1.0, 0.5, 0.0, 0.95)
TRAIL_RGBA = (1.0, 0.5, 0.0, 0.8)
#: Ticks (50 Hz) a marker stays after its force ends: a push of 0.1 s would be 2-3 frames of a video.
LINGER_TICKS = 20
#: A carried object's trail keeps a point every this many ticks, at most this many points.
TRAIL_EVERY = 2
TRAIL_POINTS = 200
#: A carrying hand's forearm: this long (m), this way (up and across the table from the front camera,
#: where the person stands, leaning right: one look on every frame).
FOREARM_LENGTH = 0.28
FOREARM_DIRECTION = np.array([0.35, 0.55, 0.76]) / np.linalg.norm([0.35, 0.55, 0.76])
#: A wrench smaller than this (N, N m) is none.
_EPS = 1e-9

MarkerKind = Literal["hand", "push", "knock"]
#: How a banner says what each marker shows.
WHAT = {
    "hand": "a person's hand takes it and sets it down",
    "push": "a person pushes it",
    "knock": "a person knocks it over",
}
#: The disturbance kind a marker stands for, when nobody named it (``perturb`` and ``shift`` both push).
KIND = {"hand": "pull", "push": "push", "knock": "knock"}


@dataclass(frozen=True)
class Shape:
    """One primitive of a marker, in the world frame.

    Attributes:
        kind: ``ellipsoid`` (``a`` its centre, ``size`` its half axes along ``rotation``'s
            columns), ``capsule`` or ``arrow`` (from ``a`` to ``b``, ``size[0]`` its radius).
        a: Centre or start (m).
        b: End (m; capsules and arrows).
        size: Half axes or radius (m).
        rotation: 3x3 rotation of an ellipsoid.
        rgba: Colour.
    """

    kind: Literal["ellipsoid", "capsule", "arrow"]
    a: np.ndarray
    b: np.ndarray = field(default_factory=lambda: np.zeros(3))
    size: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    rgba: tuple[float, float, float, float] = SKIN_RGBA


@dataclass(frozen=True)
class DisturbanceMarker:
    """A disturbance acting on an object now (or a moment ago).

    Attributes:
        kind: ``hand`` (a person carries it: a pull), ``push`` or ``knock``.
        obj: The object's name.
        contact: Where the hand or finger touches it (m, world).
        direction: Unit direction of the push (horizontal); for a hand, up (unused).
        above: A point over the object's top (a push's arrow goes there).
        acting: False while it lingers after the force ended.
    """

    kind: MarkerKind
    obj: str
    contact: np.ndarray
    direction: np.ndarray
    above: np.ndarray
    acting: bool = True

    def shapes(self) -> list[Shape]:
        """The primitives that draw it: a hand over the object, or a finger and hand behind it."""
        if self.kind == "hand":
            return _hand_shapes(self.contact)
        return _push_shapes(self.contact, self.direction, self.above)

    def moved(self, by: np.ndarray, acting: bool) -> DisturbanceMarker:
        """The same marker shifted by ``by`` (it follows its object while it lingers)."""
        return DisturbanceMarker(self.kind, self.obj, self.contact + by, self.direction, self.above + by, acting)


def _frame(x: np.ndarray) -> np.ndarray:
    """A rotation whose first column is the horizontal direction ``x`` (third column up)."""
    x = np.array([x[0], x[1], 0.0]) / max(float(np.hypot(x[0], x[1])), _EPS)
    z = np.array([0.0, 0.0, 1.0])
    return np.column_stack([x, np.cross(z, x), z])


def _forearm(palm: np.ndarray) -> np.ndarray:
    """Where the forearm of a hand at ``palm`` goes: up and across the table, leaning right (as seen from the front)."""
    return palm + FOREARM_LENGTH * FOREARM_DIRECTION


def _hand_shapes(top: np.ndarray) -> list[Shape]:
    """A hand closed over an object's top (``top``), the forearm up and away across the table."""
    palm = top + np.array([0.0, 0.012, 0.022])
    elbow = _forearm(palm)
    shapes = [
        Shape("ellipsoid", palm, size=np.array([0.045, 0.05, 0.018]), rotation=np.eye(3)),
        Shape("capsule", palm + 0.2 * (elbow - palm), elbow, size=np.array([0.028, 0.0, 0.0])),
    ]
    for side in (-1.0, 1.0):  # thumb and fingers down the object's sides
        knuckle = palm + np.array([side * 0.035, -0.01, -0.005])
        shapes.append(Shape("capsule", knuckle, knuckle + np.array([0.0, -0.01, -0.045]), size=np.array([0.01, 0, 0])))
    return shapes


def _push_shapes(contact: np.ndarray, direction: np.ndarray, above: np.ndarray) -> list[Shape]:
    """A finger touching ``contact`` from behind, its hand and forearm, and an arrow along ``direction`` over
    the object (``above``: over its top)."""
    rot = _frame(direction)
    d = rot[:, 0]
    up = np.array([0.0, 0.0, 1.0])
    tip = contact - 0.008 * d
    knuckle = tip - 0.07 * d + 0.01 * up
    palm = knuckle - 0.045 * d + 0.015 * up
    # Short, up and to the side behind the hand: straight back toward the front camera it would hide the object.
    elbow = palm - 0.06 * d + 0.13 * up - 0.11 * rot[:, 1]
    arrow_start = above - 0.06 * d
    return [
        Shape("capsule", tip, knuckle, size=np.array([0.009, 0.0, 0.0])),
        Shape("ellipsoid", palm, size=np.array([0.05, 0.04, 0.018]), rotation=rot),
        Shape("capsule", palm - 0.03 * d + 0.01 * up, elbow, size=np.array([0.026, 0.0, 0.0])),
        Shape("arrow", arrow_start, arrow_start + 0.14 * d, size=np.array([0.016, 0.0, 0.0]), rgba=ARROW_RGBA),
    ]


def read_marker(world, obj: str) -> DisturbanceMarker | None:
    """The disturbance acting on ``obj`` now, read from the wrench on its body (None: none acts).

    Args:
        world: The simulated world (``model``, ``data``, ``object_pose``, ``object_spec``).
        obj: One of its objects.
    """
    wrench = world.data.xfrc_applied[world.object_body_id(obj)]
    force, torque = wrench[:3], wrench[3:]
    if float(np.abs(wrench).max()) < _EPS:
        return None
    pos, matrix = world.object_pose(obj)
    spec = world.object_spec(obj)
    up = np.array([0.0, 0.0, 1.0])
    half_up = spec.half_extent_along(matrix, up)
    above = pos + (half_up + 0.04) * up
    if abs(float(force[2])) > _EPS:  # it carries the weight: a person's hand
        return DisturbanceMarker("hand", obj, pos + half_up * up, up, above)
    # A horizontal force F at r = (0, 0, h) from the centre: torque = (-h F_y, h F_x, 0).
    h = float(torque[1] / force[0]) if abs(force[0]) >= abs(force[1]) else float(-torque[0] / force[1])
    direction = np.array([force[0], force[1], 0.0]) / max(float(np.hypot(force[0], force[1])), _EPS)
    # Drawn on the object's side, between a finger's width over its foot and its top.
    height = float(np.clip(h, -half_up + 0.012, half_up - 0.005))
    contact = pos + height * up - spec.half_extent_along(matrix, direction) * direction
    return DisturbanceMarker("knock" if h > 0.0 else "push", obj, contact, direction, above)


class DisturbanceMarkers:
    """Follows a world's disturbances tick by tick: markers to draw, a push's a moment longer, carry trails.

    Call :meth:`update` once per control tick (every tick, also those not filmed: trails and
    lingering count ticks).

    Args:
        world: The simulated world.
        linger_ticks: Ticks a marker stays after its force ended.
    """

    def __init__(self, world, linger_ticks: int = LINGER_TICKS) -> None:
        self.world = world
        self.linger_ticks = linger_ticks
        self.markers: list[DisturbanceMarker] = []
        self.trails: dict[str, list[np.ndarray]] = {}
        # Per object: the last acting marker, where the object was then, and that tick.
        self._last: dict[str, tuple[DisturbanceMarker, np.ndarray, int]] = {}

    def update(self) -> list[DisturbanceMarker]:
        """The markers of this tick (acting, then lingering); also kept as :attr:`markers`."""
        world, tick = self.world, self.world.tick
        markers = []
        for obj in world.object_names:
            marker = read_marker(world, obj)
            pos = world.object_pose(obj)[0]
            if marker is not None:
                self._last[obj] = (marker, pos.copy(), tick)
                markers.append(marker)
                if marker.kind == "hand":
                    self._extend_trail(obj, pos, tick)
                continue
            last = self._last.get(obj)
            if last is None:
                continue
            previous, then, since = last
            if tick - since > self.linger_ticks:
                del self._last[obj]
                self.trails.pop(obj, None)
                continue
            markers.append(previous.moved(pos - then, acting=False))
        self.markers = markers
        return markers

    def _extend_trail(self, obj: str, pos: np.ndarray, tick: int) -> None:
        trail = self.trails.setdefault(obj, [])
        if tick % TRAIL_EVERY == 0 and len(trail) < TRAIL_POINTS:
            trail.append(pos.copy())

    def shapes(self) -> list[Shape]:
        """Every primitive to draw now: the markers and the trails (thin segments)."""
        shapes = [shape for marker in self.markers for shape in marker.shapes()]
        for trail in self.trails.values():
            shapes += [
                Shape("capsule", a, b, size=np.array([0.004, 0.0, 0.0]), rgba=TRAIL_RGBA)
                for a, b in pairwise(trail)
                if float(np.linalg.norm(b - a)) > 1e-4
            ]
        return shapes


_GEOM = {"ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID, "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
         "arrow": mujoco.mjtGeom.mjGEOM_ARROW}


def add_to_scene(scene: mujoco.MjvScene, shapes: list[Shape]) -> int:
    """Append ``shapes`` to a scene after ``update_scene`` (its free geoms); returns how many fit.

    Visual geoms of the scene only: nothing in the model or the data changes.
    """
    added = 0
    for shape in shapes:
        if scene.ngeom >= scene.maxgeom:
            break
        geom = scene.geoms[scene.ngeom]
        rgba = np.asarray(shape.rgba, dtype=np.float32)
        if shape.kind == "ellipsoid":
            mujoco.mjv_initGeom(geom, _GEOM["ellipsoid"], shape.size, shape.a, shape.rotation.reshape(-1), rgba)
        else:
            mujoco.mjv_initGeom(geom, _GEOM[shape.kind], np.zeros(3), np.zeros(3), np.eye(3).reshape(-1), rgba)
            mujoco.mjv_connector(geom, _GEOM[shape.kind], float(shape.size[0]), shape.a, shape.b)
        geom.category = mujoco.mjtCatBit.mjCAT_DECOR
        scene.ngeom += 1
        added += 1
    return added
