"""Tests of the monitor templates (agentchord.expr.templates, paper Eq. 14-19)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from agentchord.expr import FUNCTIONS, TEMPLATES, ExprTypeError, Vocabulary, compile_expr
from agentchord.expr.templates import TEMPLATE_FUNCTIONS
from agentchord.features.frame import make_static_frame

VOCAB = Vocabulary(objects={"bottle", "cup"})


def make_frame(**cup):
    return make_static_frame(
        objects={
            "bottle": {"pos": (0.30, 0.10, 0.10)},
            "cup": {"pos": (0.40, -0.10, 0.05), **cup},
        },
        arms={"right": {"ee": (0.30, 0.10, 0.14), "width": 0.004, "closed": 1.0}, "left": {"width": 0.06}},
        holding={("right", "bottle")},
    )


def monitor(source: str, frame) -> float:
    return compile_expr(source, VOCAB).scalar(frame)


def test_drift_eq14() -> None:
    frame = make_frame()
    assert monitor("drift(cup, 0.03)", frame) == pytest.approx(-0.03)
    frame.objects["cup"].pos = np.array([0.44, -0.07, 0.05])  # moved 5 cm from the captured reference
    assert monitor("drift(cup, 0.03)", frame) == pytest.approx(0.02)
    assert monitor("drift(cup, 0.03)", frame) == pytest.approx(monitor("norm(cup.pos - ref(cup)) - 0.03", frame))


@pytest.mark.parametrize(("axis", "value"), [((0, 0, 1), -30.0), ((1, 0, 1), 15.0), ((0, 1, 0), 60.0)])
def test_tipped_eq15(axis: tuple[float, float, float], value: float) -> None:
    frame = make_frame(axis=axis)
    assert monitor("tipped(cup, 30)", frame) == pytest.approx(value)
    assert monitor("tipped(cup, 30)", frame) == pytest.approx(monitor("tilt(cup) - 30", frame))


def test_grip_empty_eq16() -> None:
    frame = make_frame()
    # right fingers at 4 mm: closed past a 2 cm minimum object width -> nothing in the grasp.
    assert monitor("grip_empty(right, 0.02)", frame) == pytest.approx(0.016)
    assert monitor("grip_empty(left, 0.02)", frame) == pytest.approx(-0.04)
    assert monitor("right.closed * grip_empty(right, 0.02)", frame) == pytest.approx(0.016)


def test_slipped_eq17() -> None:
    frame = make_frame()
    assert monitor("slipped(right, bottle, 0.08)", frame) == pytest.approx(0.04 - 0.08)
    frame.objects["bottle"].pos = np.array([0.30, 0.10, 0.02])  # fell 8 cm below the fingers
    assert monitor("slipped(right, bottle, 0.08)", frame) == pytest.approx(0.12 - 0.08)
    assert monitor("slipped(right, bottle, 0.08)", frame) == pytest.approx(
        monitor("dist(bottle.pos, right.ee) - 0.08", frame)
    )


def test_lost_view_eq18() -> None:
    assert monitor("lost_view(cup, 50)", make_frame(points=1000)) == -950.0
    assert monitor("lost_view(cup, 50)", make_frame(points=12)) == 38.0


def test_misaligned_eq19() -> None:
    frame = make_frame()
    # Lateral offset only: the 5 cm height difference is ignored.
    assert monitor("misaligned(bottle.pos, cup.pos, 0.03)", frame) == pytest.approx(math.hypot(0.1, 0.2) - 0.03)
    assert monitor("misaligned(bottle.pos, cup.pos + [-0.1, 0.2, 0.7], 0.03)", frame) == pytest.approx(-0.03)
    assert monitor("misaligned([0, 0, 0], [3, 4, 9], 1)", frame) == 4.0  # folded at compile time
    assert monitor("misaligned(bottle.pos, cup.pos, 0.03)", frame) == pytest.approx(
        monitor("norm(xy(bottle.pos - cup.pos)) - 0.03", frame)
    )


@pytest.mark.parametrize("name", sorted(TEMPLATES))
def test_template_examples_compile_and_are_normal_on_a_nominal_frame(name: str) -> None:
    info = TEMPLATES[name]
    assert info.signature.startswith(f"{name}(")
    assert name in info.example
    assert 14 <= info.equation <= 19
    expr = compile_expr(info.example, VOCAB)
    frame = make_static_frame(
        objects={"bottle": {"pos": (0.4, 0.1, 0.2)}, "cup": {"pos": (0.35, 0.2, 0.05)}},
        arms={"right": {"ee": (0.4, 0.1, 0.2), "width": 0.06, "closed": 1.0}},
        holding={("right", "bottle")},
    )
    assert expr.scalar(frame) <= 0.0


def test_templates_are_functions_of_the_language() -> None:
    assert set(TEMPLATES) == set(TEMPLATE_FUNCTIONS)
    for name, function in TEMPLATE_FUNCTIONS.items():
        assert FUNCTIONS[name] == function.description
        assert function.signature == TEMPLATES[name].signature


@pytest.mark.parametrize(
    "source",
    [
        "drift(right, 0.03)",
        "drift(cup)",
        "drift(cup, cup.pos)",
        "tipped(0.3, cup)",
        "grip_empty(bottle, 0.02)",
        "slipped(bottle, right, 0.05)",
        "lost_view(cup)",
        "misaligned(bottle, cup, 0.02)",
        "misaligned(bottle.quat, cup.pos, 0.02)",
    ],
)
def test_wrong_template_calls_are_refused(source: str) -> None:
    with pytest.raises(ExprTypeError):
        compile_expr(source, VOCAB)
