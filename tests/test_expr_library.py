"""Tests of the function library (agentchord.expr.library), through compiled expressions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from agentchord.expr import FUNCTIONS, ArgKind, ExprTypeError, Vocabulary, compile_expr
from agentchord.expr.library import LIBRARY, angle, cross, xy
from agentchord.features.frame import make_static_frame

VOCAB = Vocabulary(objects={"bottle", "cup"})


def evaluate(source: str, frame=None, **kwargs) -> float | np.ndarray:
    frame = frame if frame is not None else make_frame()
    return compile_expr(source, VOCAB, **kwargs)(frame)


def make_frame(**bottle):
    return make_static_frame(
        objects={
            "bottle": {"pos": (0.3, 0.1, 0.1), "extent": (0.06, 0.06, 0.2), **bottle},
            "cup": {"pos": (0.4, -0.1, 0.05)},
        },
        arms={"right": {"ee": (0.3, 0.1, 0.12), "width": 0.05, "closed": 1.0}},
        holding={("right", "bottle")},
    )


VALUE_CASES = [
    ("norm([3, 4, 12])", 13.0),
    ("norm(cup.pos - bottle.pos)", math.sqrt(0.1**2 + 0.2**2 + 0.05**2)),
    ("dot([1, 2, 3], [4, 5, 6])", 32.0),
    ("dot(bottle.pos, [0, 0, 1])", 0.1),
    ("cross([1, 0, 0], [0, 1, 0])[2]", 1.0),
    ("cross(bottle.axis, [1, 0, 0])[1]", 1.0),
    ("dist(bottle.pos, cup.pos)", math.sqrt(0.1**2 + 0.2**2 + 0.05**2)),
    ("dist([0, 0, 0], [1, 2, 2])", 3.0),
    ("angle([1, 0, 0], [0, 1, 0])", 90.0),
    ("angle([1, 0, 0], [-1, 0, 0])", 180.0),
    ("angle([1, 1, 0, 0], [1, 0, 0, 0])", 45.0),
    ("angle(bottle.axis, [0, 0, 1])", 0.0),
    ("abs(-2.5)", 2.5),
    ("abs(cup.pos[1])", 0.1),
    ("min(3, 1, 2)", 1.0),
    ("max(3, 1, 2)", 3.0),
    ("min(right.width, 0.02)", 0.02),
    ("max(bottle.pos[0], cup.pos[0])", 0.4),
    ("clip(5, 0, 1)", 1.0),
    ("clip(-5, 0, 1)", 0.0),
    ("clip(0.5, 0, 1)", 0.5),
    ("clip(right.width, 0, 0.01)", 0.01),
    ("holding(right, bottle)", 1.0),
    ("holding(right, cup)", 0.0),
    ("holding(left, bottle)", 0.0),
    ("tilt(bottle)", 0.0),
    ("norm(ref(cup) - cup.pos)", 0.0),
    ("ref(cup)[0]", 0.4),
    ("at(bottle, 0)[2]", 0.0),
    ("at(bottle, 1)[2]", 0.2),
    ("at(bottle, 0.5)[2]", 0.1),
    ("norm(xy([3, 4, 5]))", 5.0),
    ("xy(bottle.pos)[2]", 0.0),
    ("xy(bottle.pos)[0]", 0.3),
    ("local(cup, bottle.pos)[0]", -0.1),
    ("local(cup, cup.pos)[2]", 0.0),
]


@pytest.mark.parametrize(("source", "expected"), VALUE_CASES)
def test_function_values(source: str, expected: float) -> None:
    assert evaluate(source) == pytest.approx(expected, abs=1e-12)


def test_every_library_function_is_exercised_above() -> None:
    # Guards against a function added to the library without a value test.
    tested = {name for name in LIBRARY if any(source.startswith(f"{name}(") for source, _ in VALUE_CASES)}
    assert tested == set(LIBRARY)


@pytest.mark.parametrize(
    ("axis", "degrees"),
    [
        ((0.0, 0.0, 1.0), 0.0),
        ((1.0, 0.0, 0.0), 90.0),
        ((0.0, -1.0, 0.0), 90.0),
        ((0.0, 0.0, -1.0), 180.0),
        ((1.0, 0.0, 1.0), 45.0),
        ((0.0, 2.0, 2.0), 45.0),  # not normalised
        ((math.sin(math.radians(1e-4)), 0.0, math.cos(math.radians(1e-4))), 1e-4),  # accurate near upright
    ],
)
def test_tilt(axis: tuple[float, float, float], degrees: float) -> None:
    assert evaluate("tilt(bottle)", make_frame(axis=axis)) == pytest.approx(degrees, rel=1e-9, abs=1e-12)


def test_tilt_of_degenerate_axis_is_nan() -> None:
    assert math.isnan(evaluate("tilt(bottle)", make_frame(axis=(0.0, 0.0, 0.0))))


def test_holding_follows_the_frame() -> None:
    expr = compile_expr("0.5 - holding(right, bottle)", VOCAB)
    frame = make_frame()
    assert expr(frame) == -0.5
    frame.holding.clear()
    assert expr(frame) == 0.5


def test_ref_is_captured_at_edge_start() -> None:
    expr = compile_expr("dist(cup.pos, ref(cup))", VOCAB)
    frame = make_frame()
    assert expr(frame) == 0.0
    frame.objects["cup"].pos = frame.objects["cup"].pos + np.array([0.03, 0.04, 0.0])
    assert expr(frame) == pytest.approx(0.05)
    frame.capture_refs()
    assert expr(frame) == 0.0


def test_vector_results_are_numpy_when_allowed() -> None:
    out = evaluate("cup.top + [0.05, -0.10, 0.10]", allow_vector=True)
    assert isinstance(out, np.ndarray)
    np.testing.assert_allclose(out, [0.45, -0.2, 0.2])
    np.testing.assert_allclose(evaluate("ref(bottle)", allow_vector=True), [0.3, 0.1, 0.1])
    np.testing.assert_allclose(evaluate("at(bottle, 0.25)", allow_vector=True), [0.3, 0.1, 0.05])


@pytest.mark.parametrize("seed", range(5))
def test_local_is_the_point_in_the_objects_own_frame(seed: int) -> None:
    rng = np.random.default_rng(seed)
    quat = rng.normal(size=4)
    quat /= np.linalg.norm(quat)
    point = rng.normal(size=3)
    frame = make_static_frame(objects={"bottle": {"pos": (0.3, 0.1, 0.1), "quat": tuple(quat)}, "cup": {"pos": tuple(point)}})
    rotation = Rotation.from_quat(quat, scalar_first=True)
    expected = rotation.inv().apply(point - np.array([0.3, 0.1, 0.1]))
    got = compile_expr("local(bottle, cup.pos)", VOCAB, allow_vector=True)(frame)
    np.testing.assert_allclose(got, expected, atol=1e-12)


def test_local_reads_a_yawed_tray_along_its_length() -> None:
    # Turned 90 deg about z: a point 10 cm along world +x lies 10 cm along the object's -y.
    yaw = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))
    frame = make_static_frame(objects={"bottle": {"pos": (0.0, 0.5, 0.0), "quat": yaw}, "cup": {"pos": (0.1, 0.5, 0.0)}})
    got = compile_expr("local(bottle, cup.pos)", VOCAB, allow_vector=True)(frame)
    np.testing.assert_allclose(got, [0.0, -0.1, 0.0], atol=1e-12)


def test_xy_does_not_alter_the_frame() -> None:
    frame = make_frame()
    compile_expr("norm(xy(bottle.pos))", VOCAB)(frame)
    np.testing.assert_array_equal(frame.objects["bottle"].pos, [0.3, 0.1, 0.1])


def test_nan_propagates_through_min_max_clip() -> None:
    nan = "(1e308 * 10 - 1e308 * 10)"  # inf - inf
    for source in (f"min({nan}, 1)", f"min(1, {nan})", f"max(1, {nan})", f"clip({nan}, 0, 1)", f"clip(0.5, {nan}, 1)"):
        assert math.isnan(evaluate(source))


def test_angle_of_zero_vector_is_nan() -> None:
    assert math.isnan(angle(np.zeros(3), np.array([1.0, 0.0, 0.0])))
    assert math.isnan(angle(np.zeros(4), np.ones(4)))


def test_pure_helpers_match_numpy() -> None:
    rng = np.random.default_rng(0)
    for _ in range(50):
        a, b = rng.normal(size=3), rng.normal(size=3)
        np.testing.assert_allclose(cross(a, b), np.cross(a, b), atol=1e-15)
        expected = math.degrees(math.acos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1)))
        assert angle(a, b) == pytest.approx(expected, abs=1e-6)
        assert angle(np.append(a, 0.0), np.append(b, 0.0)) == pytest.approx(expected, abs=1e-6)
        assert xy(a)[2] == 0.0 and a[2] != 0.0


@pytest.mark.parametrize(
    ("source", "part"),
    [
        ("cross([1, 0], [0, 1])", "[1, 0]"),
        ("xy([1, 2])", "[1, 2]"),
        ("dist(bottle.pos, bottle.quat)", "dist(bottle.pos, bottle.quat)"),
        ("dot(right.q, cup.pos)", "dot(right.q, cup.pos)"),
        ("abs(bottle.pos)", "bottle.pos"),
        ("norm(right.width)", "right.width"),
        ("min(1)", "min(1)"),
        ("clip(1, 2)", "clip(1, 2)"),
        ("holding(right)", "holding(right)"),
        ("tilt(right)", "right"),
        ("ref(bottle.pos)", "bottle.pos"),
        ("at(bottle, cup.pos)", "cup.pos"),
        ("dist(bottle, cup)", "bottle"),
        ("local(cup.pos, bottle.pos)", "cup.pos"),
        ("local(cup, 1)", "1"),
        ("local(cup, [1, 2])", "[1, 2]"),
    ],
)
def test_wrong_calls_are_type_errors(source: str, part: str) -> None:
    with pytest.raises(ExprTypeError) as info:
        compile_expr(source, VOCAB)
    assert info.value.part == part
    assert part in str(info.value)


def test_descriptions_name_every_function() -> None:
    for name, function in LIBRARY.items():
        assert FUNCTIONS[name].startswith(f"{name}(")
        assert function.returns in (ArgKind.SCALAR, ArgKind.VECTOR)
