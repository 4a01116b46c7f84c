"""The feature frame Phi_t (paper Eq. 1): what constraints and monitors read.

A frame is a plain container of numpy arrays, rebuilt every control tick by an
extractor (oracle: simulator state; RGB-D: point clouds). Expressions of the
safe language (:mod:`agentchord.expr`) are compiled into callables that read
these fields directly, so the layout here is the contract between perception
and the expression language.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from agentchord.robot.aloha import ARMS  # re-exported: the frame's arms

#: World "up": gravity points along -UP.
UP = np.array([0.0, 0.0, 1.0])

#: Attributes an expression may read on an object (``bottle.pos``).
OBJECT_ATTRIBUTES = ("pos", "quat", "axis", "extent", "top", "bottom", "points")
#: Attributes an expression may read on an arm (``right.width``).
ARM_ATTRIBUTES = ("ee", "ee_quat", "q", "width", "closed")


def tilt_deg(axis) -> float:
    """Angle (deg) between a principal axis (bottom to top) and world up."""
    return float(np.degrees(np.arccos(np.clip(axis[2], -1.0, 1.0))))


def level_tilt_deg(axis) -> float:
    """Angle (deg, 0-90) between a principal axis's line and the vertical: an object upside down
    (a flipped fork) lies as level as one the right way up, and is not lying on its side."""
    return float(np.degrees(np.arccos(np.clip(abs(axis[2]), 0.0, 1.0))))


#: Largest extent (m) of a point feature (a cloth's corner) rather than a body.
POINT_EXTENT = 0.01


@dataclass
class ObjectFeatures:
    """Geometric features of one object.

    Attributes:
        pos: Centre, world frame (m).
        quat: Orientation (w, x, y, z).
        axis: Unit principal axis (a bottle's bottom-to-top direction).
        extent: Full size along the object's principal axes (m).
        top: Extremal point at the top end of the principal axis.
        bottom: Extremal point at the bottom end of the principal axis.
        points: Number of visible points (oracle mode: a constant large count).
    """

    pos: np.ndarray
    quat: np.ndarray
    axis: np.ndarray
    extent: np.ndarray
    top: np.ndarray
    bottom: np.ndarray
    points: float = 1000.0

    @property
    def is_point(self) -> bool:
        """Whether this is a point feature (a cloth's corner, lying flat in the cloth) rather than a body."""
        return bool(self.extent.max() < POINT_EXTENT)  # the method, not np.max: read for every object every tick

    def at(self, fraction: float) -> np.ndarray:
        """Fractional point along the principal axis: 0 = bottom, 1 = top."""
        return self.bottom + fraction * (self.top - self.bottom)


@dataclass
class ArmFeatures:
    """Measurable robot signals of one arm.

    Attributes:
        ee: Tool centre point between the fingers, world frame (m).
        ee_quat: Tool orientation (w, x, y, z).
        q: Joint configuration of the 6 arm joints (rad).
        width: Gripper opening between the finger pads (m).
        closed: 1.0 when the gripper is commanded closed, else 0.0.
    """

    ee: np.ndarray
    ee_quat: np.ndarray
    q: np.ndarray
    width: float
    closed: float


@dataclass
class FeatureFrame:
    """Everything a constraint or monitor may read at one tick.

    Attributes:
        objects: Features per object name.
        arms: Features per arm name (``left``, ``right``).
        holding: Arm/object pairs in a grasp (contact-based in sim).
        refs: Reference positions per object, captured at the start of the
            active edge (``ref(bottle)`` in expressions, Eq. 14).
        tick: Control tick the frame was taken at.
    """

    objects: dict[str, ObjectFeatures]
    arms: dict[str, ArmFeatures]
    holding: set[tuple[str, str]] = field(default_factory=set)
    refs: dict[str, np.ndarray] = field(default_factory=dict)
    tick: int = 0

    def is_holding(self, arm: str, obj: str) -> bool:
        """Whether ``arm`` holds ``obj`` in a grasp."""
        return (arm, obj) in self.holding

    def capture_refs(self) -> None:
        """Take the current object positions as the references of ``ref(obj)``."""
        self.refs = {name: feats.pos.copy() for name, feats in self.objects.items()}


def make_static_frame(
    objects: dict[str, dict[str, object]] | None = None,
    arms: dict[str, dict[str, object]] | None = None,
    holding: set[tuple[str, str]] | None = None,
) -> FeatureFrame:
    """Build a frame from plain values: for tests, docs and offline checks.

    Missing fields get neutral defaults (an upright 10 cm object at the origin,
    an open gripper at the origin).
    """
    frame_objects: dict[str, ObjectFeatures] = {}
    for name, values in (objects or {}).items():
        pos = np.asarray(values.get("pos", (0.0, 0.0, 0.05)), dtype=float)
        axis = np.asarray(values.get("axis", UP), dtype=float)
        extent = np.asarray(values.get("extent", (0.05, 0.05, 0.1)), dtype=float)
        half = 0.5 * float(extent[2]) * axis
        frame_objects[name] = ObjectFeatures(
            pos=pos,
            quat=np.asarray(values.get("quat", (1.0, 0.0, 0.0, 0.0)), dtype=float),
            axis=axis,
            extent=extent,
            top=np.asarray(values.get("top", pos + half), dtype=float),
            bottom=np.asarray(values.get("bottom", pos - half), dtype=float),
            points=float(values.get("points", 1000.0)),
        )
    frame_arms: dict[str, ArmFeatures] = {}
    for name in ARMS:
        values = (arms or {}).get(name, {})
        frame_arms[name] = ArmFeatures(
            ee=np.asarray(values.get("ee", (0.0, 0.0, 0.2)), dtype=float),
            ee_quat=np.asarray(values.get("ee_quat", (1.0, 0.0, 0.0, 0.0)), dtype=float),
            q=np.asarray(values.get("q", np.zeros(6)), dtype=float),
            width=float(values.get("width", 0.08)),
            closed=float(values.get("closed", 0.0)),
        )
    frame = FeatureFrame(objects=frame_objects, arms=frame_arms, holding=set(holding or ()))
    frame.capture_refs()
    return frame
