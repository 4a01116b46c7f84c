"""Tests of the expression compiler (agentchord.expr.compiler)."""

from __future__ import annotations

import ast
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from agentchord.expr import (
    MAX_DEPTH,
    CompiledExpr,
    ExprError,
    ExprEvalError,
    ExprForbiddenError,
    ExprNameError,
    ExprSyntaxError,
    ExprTypeError,
    Vocabulary,
    compile_expr,
)
from agentchord.features.frame import make_static_frame

VOCAB = Vocabulary(objects={"bottle", "cup"})


@pytest.fixture
def frame():
    return make_static_frame(
        objects={
            "bottle": {"pos": (0.30, 0.10, 0.15), "axis": (0.0, 1.0, 0.0)},  # lying on its side
            "cup": {"pos": (0.40, -0.10, 0.05), "extent": (0.08, 0.08, 0.10)},
        },
        arms={"right": {"ee": (0.30, 0.10, 0.18), "width": 0.05, "closed": 1.0}},
        holding={("right", "bottle")},
    )


# --- the design's example strings -----------------------------------------------------


def test_examples_compile_and_give_the_right_numbers(frame) -> None:
    cup_top = np.array([0.40, -0.10, 0.10])
    bottle = np.array([0.30, 0.10, 0.15])
    target = cup_top + np.array([0.05, -0.10, 0.10])
    expected = {
        "0.5 - holding(right, bottle)": -0.5,
        "dist(bottle.pos, cup.top + [0.05, -0.10, 0.10]) - 0.03": float(np.linalg.norm(bottle - target)) - 0.03,
        "tilt(bottle) - 20": 70.0,
        "right.closed * (0.5 - holding(right, bottle))": -0.5,
        "dist(cup.pos, ref(cup)) - 0.02": -0.02,
        "bottle.bottom[2] - 0.01": 0.15 - 0.05 * 0 - 0.01,  # axis is horizontal: bottom at centre height
    }
    for source, value in expected.items():
        expr = compile_expr(source, VOCAB)
        assert expr.source == source
        assert expr.is_scalar
        assert expr(frame) == pytest.approx(value, abs=1e-12), source
        assert isinstance(expr.scalar(frame), float)


def test_examples_react_to_the_frame(frame) -> None:
    dropped = compile_expr("right.closed * (0.5 - holding(right, bottle))", VOCAB)
    moved = compile_expr("dist(cup.pos, ref(cup)) - 0.02", VOCAB)
    frame.holding.clear()
    assert dropped(frame) == 0.5
    frame.arms["right"].closed = 0.0
    assert dropped(frame) == 0.0
    frame.objects["cup"].pos = frame.objects["cup"].pos + np.array([0.0, 0.05, 0.0])
    assert moved(frame) == pytest.approx(0.03)


def test_referenced_names_are_reported() -> None:
    expr = compile_expr("slipped(right, bottle, 0.05) + left.width - norm(cup.pos)", VOCAB)
    assert expr.objects == {"bottle", "cup"}
    assert expr.arms == {"left", "right"}
    assert compile_expr("1 + 2", VOCAB).objects == frozenset()


