"""The fixed function library of the expression language.

Each :class:`Function` declares its parameters with their kinds, so the
compiler can refuse a wrong call (``holding(bottle, right)``) before it ever
runs. Implementations are plain Python over numpy arrays; the hot ones reduce
3-vectors through ``tolist()`` and :mod:`math`, which is several times faster
than numpy reductions on arrays this small.

Functions that read the frame take it as their first argument; object and arm
arguments arrive as their names (``"bottle"``, ``"right"``), resolved at
compile time.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import UP, FeatureFrame

#: A value of the language: a scalar or a vector.
Value = float | np.ndarray

_UX, _UY, _UZ = (float(c) for c in UP)


class ArgKind(enum.Enum):
    """What a parameter accepts or a function returns."""

    SCALAR = "scalar"
    VECTOR = "vector"
    OBJECT = "object"
    ARM = "arm"


@dataclass(frozen=True)
class Param:
    """One parameter of a library function.

    Attributes:
        name: Name shown in signatures and messages.
        kind: What the argument must be.
        size: Required vector length, ``None`` when any length fits.
    """

    name: str
    kind: ArgKind
    size: int | None = None


@dataclass(frozen=True)
class Function:
    """A callable of the language.

    Attributes:
        name: Name used in expressions.
        params: Parameters, in order.
        impl: Implementation; ``impl(frame, *args)`` when ``reads_frame``,
            else ``impl(*args)``.
        summary: One-line description of the result.
        returns: ``ArgKind.SCALAR`` or ``ArgKind.VECTOR``.
        returns_size: Length of a vector result; ``None`` means the length of
            the first vector argument.
        reads_frame: Whether ``impl`` takes the frame.
        variadic: Whether the last parameter may repeat (``min(a, b, c)``).
        same_size: Whether all vector arguments must have one length.
    """

    name: str
    params: tuple[Param, ...]
    impl: Callable[..., Value]
    summary: str
    returns: ArgKind = ArgKind.SCALAR
    returns_size: int | None = None
    reads_frame: bool = False
    variadic: bool = False
    same_size: bool = False

    @property
    def signature(self) -> str:
        """Call signature as written in expressions, e.g. ``dist(a, b)``."""
        names = [p.name for p in self.params]
        if self.variadic:
            names.append("...")
        return f"{self.name}({', '.join(names)})"

    @property
    def description(self) -> str:
        """Signature and summary on one line."""
        return f"{self.signature}: {self.summary}"


# --- pure vector/scalar functions -------------------------------------------------


def norm(v: np.ndarray) -> float:
    """Euclidean length of ``v``."""
    return math.hypot(*v.tolist())


def dot(a: np.ndarray, b: np.ndarray) -> float:
    """Dot product."""
    return float(a.dot(b))


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two 3-vectors (np.cross costs ~10 us on 3-vectors)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))


def dist(a: np.ndarray, b: np.ndarray) -> float:
    """Euclidean distance between two points."""
    return math.dist(a.tolist(), b.tolist())


def _angle3(a: list[float], b: list[float]) -> float:
    # atan2(|a x b|, a . b) stays accurate near 0 and 180 degrees, where acos does not.
    a0, a1, a2 = a
    b0, b1, b2 = b
    if (a0 == 0.0 and a1 == 0.0 and a2 == 0.0) or (b0 == 0.0 and b1 == 0.0 and b2 == 0.0):
        return math.nan
    cx = a1 * b2 - a2 * b1
    cy = a2 * b0 - a0 * b2
    cz = a0 * b1 - a1 * b0
    return math.degrees(math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), a0 * b0 + a1 * b1 + a2 * b2))


def angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two vectors in degrees; NaN when either is zero."""
    if a.shape == (3,) and b.shape == (3,):
        return _angle3(a.tolist(), b.tolist())
    na, nb = norm(a), norm(b)
    if na == 0.0 or nb == 0.0:
        return math.nan
    # Kahan's formula: accurate at every angle and for any length.
    ua, ub = a * nb, b * na
    return math.degrees(2.0 * math.atan2(norm(ua - ub), norm(ua + ub)))


def abs_(x: float) -> float:
    """Absolute value."""
    return abs(x)


def min_(*xs: float) -> float:
    """Smallest argument; NaN if any argument is NaN (as numpy does)."""
    for x in xs:
        if x != x:
            return math.nan
    return min(xs)


def max_(*xs: float) -> float:
    """Largest argument; NaN if any argument is NaN (as numpy does)."""
    for x in xs:
        if x != x:
            return math.nan
    return max(xs)


def clip(x: float, lo: float, hi: float) -> float:
    """``x`` limited to ``[lo, hi]`` (``hi`` wins when ``lo > hi``, as in numpy)."""
    if x != x or lo != lo or hi != hi:
        return math.nan
    return min(max(x, lo), hi)


