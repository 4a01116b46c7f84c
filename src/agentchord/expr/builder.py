"""The checker and builder behind :func:`~agentchord.expr.compiler.compile_expr`.

It walks a parsed expression, checks every node against the whitelist (:mod:`~agentchord.expr.whitelist`),
tracks kinds at compile time (scalar, vector of known length, object name, arm name) so that
wrong calls and non-scalar results are refused before a robot runs them, folds literal
subexpressions, and turns each allowed node into a small closure over a feature frame. Its
errors point at the offending part of the source (:mod:`~agentchord.expr.diagnostics`).
"""

from __future__ import annotations

import ast
import enum
import operator
from dataclasses import dataclass
from typing import Any, NoReturn

import numpy as np

from agentchord.expr import ops
from agentchord.expr.diagnostics import SourceLocator, shorten, suggest
from agentchord.expr.exceptions import (
    ExprForbiddenError,
    ExprNameError,
    ExprTypeError,
    ExprValueError,
)
from agentchord.expr.library import ArgKind, Function, Value
from agentchord.expr.parse import MAX_DEPTH
from agentchord.expr.vocabulary import CALLABLES, Vocabulary, is_dunder
from agentchord.expr.whitelist import ALLOWED_OPERATORS, FEATURE_SIZES, FORBIDDEN, MAX_EXPONENT, OPERATORS, REFUSED_OPERATORS
from agentchord.features.frame import ARM_ATTRIBUTES, OBJECT_ATTRIBUTES, FeatureFrame


class Kind(enum.Enum):
    """What a subexpression is, known at compile time."""

    SCALAR = "scalar"
    VECTOR = "vector"
    ANY = "value"  # a number whose shape is only known at run time
    OBJECT = "object"
    ARM = "arm"


@dataclass(frozen=True)
class Node:
    """A compiled subexpression.

    Exactly one of ``fn`` (run-time evaluator) and ``const`` (folded value, or
    the name of an object/arm) is meaningful; ``is_const`` says which.
    """

    kind: Kind
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


