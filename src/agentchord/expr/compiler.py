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

import ast
import difflib
import enum
import operator
from collections.abc import Iterable
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, NoReturn

import numpy as np

from agentchord.expr import ops
from agentchord.expr.exceptions import (
    ExprError,
    ExprEvalError,
    ExprForbiddenError,
    ExprNameError,
    ExprSyntaxError,
    ExprTypeError,
    ExprValueError,
)
from agentchord.expr.library import LIBRARY, ArgKind, Function, Value
from agentchord.expr.templates import TEMPLATE_FUNCTIONS
from agentchord.features.frame import ARM_ATTRIBUTES, ARMS, OBJECT_ATTRIBUTES, FeatureFrame

#: Longest accepted source, in characters.
MAX_SOURCE_LENGTH = 2000
#: Deepest accepted nesting, of brackets or of the expression tree.
MAX_DEPTH = 50
#: Largest accepted |exponent| of ``**``: bounds the cost and size of powers.
MAX_EXPONENT = 10.0

#: Every callable of the language (library, then templates), by name.
CALLABLES: MappingProxyType[str, Function] = MappingProxyType({**LIBRARY, **TEMPLATE_FUNCTIONS})
#: Callable name -> one-line description with its signature (for prompts and messages).
FUNCTIONS: MappingProxyType[str, str] = MappingProxyType({n: f.description for n, f in CALLABLES.items()})

# Vector lengths of the frame's features (0 = scalar); see features/frame.py.
_FEATURE_SIZES = {
    "pos": 3,
    "quat": 4,
    "axis": 3,
    "extent": 3,
    "top": 3,
    "bottom": 3,
    "points": 0,
    "ee": 3,
    "ee_quat": 4,
    "q": 6,
    "width": 0,
    "closed": 0,
}

_OPERATORS: dict[type[ast.operator], str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Pow: "**",
}
_REFUSED_OPERATORS: dict[type[ast.AST], str] = {
    ast.FloorDiv: "//",
    ast.Mod: "%",
    ast.MatMult: "@",
    ast.LShift: "<<",
    ast.RShift: ">>",
    ast.BitOr: "|",
    ast.BitXor: "^",
    ast.BitAnd: "&",
    ast.Invert: "~",
    ast.Not: "not",
}
_ALLOWED_OPERATORS = "+ - * / ** and unary -"

# Constructs refused outright, with a hint that says what to write instead.
_FORBIDDEN: dict[type[ast.AST], str] = {
    ast.Compare: "comparison {part!r} is not allowed: write constraints as 'lhs - rhs' (<= 0 when satisfied)",
    ast.BoolOp: (
        "boolean operator {part!r} is not allowed: combine conditions as max(a, b) (both must hold) "
        "or min(a, b) (either holds)"
    ),
    ast.IfExp: (
        "conditional expression {part!r} is not allowed: use min/max/clip, or gate with a 0/1 feature "
        "as in right.closed * (...)"
    ),
    ast.NamedExpr: "assignment expression {part!r} is not allowed",
    ast.Lambda: "lambda {part!r} is not allowed",
    ast.ListComp: "comprehension {part!r} is not allowed",
    ast.SetComp: "comprehension {part!r} is not allowed",
    ast.DictComp: "comprehension {part!r} is not allowed",
    ast.GeneratorExp: "generator expression {part!r} is not allowed",
    ast.Dict: "dict literal {part!r} is not allowed: vectors are written [x, y, z]",
    ast.Set: "set literal {part!r} is not allowed: vectors are written [x, y, z]",
    ast.JoinedStr: "f-string {part!r} is not allowed: expressions are numeric",
    ast.FormattedValue: "f-string {part!r} is not allowed: expressions are numeric",
    ast.Starred: "starred expression {part!r} is not allowed",
    ast.Slice: "slice {part!r} is not allowed: index one component, as in v[0]",
    ast.Await: "await {part!r} is not allowed",
    ast.Yield: "yield {part!r} is not allowed",
    ast.YieldFrom: "yield {part!r} is not allowed",
}


