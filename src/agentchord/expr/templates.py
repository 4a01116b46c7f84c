"""Monitor templates of the paper (Eq. 14-19) as functions of the language.

Each template returns a scalar that is > 0 when its failure is present and
<= 0 during normal execution, so a monitor can be the bare call
(``"drift(cup, 0.03)"``) or a composition of it. Tolerances are explicit
arguments: the arranger picks them from shared defaults or scene geometry.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from agentchord.expr.library import ArgKind, Function, Param, tilt
from agentchord.features.frame import FeatureFrame


def drift(frame: FeatureFrame, obj: str, eps: float) -> float:
    """Eq. 14, pose drift: ``||obj.pos - ref(obj)|| - eps``."""
    return math.dist(frame.objects[obj].pos.tolist(), frame.refs[obj].tolist()) - eps


def tipped(frame: FeatureFrame, obj: str, eps_deg: float) -> float:
    """Eq. 15, uprightness violation: ``tilt(obj) - eps_deg``."""
    return tilt(frame, obj) - eps_deg


def grip_empty(frame: FeatureFrame, arm: str, w_min: float) -> float:
    """Eq. 16, not fully grasped: ``w_min - arm.width``.

    Fingers closed past the smallest object width have nothing between them.
    """
    return w_min - frame.arms[arm].width


def slipped(frame: FeatureFrame, arm: str, obj: str, d_max: float) -> float:
    """Eq. 17, slipped grasp: ``||obj.pos - arm.ee|| - d_max``."""
    return math.dist(frame.objects[obj].pos.tolist(), frame.arms[arm].ee.tolist()) - d_max


def lost_view(frame: FeatureFrame, obj: str, n_min: float) -> float:
    """Eq. 18, visibility loss: ``n_min - obj.points``."""
    return n_min - frame.objects[obj].points


def misaligned(a: np.ndarray, b: np.ndarray, eps: float) -> float:
    """Eq. 19, relational misalignment: ``||xy(a - b)|| - eps`` (lateral offset)."""
    a0, a1 = a.tolist()[:2]
    b0, b1 = b.tolist()[:2]
    return math.hypot(a0 - b0, a1 - b1) - eps


class TemplateInfo(NamedTuple):
    """What a prompt needs to know about a template.

    Attributes:
        signature: Call signature, e.g. ``drift(obj, eps)``.
        description: One line: the failure it detects and its formula.
        example: A monitor string using it.
        equation: Equation number in the paper.
    """

    signature: str
    description: str
    example: str
    equation: int


_S, _V, _O, _A = ArgKind.SCALAR, ArgKind.VECTOR, ArgKind.OBJECT, ArgKind.ARM

#: Templates as callables of the language, by name.
TEMPLATE_FUNCTIONS: dict[str, Function] = {
    f.name: f
    for f in (
        Function(
            "drift",
            (Param("obj", _O), Param("eps", _S)),
            drift,
            "object moved more than eps (m) from its reference: ||obj.pos - ref(obj)|| - eps.",
            reads_frame=True,
        ),
        Function(
            "tipped",
            (Param("obj", _O), Param("eps_deg", _S)),
            tipped,
            "object tilted more than eps_deg from upright: tilt(obj) - eps_deg.",
            reads_frame=True,
        ),
        Function(
            "grip_empty",
            (Param("arm", _A), Param("w_min", _S)),
            grip_empty,
            "fingers closed past the smallest object width w_min (m), nothing held: w_min - arm.width.",
            reads_frame=True,
        ),
        Function(
            "slipped",
            (Param("arm", _A), Param("obj", _O), Param("d_max", _S)),
            slipped,
            "object farther than d_max (m) from the gripper: ||obj.pos - arm.ee|| - d_max.",
            reads_frame=True,
        ),
        Function(
            "lost_view",
            (Param("obj", _O), Param("n_min", _S)),
            lost_view,
            "fewer than n_min visible points on the object: n_min - obj.points.",
            reads_frame=True,
        ),
        Function(
            "misaligned",
            (Param("a", _V, 3), Param("b", _V, 3), Param("eps", _S)),
            misaligned,
            "points a and b laterally farther apart than eps (m): ||xy(a - b)|| - eps.",
        ),
    )
}

#: Template name -> signature, one-line description, example monitor, equation.
TEMPLATES: dict[str, TemplateInfo] = {
    "drift": TemplateInfo(
        "drift(obj, eps)",
        "pose drift / shifted object: the object moved more than eps metres from its reference position",
        "drift(cup, 0.03)",
        14,
    ),
    "tipped": TemplateInfo(
        "tipped(obj, eps_deg)",
        "tilted object: its principal axis is more than eps_deg degrees from world up",
        "tipped(bottle, 30)",
        15,
    ),
    "grip_empty": TemplateInfo(
        "grip_empty(arm, w_min)",
        "not fully grasped: the gripper closed narrower than w_min metres, so nothing is between the fingers",
        "right.closed * grip_empty(right, 0.02)",
        16,
    ),
    "slipped": TemplateInfo(
        "slipped(arm, obj, d_max)",
        "slipped grasp: the object is farther than d_max metres from the gripper",
        "slipped(right, bottle, 0.08)",
        17,
    ),
    "lost_view": TemplateInfo(
        "lost_view(obj, n_min)",
        "tracking loss: fewer than n_min valid points of the object are visible",
        "lost_view(cup, 50)",
        18,
    ),
    "misaligned": TemplateInfo(
        "misaligned(a, b, eps)",
        "relational misalignment: points a and b are laterally (in x-y) farther apart than eps metres",
        "misaligned(bottle.pos, cup.top + [0.05, -0.10, 0.0], 0.03)",
        19,
    ),
}