# --- the language -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("1 + 2 * 3", 7.0),
        ("(1 + 2) * 3", 9.0),
        ("2 ** 3 ** 2", 512.0),  # right-associative, as in Python
        ("-2 ** 2", -4.0),
        ("2 ** -1", 0.5),
        ("+3 - -3", 6.0),
        ("7 / 2", 3.5),
        ("1 / 0", math.inf),
        ("-1 / 0", -math.inf),
        ("[1, 2, 3][-1]", 3.0),
        ("(1, 2, 3)[0]", 1.0),
        ("norm([1, 2] * 3)", math.hypot(3, 6)),  # numpy semantics, never list repetition
        ("norm([3, 4] + 1)", math.hypot(4, 5)),
        ("(-8) ** 0.5", math.nan),  # never a complex number
        ("1e308 * 10", math.inf),
        ("10.0 ** 10 ** 10 ** 0", 1e10),
        ("cup.pos[1]", -0.10),
        ("right.q[5]", 0.0),
        ("right.ee_quat[0]", 1.0),
        ("cup.extent[2] / 2", 0.05),
        ("cup.points - 1000", 0.0),
        ("norm(bottle.axis)", 1.0),
        ("norm(bottle.pos - bottle.pos)", 0.0),
        ("dist(at(cup, 0.5), cup.pos)", 0.0),
        ("norm([bottle.pos[0], cup.pos[1], 0] - [0.3, -0.1, 0])", 0.0),
        ("(right.width - 0.01) ** 2", 0.04**2),
        ("right.width ** 0.5", math.sqrt(0.05)),
        ("right.width / 0", math.inf),
        ("0 / (right.width - 0.05)", math.nan),
        ("  tilt(bottle) - 20", 70.0),  # a leading space is harmless
        ("\n  tilt(bottle) - 20\n", 70.0),  # so are the blanks of a YAML block scalar
        ("dist(bottle.pos,\n     cup.pos)", math.sqrt(0.1**2 + 0.2**2 + 0.1**2)),
    ],
)
def test_language_values(frame, source: str, expected: float) -> None:
    value = compile_expr(source, VOCAB)(frame)
    if math.isnan(expected):
        assert math.isnan(value)
    else:
        assert value == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_constants_are_folded() -> None:
    expr = compile_expr("norm([3, 4, 0]) * 2 - max(1, 2) ** 2", VOCAB)
    assert expr.evaluator(None) == 6.0  # a folded constant never touches the frame


def test_constant_vector_result_is_read_only() -> None:
    expr = compile_expr("[1, 2, 3] * 2", VOCAB, allow_vector=True)
    out = expr(None)
    np.testing.assert_array_equal(out, [2, 4, 6])
    with pytest.raises(ValueError):
        out[0] = 5.0


def test_vector_result_needs_allow_vector(frame) -> None:
    with pytest.raises(ExprTypeError, match="vector of 3 values"):
        compile_expr("cup.top + [0, 0, 0.1]", VOCAB)
    expr = compile_expr("cup.top + [0, 0, 0.1]", VOCAB, allow_vector=True)
    assert not expr.is_scalar
    np.testing.assert_allclose(expr(frame), [0.4, -0.1, 0.2])
    with pytest.raises(ExprEvalError, match="vector"):
        expr.scalar(frame)


def test_evaluation_never_mutates_the_frame(frame) -> None:
    before = {n: o.pos.copy() for n, o in frame.objects.items()}
    for source in ("norm(xy(bottle.pos)) + dist(cup.pos, -cup.pos)", "norm(bottle.pos * 2 + 1)", "norm(-ref(cup))"):
        compile_expr(source, VOCAB)(frame)
    for name, pos in before.items():
        np.testing.assert_array_equal(frame.objects[name].pos, pos)
        np.testing.assert_array_equal(frame.refs[name], pos)


def test_missing_object_at_run_time_is_an_eval_error(frame) -> None:
    expr = compile_expr("drift(cup, 0.03) + tilt(bottle)", Vocabulary(objects={"bottle", "cup"}))
    del frame.objects["cup"]
    with pytest.raises(ExprEvalError, match="object 'cup'") as info:
        expr(frame)
    assert isinstance(info.value, ExprError)


def test_compiled_expressions_pickle(frame) -> None:
    expr = compile_expr("right.closed * (0.5 - holding(right, bottle))", VOCAB)
    clone = pickle.loads(pickle.dumps(expr))
    assert isinstance(clone, CompiledExpr)
    assert clone.source == expr.source and clone.vocabulary == VOCAB
    assert clone(frame) == expr(frame)


def test_errors_pickle() -> None:
    with pytest.raises(ExprNameError) as info:
        compile_expr("bottle.mass", VOCAB)
    clone = pickle.loads(pickle.dumps(info.value))
    assert type(clone) is ExprNameError
    assert (clone.part, clone.col, clone.source, str(clone)) == ("mass", 7, "bottle.mass", str(info.value))