class ClosureBuilder(SourceLocator):
    """Checks and compiles one parsed expression (its errors located by :class:`SourceLocator`)."""

    def __init__(
        self, source: str, text: str, shift: int, vocabulary: Vocabulary, finite_constants: bool = False
    ) -> None:
        super().__init__(source, text, shift)
        self.finite_constants = finite_constants
        self.vocabulary = vocabulary
        self.objects: set[str] = set()
        self.arms: set[str] = set()

    # --- errors -------------------------------------------------------------------------

    def unknown_name(self, node: ast.AST, name: str) -> NoReturn:
        known = sorted(self.vocabulary.objects | self.vocabulary.arms)
        message = f"unknown name {name!r}{suggest(name, known)} ({self.vocabulary.describe()})"
        self.fail(ExprNameError, message, node, name)

    # --- whole-tree checks ----------------------------------------------------------------

    def check_tree(self, tree: ast.Expression) -> None:
        """Refuse dunders anywhere and trees deeper than ``MAX_DEPTH`` (iteratively)."""
        stack: list[tuple[ast.AST, int]] = [(tree.body, 1)]
        while stack:
            node, depth = stack.pop()
            if depth > MAX_DEPTH:
                part = shorten(self.segment(node))
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
            if is_dunder(name):
                col = self.attr_column(node) if isinstance(node, ast.Attribute) else None
                self.fail(ExprForbiddenError, f"dunder name {name!r} is not allowed", node, name, col)
            for child in ast.iter_child_nodes(node):
                stack.append((child, depth + 1 if isinstance(child, ast.expr) else depth))

    # --- compilation ----------------------------------------------------------------------

    def compile(self, node: ast.AST) -> Node:
        """Compile one node (recursion depth is bounded by :meth:`check_tree`)."""
        handler = _HANDLERS.get(type(node))
        if handler is not None:
            out = handler(self, node)
            if self.finite_constants and out.is_const and out.kind in (Kind.SCALAR, Kind.VECTOR, Kind.ANY):
                self.check_finite(out)
            return out
        template = FORBIDDEN.get(type(node))
        if template is not None:
            part = self.segment(node)
            if isinstance(node, ast.BoolOp):
                part = "and" if isinstance(node.op, ast.And) else "or"
                self.fail(ExprForbiddenError, template.format(part=self.segment(node)), node, part)
            self.fail(ExprForbiddenError, template.format(part=part), node)
        self.fail(ExprForbiddenError, f"{type(node).__name__} {self.segment(node)!r} is not allowed", node)

    def check_finite(self, out: Node) -> None:
        """Refuse a folded constant that is NaN or infinite."""
        try:
            values = np.asarray(out.const, dtype=float)
        except (TypeError, ValueError):
            return
        if not np.all(np.isfinite(values)):
            shown = np.array2string(values, precision=3) if values.ndim else f"{float(values):g}"
            self.fail(
                ExprValueError,
                f"{shorten(self.segment(out.ast_node))!r} is {shown}, not a finite number: the expression "
                "would be NaN or infinite on every frame (a monitor that never or always fires)",
                out.ast_node,
            )

    def value(self, node: ast.AST, what: str) -> Node:
        """Compile ``node`` and require a number (not an object or arm name)."""
        out = self.compile(node)
        if out.kind in (Kind.OBJECT, Kind.ARM):
            example = "pos" if out.kind is Kind.OBJECT else "ee"
            self.fail(
                ExprTypeError,
                f"{out.kind.value} {out.const!r} cannot be used as {what}: read a feature such as "
                f"{out.const}.{example}, or pass it to a function that takes an {out.kind.value}",
                node,
            )
        return out

    def constant(self, node: ast.Constant) -> Node:
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
        return Node(Kind.SCALAR, node, const=number)

    def name(self, node: ast.Name) -> Node:
        name = node.id
        if name in self.vocabulary.objects:
            self.objects.add(name)
            return Node(Kind.OBJECT, node, const=name)
        if name in self.vocabulary.arms:
            self.arms.add(name)
            return Node(Kind.ARM, node, const=name)
        if name in CALLABLES:
            self.fail(ExprTypeError, f"function {name!r} must be called, as in {CALLABLES[name].signature}", node)
        self.unknown_name(node, name)

    def attribute(self, node: ast.Attribute) -> Node:
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
                f"attribute {attr!r} of {kind}{owner!r} is not a feature{suggest(attr, allowed)} "
                f"(allowed: {', '.join(allowed)})",
                node,
                attr,
                self.attr_column(node),
            )
        group.add(owner)
        size = FEATURE_SIZES.get(attr)
        kind = Kind.ANY if size is None else (Kind.SCALAR if size == 0 else Kind.VECTOR)
        get = operator.attrgetter(attr)

        def read_object(f: FeatureFrame) -> Value:
            return get(f.objects[owner])

        def read_arm(f: FeatureFrame) -> Value:
            return get(f.arms[owner])

        fn = read_object if table == "objects" else read_arm
        return Node(kind, node, fn=fn, size=size or None, feature=(table, owner, attr))

    def unary(self, node: ast.UnaryOp) -> Node:
        if type(node.op) in REFUSED_OPERATORS:
            symbol = REFUSED_OPERATORS[type(node.op)]
            self.fail(
                ExprForbiddenError,
                f"operator {symbol!r} in {self.segment(node)!r} is not allowed (allowed: {ALLOWED_OPERATORS})",
                node,
                symbol,
            )
        operand = self.value(node.operand, "an operand")
        if isinstance(node.op, ast.UAdd):
            return Node(operand.kind, node, fn=operand.fn, const=operand.const, size=operand.size)
        if operand.is_const:
            return Node(operand.kind, node, const=ops.negate(operand.const), size=operand.size)
        a = operand.fn
        return Node(operand.kind, node, fn=lambda f: -a(f), size=operand.size)

    def binary(self, node: ast.BinOp) -> Node:
        symbol = OPERATORS.get(type(node.op))
        if symbol is None:
            refused = REFUSED_OPERATORS.get(type(node.op), type(node.op).__name__)
            self.fail(
                ExprForbiddenError,
                f"operator {refused!r} in {self.segment(node)!r} is not allowed (allowed: {ALLOWED_OPERATORS})",
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
            return Node(kind, node, const=_freeze(folded), size=size)
        fn = ops.binary(symbol, left.fn, left.const, right.fn, right.const)
        return Node(kind, node, fn=fn, size=size)

    def check_exponent(self, node: ast.AST, exponent: Node) -> None:
        ok = exponent.is_const and exponent.kind is Kind.SCALAR
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

    def combine(self, node: ast.BinOp, symbol: str, left: Node, right: Node) -> tuple[Kind, int | None]:
        """Kind and length of ``left <symbol> right`` (numpy broadcasting of scalars)."""
        if symbol == "**":
            return left.kind, left.size
        if left.kind is Kind.VECTOR and right.kind is Kind.VECTOR:
            if left.size is not None and right.size is not None and left.size != right.size:
                self.fail(
                    ExprTypeError,
                    f"cannot combine vectors of {left.size} and {right.size} values in {self.segment(node)!r}",
                    node,
                )
            return Kind.VECTOR, left.size or right.size
        if Kind.ANY in (left.kind, right.kind):
            return Kind.ANY, None
        if Kind.VECTOR in (left.kind, right.kind):
            return Kind.VECTOR, left.size or right.size
        return Kind.SCALAR, None

    def sequence(self, node: ast.List | ast.Tuple) -> Node:
        if not node.elts:
            self.fail(ExprTypeError, "empty vector [] is not allowed", node)
        items = []
        for element in node.elts:
            item = self.value(element, "a vector component")
            if item.kind is Kind.VECTOR:
                self.fail(
                    ExprTypeError,
                    f"vector component {self.segment(element)!r} is itself a vector: components must be scalars",
                    element,
                )
            items.append(item)
        if all(item.is_const for item in items):
            value = np.array([i.const for i in items], dtype=float)
            return Node(Kind.VECTOR, node, const=_freeze(value), size=len(items))
        return Node(Kind.VECTOR, node, fn=ops.vector([i.operand() for i in items]), size=len(items))

    def subscript(self, node: ast.Subscript) -> Node:
        index_node = node.slice
        if isinstance(index_node, ast.Slice):
            self.fail(ExprForbiddenError, FORBIDDEN[ast.Slice].format(part=self.segment(index_node)), index_node)
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
        if base.kind is Kind.SCALAR:
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
            return Node(Kind.SCALAR, node, const=float(base.const[index]))
        if base.feature is not None:
            # Fused read: bottle.bottom[2] costs one closure, not two.
            table, owner, attr = base.feature
            get = operator.attrgetter(attr)
            if table == "objects":
                return Node(Kind.SCALAR, node, fn=lambda f: float(get(f.objects[owner])[index]))
            return Node(Kind.SCALAR, node, fn=lambda f: float(get(f.arms[owner])[index]))
        a = base.fn
        return Node(Kind.SCALAR, node, fn=lambda f: float(a(f)[index]))

    def call(self, node: ast.Call) -> Node:
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
                f"call to {name!r} is not allowed{suggest(name, CALLABLES)} (allowed: {', '.join(CALLABLES)})",
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
        sizes = {a.size for a in args if a.kind is Kind.VECTOR and a.size is not None}
        if function.same_size and len(sizes) > 1:
            self.fail(
                ExprTypeError,
                f"{function.signature} needs vectors of one length, got lengths {sorted(sizes)}",
                node,
            )
        if function.returns is ArgKind.SCALAR:
            kind, size = Kind.SCALAR, None
        else:
            first = next((a.size for a in args if a.kind in (Kind.VECTOR, Kind.ANY)), None)
            kind, size = Kind.VECTOR, function.returns_size or first
        if not function.reads_frame and all(a.is_const for a in args):
            try:
                with np.errstate(all="ignore"):
                    folded = function.impl(*[a.const for a in args])
            except (ValueError, ArithmeticError, IndexError) as exc:
                self.fail(ExprTypeError, f"cannot compute {self.segment(node)!r}: {exc}", node)
            return Node(kind, node, const=_freeze(folded), size=size)
        fn = ops.call(function.impl, function.reads_frame, [a.operand() for a in args])
        return Node(kind, node, fn=fn, size=size)

    def argument(self, function: Function, index: int, node: ast.AST) -> Node:
        """Compile argument ``index`` of a call and check it against its parameter."""
        param = function.params[min(index, len(function.params) - 1)]
        arg = self.compile(node)
        where = f"argument {param.name!r} of {function.signature}"
        if param.kind in (ArgKind.OBJECT, ArgKind.ARM):
            wanted = Kind.OBJECT if param.kind is ArgKind.OBJECT else Kind.ARM
            if arg.kind is not wanted:
                names = self.vocabulary.objects if wanted is Kind.OBJECT else self.vocabulary.arms
                if arg.kind in (Kind.OBJECT, Kind.ARM):
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
        if arg.kind in (Kind.OBJECT, Kind.ARM):
            feature = "pos" if arg.kind is Kind.OBJECT else "ee"
            self.fail(
                ExprTypeError,
                f"{where} must be a {param.kind.value}, got {arg.kind.value} {arg.const!r} "
                f"(did you mean {arg.const}.{feature}?)",
                node,
            )
        if param.kind is ArgKind.SCALAR and arg.kind is Kind.VECTOR:
            self.fail(
                ExprTypeError,
                f"{where} must be a scalar, got the vector {self.segment(node)!r} (reduce it with norm() or v[i])",
                node,
            )
        if param.kind is ArgKind.VECTOR:
            if arg.kind is Kind.SCALAR:
                self.fail(ExprTypeError, f"{where} must be a vector, got the scalar {self.segment(node)!r}", node)
            if param.size is not None and arg.size is not None and arg.size != param.size:
                self.fail(
                    ExprTypeError,
                    f"{where} must be a vector of {param.size} values, got {arg.size}: {self.segment(node)!r}",
                    node,
                )
        return arg


_HANDLERS = {
    ast.Constant: ClosureBuilder.constant,
    ast.Name: ClosureBuilder.name,
    ast.Attribute: ClosureBuilder.attribute,
    ast.UnaryOp: ClosureBuilder.unary,
    ast.BinOp: ClosureBuilder.binary,
    ast.List: ClosureBuilder.sequence,
    ast.Tuple: ClosureBuilder.sequence,
    ast.Subscript: ClosureBuilder.subscript,
    ast.Call: ClosureBuilder.call,
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