@dataclass(frozen=True)
class Vocabulary:
    """The names an expression may use.

    Attributes:
        objects: Object names of the task (``bottle``, ``cup``).
        arms: Arm names of the robot.
    """

    objects: frozenset[str]
    arms: frozenset[str] = frozenset(ARMS)

    def __post_init__(self) -> None:
        # Accept any iterable of names, but keep the dataclass hashable and immutable.
        for field_name in ("objects", "arms"):
            names = getattr(self, field_name)
            if isinstance(names, str):
                raise TypeError(f"Vocabulary.{field_name} must be a collection of names, not the string {names!r}")
            names = frozenset(names)
            for name in names:
                if not isinstance(name, str) or not name.isidentifier() or _is_dunder(name):
                    raise ValueError(
                        f"Vocabulary.{field_name}: {name!r} cannot be used in expressions "
                        "(names must be identifiers that neither start nor end with '__')"
                    )
            object.__setattr__(self, field_name, names)
        if clash := self.objects & self.arms:
            raise ValueError(f"Vocabulary: {', '.join(sorted(clash))} named both an object and an arm")

    @classmethod
    def from_frame(cls, frame: FeatureFrame) -> Vocabulary:
        """The objects and arms present in ``frame``."""
        return cls(objects=frozenset(frame.objects), arms=frozenset(frame.arms))

    def describe(self) -> str:
        """``objects: bottle, cup; arms: left, right`` (for messages)."""
        objects = ", ".join(sorted(self.objects)) or "none"
        return f"objects: {objects}; arms: {', '.join(sorted(self.arms)) or 'none'}"


class _Kind(enum.Enum):
    SCALAR = "scalar"
    VECTOR = "vector"
    ANY = "value"  # a number whose shape is only known at run time
    OBJECT = "object"
    ARM = "arm"