def xy(v: np.ndarray) -> np.ndarray:
    """``v`` with its z component set to 0, for lateral distances."""
    out = v.copy()
    out[2] = 0.0
    return out


# --- functions of the frame ---------------------------------------------------------


def holding(frame: FeatureFrame, arm: str, obj: str) -> float:
    """1.0 when ``arm`` holds ``obj``, else 0.0."""
    return 1.0 if frame.is_holding(arm, obj) else 0.0


def tilt(frame: FeatureFrame, obj: str) -> float:
    """Angle in degrees between the object's principal axis and world up."""
    return _angle3(frame.objects[obj].axis.tolist(), [_UX, _UY, _UZ])


def ref(frame: FeatureFrame, obj: str) -> np.ndarray:
    """Reference position of ``obj``, captured at the start of the active edge."""
    return frame.refs[obj]


def at(frame: FeatureFrame, obj: str, fraction: float) -> np.ndarray:
    """Point at ``fraction`` along the object's axis: 0 = bottom, 1 = top."""
    return frame.objects[obj].at(fraction)


def local(frame: FeatureFrame, obj: str, p: np.ndarray) -> np.ndarray:
    """``p`` (world frame) in the object's own frame: ``R(obj.quat)^T (p - obj.pos)``.

    Along the object's axes its extents are measured, so a footprint reads as two bounds
    (a capsule inside a long tray: ``abs(local(tray, capsule.pos)[0]) - 0.11``).
    """
    o = frame.objects[obj]
    w, x, y, z = o.quat.tolist()
    d0, d1, d2 = (p - o.pos).tolist()
    return np.array([
        (1.0 - 2.0 * (y * y + z * z)) * d0 + 2.0 * (x * y + w * z) * d1 + 2.0 * (x * z - w * y) * d2,
        2.0 * (x * y - w * z) * d0 + (1.0 - 2.0 * (x * x + z * z)) * d1 + 2.0 * (y * z + w * x) * d2,
        2.0 * (x * z + w * y) * d0 + 2.0 * (y * z - w * x) * d1 + (1.0 - 2.0 * (x * x + y * y)) * d2,
    ])


_S, _V, _O, _A = ArgKind.SCALAR, ArgKind.VECTOR, ArgKind.OBJECT, ArgKind.ARM

#: The library, by name, in the order listed to users.
LIBRARY: dict[str, Function] = {
    f.name: f
    for f in (
        Function("norm", (Param("v", _V),), norm, "Euclidean length of vector v."),
        Function("dot", (Param("a", _V), Param("b", _V)), dot, "dot product of vectors a and b.", same_size=True),
        Function(
            "cross",
            (Param("a", _V, 3), Param("b", _V, 3)),
            cross,
            "cross product of 3-vectors a and b.",
            returns=_V,
            returns_size=3,
        ),
        Function(
            "dist", (Param("a", _V), Param("b", _V)), dist, "distance between points a and b (m).", same_size=True
        ),
        Function(
            "angle", (Param("a", _V), Param("b", _V)), angle, "angle between vectors a and b (degrees).", same_size=True
        ),
        Function("abs", (Param("x", _S),), abs_, "absolute value of scalar x."),
        Function("min", (Param("a", _S), Param("b", _S)), min_, "smallest of two or more scalars.", variadic=True),
        Function("max", (Param("a", _S), Param("b", _S)), max_, "largest of two or more scalars.", variadic=True),
        Function("clip", (Param("x", _S), Param("lo", _S), Param("hi", _S)), clip, "x limited to [lo, hi]."),
        Function(
            "holding",
            (Param("arm", _A), Param("obj", _O)),
            holding,
            "1.0 when the arm holds the object in a grasp, else 0.0.",
            reads_frame=True,
        ),
        Function(
            "tilt",
            (Param("obj", _O),),
            tilt,
            "angle between the object's principal axis and world up (degrees; 0 = upright).",
            reads_frame=True,
        ),
        Function(
            "ref",
            (Param("obj", _O),),
            ref,
            "reference position of the object, captured at the start of the active edge.",
            returns=_V,
            returns_size=3,
            reads_frame=True,
        ),
        Function(
            "at",
            (Param("obj", _O), Param("f", _S)),
            at,
            "point at fraction f along the object's axis (0 = bottom, 1 = top).",
            returns=_V,
            returns_size=3,
            reads_frame=True,
        ),
        Function(
            "local",
            (Param("obj", _O), Param("p", _V, 3)),
            local,
            "point p (world frame) in the object's own frame, along the axes its extents are measured on.",
            returns=_V,
            returns_size=3,
            reads_frame=True,
        ),
        Function(
            "xy", (Param("v", _V, 3),), xy, "v with z set to 0, for lateral distances.", returns=_V, returns_size=3
        ),
    )
}