def test_vocabulary() -> None:
    vocab = Vocabulary(objects=["cup", "bottle"])
    assert vocab.objects == frozenset({"cup", "bottle"})
    assert vocab.arms == frozenset({"left", "right"})
    assert hash(vocab) == hash(Vocabulary(objects={"bottle", "cup"}))
    frame = make_static_frame({"block": {}})
    assert Vocabulary.from_frame(frame) == Vocabulary(objects={"block"})
    for bad in (["red-block"], ["__class__"], ["1cup"], [3]):
        with pytest.raises(ValueError):
            Vocabulary(objects=bad)
    with pytest.raises(ValueError, match="both"):
        Vocabulary(objects={"left"})
    with pytest.raises(TypeError):
        Vocabulary(objects="cup")


def test_object_named_like_a_function() -> None:
    vocab = Vocabulary(objects={"clip", "cup"})
    frame = make_static_frame({"clip": {"pos": (1.0, 0.0, 0.0)}, "cup": {}})
    assert compile_expr("clip(clip.pos[0], 0, 0.5) + tilt(clip)", vocab)(frame) == 0.5


def test_error_attributes_locate_the_offending_part() -> None:
    with pytest.raises(ExprNameError) as info:
        compile_expr("tilt(bottle) - bottle.mass", VOCAB)
    err = info.value
    assert (err.source, err.part, err.col) == ("tilt(bottle) - bottle.mass", "mass", 22)
    assert "attribute 'mass' of 'bottle' is not a feature (allowed: pos, quat" in str(err)

    with pytest.raises(ExprNameError) as info:
        compile_expr("dist(bootle.pos, cup.pos)", VOCAB)
    assert (info.value.part, info.value.col) == ("bootle", 5)
    assert "unknown name 'bootle'" in str(info.value)
    assert "did you mean 'bottle'" in str(info.value)
    assert "objects: bottle, cup; arms: left, right" in str(info.value)

    with pytest.raises(ExprNameError) as info:
        compile_expr("1 + open('/etc/passwd')", VOCAB)
    assert (info.value.part, info.value.col) == ("open", 4)
    assert "call to 'open' is not allowed (allowed: norm, dot, cross, dist" in str(info.value)


# --- hostile and malformed sources ------------------------------------------------------

