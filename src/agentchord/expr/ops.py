"""Arithmetic of the language: IEEE-safe operators and the closures built from them.

The compiler turns ``a - b`` into ``lambda f: a(f) - b(f)``; when one side is
a constant it is captured directly (``lambda f: a(f) - 0.5``), which saves a
call per node and tick. Division by zero and overflowing powers give
``inf``/``nan`` as numpy would, instead of raising inside a control loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from agentchord.expr.library import Value
from agentchord.features.frame import FeatureFrame

#: A compiled (sub)expression: frame -> value.
Evaluator = Callable[[FeatureFrame], Any]


def constant(value: Value) -> Evaluator:
    """An evaluator that ignores the frame and returns ``value``."""
    return lambda f: value


def _ieee(ufunc: np.ufunc, x: Value, y: Value) -> Value:
    # The rare exceptional path: let numpy give the IEEE answer, without warnings.
    with np.errstate(all="ignore"):
        out = ufunc(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    return out if isinstance(out, np.ndarray) and out.ndim else float(out)


def divide(x: Value, y: Value) -> Value:
    """``x / y`` with IEEE results (``inf``, ``nan``) instead of ZeroDivisionError."""
    if not isinstance(y, np.ndarray) and y != 0.0:
        return x / y  # a nonzero scalar divisor neither raises nor warns
    return _ieee(np.divide, x, y)


def power(x: Value, e: float) -> Value:
    """``x ** e`` with IEEE results: never complex, never OverflowError."""
    if isinstance(x, np.ndarray):
        return _ieee(np.power, x, e)
    try:
        # math.pow, unlike **, never returns a complex number for a negative base.
        return math.pow(x, e)
    except (OverflowError, ValueError):
        return _ieee(np.power, x, e)


def negate(x: Value) -> Value:
    """``-x``."""
    return -x


#: Operator symbol -> the function that applies it; used for constant folding too,
#: so folded and evaluated results agree bit for bit.
APPLY: dict[str, Callable[[Any, Any], Value]] = {
    "+": lambda x, y: x + y,
    "-": lambda x, y: x - y,
    "*": lambda x, y: x * y,
    "/": divide,
    "**": power,
}


def binary(symbol: str, a: Evaluator | None, ca: Value | None, b: Evaluator | None, cb: Value | None) -> Evaluator:
    """Closure for ``a <symbol> b`` where at most one side is a constant.

    Args:
        symbol: One of ``+ - * / **``.
        a: Evaluator of the left operand, or ``None`` when it is the constant ``ca``.
        ca: Left constant (used when ``a`` is ``None``).
        b: Evaluator of the right operand, or ``None`` when it is the constant ``cb``.
        cb: Right constant (used when ``b`` is ``None``).

    Returns:
        The evaluator of the operation.
    """
    if symbol == "**":
        assert a is not None and b is None, "exponents are compile-time constants"
        if cb == 2.0:

            def square(f: FeatureFrame) -> Value:
                x = a(f)
                return x * x

            return square
        e = cb
        return lambda f: power(a(f), e)
    if a is not None and b is not None:
        if symbol == "+":
            return lambda f: a(f) + b(f)
        if symbol == "-":
            return lambda f: a(f) - b(f)
        if symbol == "*":
            return lambda f: a(f) * b(f)
        return lambda f: divide(a(f), b(f))
    if a is not None:
        c = cb
        if symbol == "+":
            return lambda f: a(f) + c
        if symbol == "-":
            return lambda f: a(f) - c
        if symbol == "*":
            return lambda f: a(f) * c
        if isinstance(c, float) and c != 0.0:
            return lambda f: a(f) / c  # a nonzero float divisor cannot raise
        return lambda f: divide(a(f), c)
    assert b is not None
    c = ca
    if symbol == "+":
        return lambda f: c + b(f)
    if symbol == "-":
        return lambda f: c - b(f)
    if symbol == "*":
        return lambda f: c * b(f)
    return lambda f: divide(c, b(f))


def call(impl: Callable[..., Value], reads_frame: bool, args: list[tuple[Evaluator | None, Any]]) -> Evaluator:
    """Closure for a library call.

    Args:
        impl: The function's implementation.
        reads_frame: Whether ``impl`` takes the frame first.
        args: One ``(evaluator, None)`` or ``(None, constant)`` per argument;
            object and arm names are constants.

    Returns:
        The evaluator of the call.
    """
    if all(fn is None for fn, _ in args):
        # Typical of templates and frame readers: drift(cup, 0.03), holding(right, bottle).
        values = tuple(c for _, c in args)
        if not reads_frame:
            result = impl(*values)
            return lambda f: result
        if len(values) == 1:
            (v0,) = values
            return lambda f: impl(f, v0)
        if len(values) == 2:
            v0, v1 = values
            return lambda f: impl(f, v0, v1)
        if len(values) == 3:
            v0, v1, v2 = values
            return lambda f: impl(f, v0, v1, v2)
        return lambda f: impl(f, *values)
    fns = [fn if fn is not None else constant(c) for fn, c in args]
    if reads_frame:
        if len(fns) == 1:
            (g0,) = fns
            return lambda f: impl(f, g0(f))
        if len(fns) == 2:
            g0, g1 = fns
            return lambda f: impl(f, g0(f), g1(f))
        if len(fns) == 3:
            g0, g1, g2 = fns
            return lambda f: impl(f, g0(f), g1(f), g2(f))
        return lambda f: impl(f, *[g(f) for g in fns])
    if len(fns) == 1:
        (g0,) = fns
        return lambda f: impl(g0(f))
    if len(fns) == 2:
        g0, g1 = fns
        return lambda f: impl(g0(f), g1(f))
    if len(fns) == 3:
        g0, g1, g2 = fns
        return lambda f: impl(g0(f), g1(f), g2(f))
    return lambda f: impl(*[g(f) for g in fns])


def vector(items: list[tuple[Evaluator | None, Any]]) -> Evaluator:
    """Closure building a numpy vector from scalar items (some may be constants)."""
    fns = [fn if fn is not None else constant(c) for fn, c in items]
    if len(fns) == 3:
        g0, g1, g2 = fns
        return lambda f: np.array((g0(f), g1(f), g2(f)), dtype=float)
    return lambda f: np.array([g(f) for g in fns], dtype=float)
