"""Compiler of constraint/monitor expressions into closures over a feature frame.

The source is parsed with :func:`ast.parse` (``mode="eval"``) and every node
is checked against a whitelist; nothing is ever handed to ``eval``, ``exec``
or ``compile``. Each allowed node becomes a small closure (``lambda f: a(f) -
b(f)``), literal subexpressions are folded, and object/arm names are resolved
to dictionary keys at compile time, so evaluating an expression costs only
dict lookups, attribute reads and a few float or tiny-numpy operations.

Kinds are tracked at compile time (scalar, vector of known length, object name,
arm name) so that wrong calls and non-scalar results are refused before a
robot ever runs them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from agentchord.expr import ops
from agentchord.expr.builder import ClosureBuilder, Kind
from agentchord.expr.diagnostics import shorten
from agentchord.expr.exceptions import ExprEvalError, ExprTypeError
from agentchord.expr.library import Value
from agentchord.expr.parse import parse_bounded
from agentchord.expr.vocabulary import Vocabulary
from agentchord.features.frame import FeatureFrame


class CompiledExpr:
    """An expression compiled against a vocabulary: call it with a frame.

    Attributes:
        source: The expression as written.
        vocabulary: The vocabulary it was compiled against.
        objects: Object names it reads.
        arms: Arm names it reads.
        is_scalar: Whether the result is known to be a scalar at compile time.
    """

    __slots__ = ("_allow_vector", "_fn", "arms", "is_scalar", "objects", "source", "vocabulary")

    def __init__(
        self,
        source: str,
        vocabulary: Vocabulary,
        fn: ops.Evaluator,
        objects: frozenset[str],
        arms: frozenset[str],
        is_scalar: bool,
        allow_vector: bool,
    ) -> None:
        self.source = source
        self.vocabulary = vocabulary
        self.objects = objects
        self.arms = arms
        self.is_scalar = is_scalar
        self._fn = fn
        self._allow_vector = allow_vector

    @property
    def evaluator(self) -> ops.Evaluator:
        """The raw closure ``frame -> value``, without error translation (hot loops)."""
        return self._fn

    def __call__(self, frame: FeatureFrame) -> Value:
        """Evaluate on ``frame``.

        Raises:
            ExprEvalError: The frame lacks an object, arm or reference the
                expression reads, or a value had an unexpected shape.
        """
        try:
            return self._fn(frame)
        except (KeyError, IndexError, AttributeError, TypeError, ValueError) as exc:
            raise self._eval_error(frame, exc) from exc

    def scalar(self, frame: FeatureFrame) -> float:
        """Evaluate on ``frame`` and return a Python float.

        Raises:
            ExprEvalError: As :meth:`__call__`, or the result is a vector.
        """
        try:
            value = self._fn(frame)
        except (KeyError, IndexError, AttributeError, TypeError, ValueError) as exc:
            raise self._eval_error(frame, exc) from exc
        if type(value) is float:
            return value
        if isinstance(value, np.ndarray):
            if value.ndim == 0:
                return float(value)
            raise ExprEvalError(
                f"expression gives a vector of {value.size} values, expected a scalar",
                source=self.source,
            )
        return float(value)

    def _eval_error(self, frame: FeatureFrame, exc: Exception) -> ExprEvalError:
        missing = [f"object {n!r}" for n in sorted(self.objects) if n not in frame.objects]
        missing += [f"arm {n!r}" for n in sorted(self.arms) if n not in frame.arms]
        missing += [f"reference of {n!r}" for n in sorted(self.objects) if n not in frame.refs]
        if missing and isinstance(exc, KeyError):
            message = f"the frame has no {', '.join(missing)} (frame objects: {', '.join(sorted(frame.objects))})"
        else:
            message = f"evaluation failed: {type(exc).__name__}: {exc}"
        return ExprEvalError(message, source=self.source)

    def __repr__(self) -> str:
        return f"CompiledExpr({self.source!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        # Closures do not pickle; recompiling from the source is cheap and exact.
        return (_recompile, (self.source, self.vocabulary, self._allow_vector))


def _recompile(source: str, vocabulary: Vocabulary, allow_vector: bool) -> CompiledExpr:
    return compile_expr(source, vocabulary, allow_vector=allow_vector)


def compile_expr(
    source: str, vocabulary: Vocabulary, *, allow_vector: bool = False, finite_constants: bool = False
) -> CompiledExpr:
    """Compile a constraint/monitor expression.

    Args:
        source: The expression, e.g. ``"dist(bottle.pos, cup.top) - 0.03"``.
        vocabulary: The object and arm names it may use.
        allow_vector: Accept a vector result (e.g. a target point for a
            solver); constraints and monitors must be scalars.
        finite_constants: Refuse a constant part that is NaN or infinite
            (``0/0``, ``1e400``): a monitor holding one is NaN or infinite on
            every frame, so it never fires or always does. ``graph check`` sets it.

    Returns:
        The compiled expression.

    Raises:
        ExprSyntaxError: ``source`` is not a well-formed expression.
        ExprForbiddenError: ``source`` uses a construct outside the language,
            is longer than ``MAX_SOURCE_LENGTH`` or nested deeper than ``MAX_DEPTH``.
        ExprNameError: ``source`` names an unknown object, arm, feature or function.
        ExprTypeError: wrong argument count or kind, or a vector result when
            ``allow_vector`` is false.
        ExprValueError: a constant part is not finite and ``finite_constants`` is set.
    """
    if not isinstance(source, str):
        raise ExprTypeError(f"an expression must be a string, got {type(source).__name__}", part=repr(source))
    if not isinstance(vocabulary, Vocabulary):
        raise TypeError(f"vocabulary must be a Vocabulary, got {type(vocabulary).__name__}")
    tree, text, shift = parse_bounded(source)
    compiler = ClosureBuilder(source, text, shift, vocabulary, finite_constants)
    compiler.check_tree(tree)
    node = compiler.compile(tree.body)
    is_scalar = node.kind is Kind.SCALAR
    if node.kind in (Kind.OBJECT, Kind.ARM):
        compiler.fail(
            ExprTypeError,
            f"{node.kind.value} {node.const!r} is not a value: read a feature such as "
            f"{node.const}.{'pos' if node.kind is Kind.OBJECT else 'ee'} or pass it to a function",
            node.ast_node,
        )
    if node.kind is Kind.VECTOR and not allow_vector:
        compiler.fail(
            ExprTypeError,
            f"{shorten(compiler.segment(node.ast_node))!r} gives a vector of {node.size or 'several'} values, "
            "expected a scalar: reduce it with norm(...), dist(...), dot(...) or an index such as v[2]",
            node.ast_node,
        )
    if node.is_const and isinstance(node.const, np.ndarray):
        node.const.flags.writeable = False  # a returned constant must not be altered by callers
    return CompiledExpr(
        source,
        vocabulary,
        node.evaluator(),
        frozenset(compiler.objects),
        frozenset(compiler.arms),
        is_scalar,
        allow_vector,
    )


__all__ = ["CompiledExpr", "compile_expr"]