HOSTILE = [
    # (source, exception class, offending part that the message must name)
    ("__import__('os').system('x')", ExprForbiddenError, "__import__"),
    ("open('/etc/passwd')", ExprNameError, "open"),
    ("bottle.__class__", ExprForbiddenError, "__class__"),
    ("().__class__.__bases__[0].__subclasses__()", ExprForbiddenError, "__"),
    ("(lambda: 1)()", ExprForbiddenError, "lambda"),
    ("lambda: 1", ExprForbiddenError, "lambda"),
    ("[x for x in (1,2)]", ExprForbiddenError, "[x for x in (1,2)]"),
    ("{x for x in (1,2)}", ExprForbiddenError, "{x for x in (1,2)}"),
    ("{x: x for x in (1,2)}", ExprForbiddenError, "{x: x for x in (1,2)}"),
    ("norm(x for x in (1,2))", ExprForbiddenError, "x for x in (1,2)"),
    ("f'{1}'", ExprForbiddenError, "f'{1}'"),
    ("'a'", ExprForbiddenError, "'a'"),
    ("b'a'", ExprForbiddenError, "b'a'"),
    ("eval('1')", ExprNameError, "eval"),
    ("exec('1')", ExprNameError, "exec"),
    ("compile('1', 'x', 'eval')", ExprNameError, "compile"),
    ("getattr(bottle, 'pos')", ExprNameError, "getattr"),
    ("print(1)", ExprNameError, "print"),
    ("globals()", ExprNameError, "globals"),
    ("vars()", ExprNameError, "vars"),
    ("breakpoint()", ExprNameError, "breakpoint"),
    ("type(bottle)", ExprNameError, "type"),
    ("bottle.pos.__add__", ExprForbiddenError, "__add__"),
    ("bottle.pos.__add__(1)", ExprForbiddenError, "__add__"),
    ("__builtins__", ExprForbiddenError, "__builtins__"),
    ("1 if 1 else 2", ExprForbiddenError, "1 if 1 else 2"),
    ("1 < 2", ExprForbiddenError, "1 < 2"),
    ("tilt(bottle) <= 20", ExprForbiddenError, "tilt(bottle) <= 20"),
    ("a and b", ExprForbiddenError, "and"),
    ("tilt(bottle) or 1", ExprForbiddenError, "or"),
    ("not 1", ExprForbiddenError, "not"),
    ("(x := 1)", ExprForbiddenError, "x := 1"),
    ("norm(*[1])", ExprForbiddenError, "*[1]"),
    ("dist(a=1)", ExprForbiddenError, "a=1"),
    ("norm(**{})", ExprForbiddenError, "**{}"),
    ("{1: 2}", ExprForbiddenError, "{1: 2}"),
    ("{1}", ExprForbiddenError, "{1}"),
    ("bottle.pos[0:2]", ExprForbiddenError, "0:2"),
    ("bottle.pos[::-1]", ExprForbiddenError, "::-1"),
    ("bottle.pos[right.width]", ExprForbiddenError, "right.width"),
    ("bottle.pos[0, 1]", ExprForbiddenError, "0, 1"),
    ("bottle.pos[1 + 1]", ExprForbiddenError, "1 + 1"),
    ("bottle.pos[1.0]", ExprTypeError, "1.0"),
    ("bottle.pos[3]", ExprTypeError, "3"),
    ("right.width[0]", ExprTypeError, "right.width"),
    ("import os", ExprSyntaxError, "import"),
    ("1 +", ExprSyntaxError, ""),
    ("", ExprSyntaxError, ""),
    ("1; 2", ExprSyntaxError, ";"),
    ("0.5and right.width", ExprSyntaxError, "5and"),  # Python only warns on stderr; an error here
    ("9**9**9**9", ExprForbiddenError, "9**9"),
    ("2 ** 11", ExprForbiddenError, "11"),
    ("2 ** right.width", ExprForbiddenError, "right.width"),
    ("frame", ExprNameError, "frame"),
    ("frame.objects", ExprNameError, "frame"),
    ("self", ExprNameError, "self"),
    ("bottle.mass", ExprNameError, "mass"),
    ("right.pos", ExprNameError, "pos"),
    ("bottle.pos.x", ExprForbiddenError, "bottle.pos.x"),
    ("norm.x", ExprForbiddenError, "x"),
    ("unknown_obj.pos", ExprNameError, "unknown_obj"),
    ("holding(bottle, right)", ExprTypeError, "bottle"),
    ("holding(right, bottle, cup)", ExprTypeError, "holding(right, bottle, cup)"),
    ("bottle + 1", ExprTypeError, "bottle"),
    ("right", ExprTypeError, "right"),
    ("norm", ExprTypeError, "norm"),
    ("norm(bottle.pos)(1)", ExprForbiddenError, "norm(bottle.pos)"),
    ("bottle.pos.dot(cup.pos)", ExprForbiddenError, "bottle.pos.dot"),
    ("bottle(1)", ExprNameError, "bottle"),
    ("1 // 2", ExprForbiddenError, "//"),
    ("1 % 2", ExprForbiddenError, "%"),
    ("bottle.pos @ cup.pos", ExprForbiddenError, "@"),
    ("1 << 2", ExprForbiddenError, "<<"),
    ("1 | 2", ExprForbiddenError, "|"),
    ("~1", ExprForbiddenError, "~"),
    ("1j", ExprForbiddenError, "1j"),
    ("True", ExprForbiddenError, "True"),
    ("None", ExprForbiddenError, "None"),
    ("...", ExprForbiddenError, "..."),
    ("await bottle", ExprForbiddenError, "await bottle"),
    ("(yield)", ExprForbiddenError, "yield"),
    ("[]", ExprTypeError, "[]"),
    ("norm([[1, 2], [3, 4]])", ExprTypeError, "[1, 2]"),
    ("norm(bottle.pos + [1, 2])", ExprTypeError, "bottle.pos + [1, 2]"),
    ("bottle.pos", ExprTypeError, "bottle.pos"),
    ("\x00", ExprSyntaxError, ""),
    ("1 +" * 700 + "1", ExprForbiddenError, "characters"),
    ("(" * 60 + "1" + ")" * 60, ExprForbiddenError, "("),
    ("-" * 60 + "1", ExprForbiddenError, "-"),
    ("+".join(["1"] * 60), ExprForbiddenError, "1"),
    ("\uff45\uff56\uff41\uff4c('1')", ExprNameError, "eval"),  # fullwidth, NFKC-normalised
    ("\uff3f\uff3fimport\uff3f\uff3f('os')", ExprSyntaxError, "\uff3f"),  # not an identifier char
]