@dataclass(frozen=True)
class _Node:
    """A compiled subexpression.

    Exactly one of ``fn`` (run-time evaluator) and ``const`` (folded value, or
    the name of an object/arm) is meaningful; ``is_const`` says which.
    """

    kind: _Kind
    ast_node: ast.AST
    fn: ops.Evaluator | None = None
    const: Any = None
    size: int | None = None  # vector length when known
    feature: tuple[str, str, str] | None = None  # ("objects"|"arms", name, attr) for a plain feature read

    @property
    def is_const(self) -> bool:
        return self.fn is None

    def evaluator(self) -> ops.Evaluator:
        return self.fn if self.fn is not None else ops.constant(self.const)

    def operand(self) -> tuple[ops.Evaluator | None, Any]:
        return (self.fn, None) if self.fn is not None else (None, self.const)


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
    tree, text, shift = _parse(source)
    compiler = _Compiler(source, text, shift, vocabulary, finite_constants)
    compiler.check_tree(tree)
    node = compiler.compile(tree.body)
    is_scalar = node.kind is _Kind.SCALAR
    if node.kind in (_Kind.OBJECT, _Kind.ARM):
        compiler.fail(
            ExprTypeError,
            f"{node.kind.value} {node.const!r} is not a value: read a feature such as "
            f"{node.const}.{'pos' if node.kind is _Kind.OBJECT else 'ee'} or pass it to a function",
            node.ast_node,
        )
    if node.kind is _Kind.VECTOR and not allow_vector:
        compiler.fail(
            ExprTypeError,
            f"{_shorten(compiler.segment(node.ast_node))!r} gives a vector of {node.size or 'several'} values, "
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


def _parse(source: str) -> tuple[ast.Expression, str, int]:
    """Parse after the cheap size checks.

    Returns:
        The tree, the parsed text (``source`` without leading blanks) and the
        column of that text's first character in its line of ``source``.
    """
    if len(source) > MAX_SOURCE_LENGTH:
        raise ExprForbiddenError(
            f"expression of {len(source)} characters is too long (at most {MAX_SOURCE_LENGTH})",
            source=source,
            part=f"{len(source)} characters",
        )
    # Bound bracket nesting before the parser sees it (its own limit is far higher).
    depth = 0
    for col, char in enumerate(source):
        if char in "([{":
            depth += 1
            if depth > MAX_DEPTH:
                raise ExprForbiddenError(
                    f"expression is nested deeper than {MAX_DEPTH} brackets at {char!r}",
                    source=source,
                    part=char,
                    col=col,
                )
        elif char in ")]}":
            depth -= 1
    # ast.parse refuses an indented first line; leading blanks (YAML block scalars) are harmless.
    text = source.lstrip()
    prefix = source[: len(source) - len(text)]
    shift = len(prefix) - (prefix.rfind("\n") + 1)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        col = None if exc.offset is None else max(exc.offset - 1, 0) + (shift if exc.lineno == 1 else 0)
        lines = text.splitlines() or [text]
        line = lines[min(exc.lineno, len(lines)) - 1] if exc.lineno else text
        if exc.lineno == 1:
            line = " " * shift + line
        part = _token_at(line, col) if col is not None else source
        where = f" near {part!r}" if part else ""
        raise ExprSyntaxError(f"invalid expression{where}: {exc.msg}", source=source, part=part, col=col) from None
    except (ValueError, RecursionError, MemoryError) as exc:  # null bytes, parser stack
        raise ExprSyntaxError(f"invalid expression: {exc}", source=source, part=source[:40]) from None
    return tree, text, shift


def _token_at(line: str, col: int) -> str:
    """The word or symbol starting at ``col`` (for syntax error messages)."""
    rest = line[col:] if 0 <= col < len(line) else ""
    rest = rest.lstrip()
    if not rest:
        return line.strip()
    if rest[0].isidentifier() or rest[0].isdigit():
        end = 1
        while end < len(rest) and (rest[end].isalnum() or rest[end] in "_."):
            end += 1
        return rest[:end]
    return rest[0]


def _is_dunder(name: str | None) -> bool:
    return name is not None and (name.startswith("__") or name.endswith("__"))


class _Compiler:
    """Checks and compiles one parsed expression."""

    def __init__(
        self, source: str, text: str, shift: int, vocabulary: Vocabulary, finite_constants: bool = False
    ) -> None:
        self.source = source
        self.finite_constants = finite_constants
        self.text = text  # what was parsed: ast positions refer to it
        self.shift = shift  # column of text's first character in source
        self.vocabulary = vocabulary
        self.objects: set[str] = set()
        self.arms: set[str] = set()

    # --- errors -------------------------------------------------------------------------

    def segment(self, node: ast.AST) -> str:
        """Source text of ``node``."""
        return ast.get_source_segment(self.text, node) or type(node).__name__

    def column(self, node: ast.AST) -> int | None:
        lineno, offset = getattr(node, "lineno", None), getattr(node, "col_offset", None)
        if lineno is None or offset is None:
            return None
        line = self.text.splitlines()[lineno - 1]
        col = len(line.encode()[:offset].decode(errors="ignore"))  # ast offsets are UTF-8 bytes
        return col + (self.shift if lineno == 1 else 0)

    def attr_column(self, node: ast.Attribute) -> int | None:
        """Column of the attribute name itself (``mass`` in ``bottle.mass``)."""
        lineno, end = node.end_lineno, node.end_col_offset
        if lineno is None or end is None:
            return self.column(node)
        line = self.text.splitlines()[lineno - 1]
        col = len(line.encode()[:end].decode(errors="ignore")) - len(node.attr)
        return col + (self.shift if lineno == 1 else 0)

    def fail(
        self,
        cls: type[ExprError],
        message: str,
        node: ast.AST,
        part: str | None = None,
        col: int | None = None,
    ) -> NoReturn:
        raise cls(
            message,
            source=self.source,
            part=part if part is not None else self.segment(node),
            col=col if col is not None else self.column(node),
        )

    def unknown_name(self, node: ast.AST, name: str) -> NoReturn:
        known = sorted(self.vocabulary.objects | self.vocabulary.arms)
        message = f"unknown name {name!r}{_suggest(name, known)} ({self.vocabulary.describe()})"
        self.fail(ExprNameError, message, node, name)

    # --- whole-tree checks ----------------------------------------------------------------

    def check_tree(self, tree: ast.Expression) -> None:
        """Refuse dunders anywhere and trees deeper than ``MAX_DEPTH`` (iteratively)."""
        stack: list[tuple[ast.AST, int]] = [(tree.body, 1)]
        while stack:
            node, depth = stack.pop()
            if depth > MAX_DEPTH:
                part = _shorten(self.segment(node))
                self.fail(
                    ExprForbiddenError, f"expression is nested deeper than {MAX_DEPTH} levels at {part!r}", node, part
                )
            name = None
            if isinstance(node, ast.Name):
                name = node.id
            elif isinstance(node, ast.Attribute):
                name = node.attr
            elif isinstance(node, ast.keyword):
                name = node.arg
            if _is_dunder(name):
                col = self.attr_column(node) if isinstance(node, ast.Attribute) else None
                self.fail(ExprForbiddenError, f"dunder name {name!r} is not allowed", node, name, col)
            for child in ast.iter_child_nodes(node):
                stack.append((child, depth + 1 if isinstance(child, ast.expr) else depth))

    # --- compilation ----------------------------------------------------------------------

    def compile(self, node: ast.AST) -> _Node:
        """Compile one node (recursion depth is bounded by :meth:`check_tree`)."""
        handler = _HANDLERS.get(type(node))
        if handler is not None:
            out = handler(self, node)
            if self.finite_constants and out.is_const and out.kind in (_Kind.SCALAR, _Kind.VECTOR, _Kind.ANY):
                self.check_finite(out)
            return out
        template = _FORBIDDEN.get(type(node))
        if template is not None:
            part = self.segment(node)
            if isinstance(node, ast.BoolOp):
                part = "and" if isinstance(node.op, ast.And) else "or"
                self.fail(ExprForbiddenError, template.format(part=self.segment(node)), node, part)
            self.fail(ExprForbiddenError, template.format(part=part), node)
        self.fail(ExprForbiddenError, f"{type(node).__name__} {self.segment(node)!r} is not allowed", node)

    def check_finite(self, out: _Node) -> None:
        """Refuse a folded constant that is NaN or infinite."""
        try:
            values = np.asarray(out.const, dtype=float)
        except (TypeError, ValueError):
            return
        if not np.all(np.isfinite(values)):
            shown = np.array2string(values, precision=3) if values.ndim else f"{float(values):g}"
            self.fail(
                ExprValueError,
                f"{_shorten(self.segment(out.ast_node))!r} is {shown}, not a finite number: the expression "
                "would be NaN or infinite on every frame (a monitor that never or always fires)",
                out.ast_node,
            )

    def value(self, node: ast.AST, what: str) -> _Node:
        """Compile ``node`` and require a number (not an object or arm name)."""
        out = self.compile(node)
        if out.kind in (_Kind.OBJECT, _Kind.ARM):
            example = "pos" if out.kind is _Kind.OBJECT else "ee"
            self.fail(
                ExprTypeError,
                f"{out.kind.value} {out.const!r} cannot be used as {what}: read a feature such as "
                f"{out.const}.{example}, or pass it to a function that takes an {out.kind.value}",
                node,
            )
        return out

    def constant(self, node: ast.Constant) -> _Node:
        value = node.value
        if isinstance(value, bool) or value is None or value is Ellipsis:
            message = f"constant {self.segment(node)} is not allowed: use numbers such as 1.0 or 0.0"
            self.fail(ExprForbiddenError, message, node)
        if isinstance(value, (str, bytes)):
            self.fail(ExprForbiddenError, f"string {self.segment(node)} is not allowed: expressions are numeric", node)
        if isinstance(value, complex):
            self.fail(ExprForbiddenError, f"complex number {self.segment(node)} is not allowed", node)
        if not isinstance(value, (int, float)):
            self.fail(ExprForbiddenError, f"constant {self.segment(node)} is not allowed", node)
        try:
            number = float(value)  # ints become floats: no unbounded integer arithmetic
        except OverflowError:
            self.fail(ExprTypeError, f"number {self.segment(node)[:20]}... is out of range", node)
        return _Node(_Kind.SCALAR, node, const=number)

    def name(self, node: ast.Name) -> _Node:
        name = node.id
        if name in self.vocabulary.objects:
            self.objects.add(name)
            return _Node(_Kind.OBJECT, node, const=name)
        if name in self.vocabulary.arms:
            self.arms.add(name)
            return _Node(_Kind.ARM, node, const=name)
        if name in CALLABLES:
            self.fail(ExprTypeError, f"function {name!r} must be called, as in {CALLABLES[name].signature}", node)
        self.unknown_name(node, name)

    def attribute(self, node: ast.Attribute) -> _Node:
        base, attr = node.value, node.attr
        if not isinstance(base, ast.Name):
            self.fail(
                ExprForbiddenError,
                f"attribute access {self.segment(node)!r} is not allowed: only <object>.<feature> "
                "and <arm>.<feature> can be read",
                node,
                self.segment(node),
            )
        owner = base.id
        if owner in self.vocabulary.objects:
            table, allowed, group = "objects", OBJECT_ATTRIBUTES, self.objects
        elif owner in self.vocabulary.arms:
            table, allowed, group = "arms", ARM_ATTRIBUTES, self.arms
        elif owner in CALLABLES:
            self.fail(ExprForbiddenError, f"attribute {attr!r} of function {owner!r} is not allowed", node, attr)
        else:
            self.unknown_name(base, owner)
        if attr not in allowed:
            kind = "" if table == "objects" else "arm "
            self.fail(
                ExprNameError,
                f"attribute {attr!r} of {kind}{owner!r} is not a feature{_suggest(attr, allowed)} "
                f"(allowed: {', '.join(allowed)})",
                node,
                attr,
                self.attr_column(node),
            )
        group.add(owner)
        size = _FEATURE_SIZES.get(attr)
        kind = _Kind.ANY if size is None else (_Kind.SCALAR if size == 0 else _Kind.VECTOR)
        get = operator.attrgetter(attr)

        def read_object(f: FeatureFrame) -> Value:
            return get(f.objects[owner])

        def read_arm(f: FeatureFrame) -> Value:
            return get(f.arms[owner])

        fn = read_object if table == "objects" else read_arm
        return _Node(kind, node, fn=fn, size=size or None, feature=(table, owner, attr))

    def unary(self, node: ast.UnaryOp) -> _Node:
        if type(node.op) in _REFUSED_OPERATORS:
            symbol = _REFUSED_OPERATORS[type(node.op)]
            self.fail(
                ExprForbiddenError,
                f"operator {symbol!r} in {self.segment(node)!r} is not allowed (allowed: {_ALLOWED_OPERATORS})",
                node,
                symbol,
            )
        operand = self.value(node.operand, "an operand")
        if isinstance(node.op, ast.UAdd):
            return _Node(operand.kind, node, fn=operand.fn, const=operand.const, size=operand.size)
        if operand.is_const:
            return _Node(operand.kind, node, const=ops.negate(operand.const), size=operand.size)
        a = operand.fn
        return _Node(operand.kind, node, fn=lambda f: -a(f), size=operand.size)

    def binary(self, node: ast.BinOp) -> _Node:
        symbol = _OPERATORS.get(type(node.op))
        if symbol is None:
            refused = _REFUSED_OPERATORS.get(type(node.op), type(node.op).__name__)
            self.fail(
                ExprForbiddenError,
                f"operator {refused!r} in {self.segment(node)!r} is not allowed (allowed: {_ALLOWED_OPERATORS})",
                node,
                refused,
            )
        left = self.value(node.left, f"an operand of {symbol!r}")
        right = self.value(node.right, f"an operand of {symbol!r}")
        if symbol == "**":
            self.check_exponent(node.right, right)
        kind, size = self.combine(node, symbol, left, right)
        if left.is_const and right.is_const:
            try:
                with np.errstate(all="ignore"):  # inf/nan constants are legal values
                    folded = ops.APPLY[symbol](left.const, right.const)
            except (ValueError, ArithmeticError) as exc:  # e.g. vector length mismatch
                self.fail(ExprTypeError, f"cannot compute {self.segment(node)!r}: {exc}", node)
            return _Node(kind, node, const=_freeze(folded), size=size)
        fn = ops.binary(symbol, left.fn, left.const, right.fn, right.const)
        return _Node(kind, node, fn=fn, size=size)

    def check_exponent(self, node: ast.AST, exponent: _Node) -> None:
        ok = exponent.is_const and exponent.kind is _Kind.SCALAR
        if ok and not abs(exponent.const) <= MAX_EXPONENT:  # also refuses nan
            self.fail(
                ExprForbiddenError,
                f"exponent {self.segment(node)!r} (= {exponent.const:g}) is too large: "
                f"|exponent| must be at most {MAX_EXPONENT:g}",
                node,
            )
        if not ok:
            self.fail(
                ExprForbiddenError,
                f"exponent {self.segment(node)!r} must be a constant number with |exponent| <= {MAX_EXPONENT:g}",
                node,
            )

    def combine(self, node: ast.BinOp, symbol: str, left: _Node, right: _Node) -> tuple[_Kind, int | None]:
        """Kind and length of ``left <symbol> right`` (numpy broadcasting of scalars)."""
        if symbol == "**":
            return left.kind, left.size
        if left.kind is _Kind.VECTOR and right.kind is _Kind.VECTOR:
            if left.size is not None and right.size is not None and left.size != right.size:
                self.fail(
                    ExprTypeError,
                    f"cannot combine vectors of {left.size} and {right.size} values in {self.segment(node)!r}",
                    node,
                )
            return _Kind.VECTOR, left.size or right.size
        if _Kind.ANY in (left.kind, right.kind):
            return _Kind.ANY, None
        if _Kind.VECTOR in (left.kind, right.kind):
            return _Kind.VECTOR, left.size or right.size
        return _Kind.SCALAR, None

    def sequence(self, node: ast.List | ast.Tuple) -> _Node:
        if not node.elts:
            self.fail(ExprTypeError, "empty vector [] is not allowed", node)
        items = []
        for element in node.elts:
            item = self.value(element, "a vector component")
            if item.kind is _Kind.VECTOR:
                self.fail(
                    ExprTypeError,
                    f"vector component {self.segment(element)!r} is itself a vector: components must be scalars",
                    element,
                )
            items.append(item)
        if all(item.is_const for item in items):
            value = np.array([i.const for i in items], dtype=float)
            return _Node(_Kind.VECTOR, node, const=_freeze(value), size=len(items))
        return _Node(_Kind.VECTOR, node, fn=ops.vector([i.operand() for i in items]), size=len(items))

    def subscript(self, node: ast.Subscript) -> _Node:
        index_node = node.slice
        if isinstance(index_node, ast.Slice):
            self.fail(ExprForbiddenError, _FORBIDDEN[ast.Slice].format(part=self.segment(index_node)), index_node)
        index = _integer_literal(index_node)
        if index is None:
            if isinstance(index_node, ast.Constant) and isinstance(index_node.value, (int, float)):
                self.fail(ExprTypeError, f"index {self.segment(index_node)!r} must be an integer", index_node)
            self.fail(
                ExprForbiddenError,
                f"index {self.segment(index_node)!r} is not allowed: indices must be integer constants, as in v[2]",
                index_node,
            )
        base = self.value(node.value, "a vector")
        if base.kind is _Kind.SCALAR:
            self.fail(ExprTypeError, f"cannot index scalar {self.segment(node.value)!r}", node)
        if base.size is not None and not -base.size <= index < base.size:
            self.fail(
                ExprTypeError,
                f"index {index} is out of range for {self.segment(node.value)!r} ({base.size} values)",
                index_node,
            )
        # Components become Python floats: float arithmetic is ~2x faster than numpy
        # scalars' and never warns.
        if base.is_const:
            return _Node(_Kind.SCALAR, node, const=float(base.const[index]))
        if base.feature is not None:
            # Fused read: bottle.bottom[2] costs one closure, not two.
            table, owner, attr = base.feature
            get = operator.attrgetter(attr)
            if table == "objects":
                return _Node(_Kind.SCALAR, node, fn=lambda f: float(get(f.objects[owner])[index]))
            return _Node(_Kind.SCALAR, node, fn=lambda f: float(get(f.arms[owner])[index]))
        a = base.fn
        return _Node(_Kind.SCALAR, node, fn=lambda f: float(a(f)[index]))

    def call(self, node: ast.Call) -> _Node:
        if not isinstance(node.func, ast.Name):
            self.fail(
                ExprForbiddenError,
                f"call of {self.segment(node.func)!r} is not allowed: only library functions can be called, "
                f"by bare name ({', '.join(CALLABLES)})",
                node,
                self.segment(node.func),
            )
        name = node.func.id
        function = CALLABLES.get(name)
        if function is None:
            self.fail(
                ExprNameError,
                f"call to {name!r} is not allowed{_suggest(name, CALLABLES)} (allowed: {', '.join(CALLABLES)})",
                node.func,
                name,
            )
        for keyword in node.keywords:
            self.fail(
                ExprForbiddenError,
                f"keyword argument {self.segment(keyword)!r} is not allowed: pass arguments by position, "
                f"as in {function.signature}",
                keyword,
            )
        for arg in node.args:
            if isinstance(arg, ast.Starred):
                self.fail(ExprForbiddenError, f"starred argument {self.segment(arg)!r} is not allowed", arg)
        n_params, n_args = len(function.params), len(node.args)
        if n_args < n_params or (n_args > n_params and not function.variadic):
            wanted = f"at least {n_params}" if function.variadic else str(n_params)
            self.fail(
                ExprTypeError,
                f"{function.signature} takes {wanted} argument{'s' if n_params != 1 else ''}, got {n_args} "
                f"in {self.segment(node)!r}",
                node,
            )
        args = [self.argument(function, i, arg) for i, arg in enumerate(node.args)]
        sizes = {a.size for a in args if a.kind is _Kind.VECTOR and a.size is not None}
        if function.same_size and len(sizes) > 1:
            self.fail(
                ExprTypeError,
                f"{function.signature} needs vectors of one length, got lengths {sorted(sizes)}",
                node,
            )
        if function.returns is ArgKind.SCALAR:
            kind, size = _Kind.SCALAR, None
        else:
            first = next((a.size for a in args if a.kind in (_Kind.VECTOR, _Kind.ANY)), None)
            kind, size = _Kind.VECTOR, function.returns_size or first
        if not function.reads_frame and all(a.is_const for a in args):
            try:
                with np.errstate(all="ignore"):
                    folded = function.impl(*[a.const for a in args])
            except (ValueError, ArithmeticError, IndexError) as exc:
                self.fail(ExprTypeError, f"cannot compute {self.segment(node)!r}: {exc}", node)
            return _Node(kind, node, const=_freeze(folded), size=size)
        fn = ops.call(function.impl, function.reads_frame, [a.operand() for a in args])
        return _Node(kind, node, fn=fn, size=size)

    def argument(self, function: Function, index: int, node: ast.AST) -> _Node:
        """Compile argument ``index`` of a call and check it against its parameter."""
        param = function.params[min(index, len(function.params) - 1)]
        arg = self.compile(node)
        where = f"argument {param.name!r} of {function.signature}"
        if param.kind in (ArgKind.OBJECT, ArgKind.ARM):
            wanted = _Kind.OBJECT if param.kind is ArgKind.OBJECT else _Kind.ARM
            if arg.kind is not wanted:
                names = self.vocabulary.objects if wanted is _Kind.OBJECT else self.vocabulary.arms
                if arg.kind in (_Kind.OBJECT, _Kind.ARM):
                    got = f"{arg.kind.value} {arg.const!r}"
                else:
                    got = repr(self.segment(node))
                swapped = any(p.kind.value == arg.kind.value for p in function.params)
                self.fail(
                    ExprTypeError,
                    f"{where} must be an {wanted.value} name ({', '.join(sorted(names)) or 'none'}), got {got}"
                    + (" (are the arguments swapped?)" if swapped else ""),
                    node,
                )
            return arg
        if arg.kind in (_Kind.OBJECT, _Kind.ARM):
            feature = "pos" if arg.kind is _Kind.OBJECT else "ee"
            self.fail(
                ExprTypeError,
                f"{where} must be a {param.kind.value}, got {arg.kind.value} {arg.const!r} "
                f"(did you mean {arg.const}.{feature}?)",
                node,
            )
        if param.kind is ArgKind.SCALAR and arg.kind is _Kind.VECTOR:
            self.fail(
                ExprTypeError,
                f"{where} must be a scalar, got the vector {self.segment(node)!r} (reduce it with norm() or v[i])",
                node,
            )
        if param.kind is ArgKind.VECTOR:
            if arg.kind is _Kind.SCALAR:
                self.fail(ExprTypeError, f"{where} must be a vector, got the scalar {self.segment(node)!r}", node)
            if param.size is not None and arg.size is not None and arg.size != param.size:
                self.fail(
                    ExprTypeError,
                    f"{where} must be a vector of {param.size} values, got {arg.size}: {self.segment(node)!r}",
                    node,
                )
        return arg


_HANDLERS = {
    ast.Constant: _Compiler.constant,
    ast.Name: _Compiler.name,
    ast.Attribute: _Compiler.attribute,
    ast.UnaryOp: _Compiler.unary,
    ast.BinOp: _Compiler.binary,
    ast.List: _Compiler.sequence,
    ast.Tuple: _Compiler.sequence,
    ast.Subscript: _Compiler.subscript,
    ast.Call: _Compiler.call,
}


def _integer_literal(node: ast.AST) -> int | None:
    """``2`` or ``-1`` written literally, else ``None``."""
    sign = 1
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        sign = -1 if isinstance(node.op, ast.USub) else 1
        node = node.operand
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return sign * node.value
    return None


def _freeze(value: Value) -> Value:
    """Folded constants: Python floats, or read-only arrays shared by every call."""
    if isinstance(value, np.ndarray):
        value.flags.writeable = False
        return value
    return float(value)


def _shorten(text: str, limit: int = 40) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _suggest(name: str, known: Iterable[str]) -> str:
    close = difflib.get_close_matches(name, list(known), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


__all__ = [
    "CALLABLES",
    "FUNCTIONS",
    "MAX_DEPTH",
    "MAX_EXPONENT",
    "MAX_SOURCE_LENGTH",
    "CompiledExpr",
    "Vocabulary",
    "compile_expr",
]