def test_hostile_list_is_long_enough() -> None:
    assert len(HOSTILE) >= 40


@pytest.mark.parametrize(("source", "error", "part"), HOSTILE, ids=[repr(s[:30]) for s, _, _ in HOSTILE])
def test_hostile_sources_are_refused(source: str, error: type[ExprError], part: str) -> None:
    with pytest.raises(ExprError) as info:
        compile_expr(source, VOCAB)
    err = info.value
    assert type(err) is error, f"{type(err).__name__}: {err}"
    assert isinstance(err, ValueError)
    assert err.source == source
    assert part in err.message
    assert err.part is not None and part in err.part
    if err.col is not None:
        assert 0 <= err.col <= len(source)


def test_refusal_never_runs_anything(monkeypatch) -> None:
    # The compiler must not reach eval/exec, nor compile to bytecode (ast.parse compiles
    # to an AST only, which is the one use of compile() allowed).
    import builtins

    real_compile = builtins.compile

    def trap(*args, **kwargs):
        raise AssertionError("eval/exec was called")

    def ast_only(source, filename, mode, flags=0, *args, **kwargs):
        assert flags & ast.PyCF_ONLY_AST, "compile() to bytecode was called"
        return real_compile(source, filename, mode, flags, *args, **kwargs)

    monkeypatch.setattr(builtins, "eval", trap)
    monkeypatch.setattr(builtins, "exec", trap)
    monkeypatch.setattr(builtins, "compile", ast_only)
    for source, _, _ in HOSTILE:
        with pytest.raises(ExprError):
            compile_expr(source, VOCAB)
    assert compile_expr("tilt(bottle) - 20", VOCAB)


def test_non_string_source() -> None:
    with pytest.raises(ExprTypeError):
        compile_expr(3, VOCAB)  # type: ignore[arg-type]


def test_depth_limit_is_exact() -> None:
    ok = "-" * (MAX_DEPTH - 1) + "1"
    assert compile_expr(ok, VOCAB)(None) == (-1.0) ** (MAX_DEPTH - 1)
    with pytest.raises(ExprForbiddenError, match="nested"):
        compile_expr("-" + ok, VOCAB)


# --- property: compiled arithmetic equals a direct numpy computation of the same tree -----

_FEATURES = {  # leaf source -> its value on the property-test frame
    "bottle.pos[0]": 0.3,
    "bottle.pos[2]": 0.15,
    "cup.pos[1]": -0.1,
    "right.width": 0.05,
    "cup.points": 1000.0,
    "bottle.top[-1]": 0.2,
}
_PROPERTY_FRAME = make_static_frame(
    objects={"bottle": {"pos": (0.3, 0.1, 0.15)}, "cup": {"pos": (0.4, -0.1, 0.05)}},
    arms={"right": {"width": 0.05}},
)

_numbers = st.one_of(
    st.integers(min_value=-1000, max_value=1000).map(float),
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False),
    st.sampled_from([0.0, 0.5, 1.0, 2.0, 1e-3, 1e300]),
)
_leaves = st.one_of(_numbers.map(lambda v: ("num", v)), st.sampled_from(sorted(_FEATURES)).map(lambda s: ("feat", s)))


def _triples(children):
    return st.lists(children, min_size=3, max_size=3)


def _extend(children):
    return st.one_of(
        st.tuples(st.sampled_from(["+", "-", "*", "/"]), children, children),
        st.tuples(st.just("**"), children, st.sampled_from([-2.0, -1.0, 0.0, 0.5, 1.0, 2.0, 3.0])),
        st.tuples(st.just("neg"), children),
        st.tuples(st.just("abs"), children),
        st.tuples(st.sampled_from(["min", "max"]), st.lists(children, min_size=2, max_size=4)),
        st.tuples(st.just("clip"), children, children, children),
        st.tuples(st.just("norm"), st.lists(children, min_size=1, max_size=4)),
        st.tuples(st.just("index"), _triples(children), st.integers(-3, 2)),
        st.tuples(st.just("vsum"), _triples(children), _triples(children)),
    )


_trees = st.recursive(_leaves, _extend, max_leaves=20)


def _num(value: float) -> str:
    return repr(value) if math.copysign(1.0, value) > 0 else f"({value!r})"


def _render(tree) -> str:
    """Source text of a tree, fully parenthesised."""
    tag = tree[0]
    if tag == "num":
        return _num(tree[1])
    if tag == "feat":
        return tree[1]
    if tag in ("+", "-", "*", "/"):
        return f"({_render(tree[1])} {tag} {_render(tree[2])})"
    if tag == "**":
        return f"({_render(tree[1])} ** {_num(tree[2])})"
    if tag == "neg":
        return f"(-{_render(tree[1])})"
    if tag in ("abs", "min", "max"):
        args = tree[1:] if tag == "abs" else tree[1]
        return f"{tag}({', '.join(_render(a) for a in args)})"
    if tag == "clip":
        return f"clip({', '.join(_render(a) for a in tree[1:])})"
    if tag == "norm":
        return f"norm([{', '.join(_render(a) for a in tree[1])}])"
    if tag == "index":
        return f"[{', '.join(_render(a) for a in tree[1])}][{tree[2]}]"
    if tag == "vsum":
        left = ", ".join(_render(a) for a in tree[1])
        right = ", ".join(_render(a) for a in tree[2])
        return f"dot([{left}] - [{right}], [1, 1, 1])"
    raise AssertionError(tag)


def _reference(tree) -> np.float64:
    """The same tree computed directly with numpy float64 arithmetic."""
    tag = tree[0]
    if tag == "num":
        return np.float64(tree[1])
    if tag == "feat":
        return np.float64(_FEATURES[tree[1]])
    if tag == "+":
        return _reference(tree[1]) + _reference(tree[2])
    if tag == "-":
        return _reference(tree[1]) - _reference(tree[2])
    if tag == "*":
        return _reference(tree[1]) * _reference(tree[2])
    if tag == "/":
        return _reference(tree[1]) / _reference(tree[2])
    if tag == "**":
        # numpy's scalar ** follows C99 pow (np.power's ufunc swaps in sqrt for 0.5: nan at -inf).
        return _reference(tree[1]) ** np.float64(tree[2])
    if tag == "neg":
        return -_reference(tree[1])
    if tag == "abs":
        return np.abs(_reference(tree[1]))
    if tag == "min":
        return np.min([_reference(a) for a in tree[1]])
    if tag == "max":
        return np.max([_reference(a) for a in tree[1]])
    if tag == "clip":
        x, lo, hi = (_reference(a) for a in tree[1:])
        return np.minimum(np.maximum(x, lo), hi)
    if tag == "norm":
        # math.hypot: correctly rounded, and inf wins over nan as in C99 (np.linalg.norm is neither).
        return np.float64(math.hypot(*[_reference(a) for a in tree[1]]))
    if tag == "index":
        return np.array([_reference(a) for a in tree[1]])[tree[2]]
    if tag == "vsum":
        left = np.array([_reference(a) for a in tree[1]])
        right = np.array([_reference(a) for a in tree[2]])
        return np.dot(left - right, np.ones(3))
    raise AssertionError(tag)


def _depth(node: ast.AST) -> int:
    children = [c for c in ast.iter_child_nodes(node) if isinstance(c, ast.expr)]
    return 1 + max((_depth(c) for c in children), default=0)


@settings(max_examples=400, deadline=None)
@given(_trees)
def test_compiled_arithmetic_matches_numpy(tree) -> None:
    source = _render(tree)
    if len(source) > 2000 or _depth(ast.parse(source, mode="eval").body) > MAX_DEPTH:
        return
    with np.errstate(all="ignore"):  # inf - inf and the like: both sides give nan, without a warning
        expected = float(_reference(tree))
        value = compile_expr(source, VOCAB).scalar(_PROPERTY_FRAME)
    if math.isnan(expected):
        assert math.isnan(value), source
    elif math.isinf(expected):
        assert value == expected, source
    else:
        assert value == pytest.approx(expected, rel=1e-9, abs=1e-300), source
