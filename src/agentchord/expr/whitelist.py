"""The whitelist of the expression language: what may be written, and the hint for what may not.

The :class:`~agentchord.expr.builder.ClosureBuilder` compiles the allowed operators and reads
features of the sizes below; everything else is refused with the message kept here.
"""

from __future__ import annotations

import ast

#: Largest accepted |exponent| of ``**``: bounds the cost and size of powers.
MAX_EXPONENT = 10.0

#: Vector lengths of the frame's features (0 = scalar); see features/frame.py.
FEATURE_SIZES = {
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

#: The binary operators the language computes.
OPERATORS: dict[type[ast.operator], str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Pow: "**",
}
#: Python operators the language refuses, as they are written.
REFUSED_OPERATORS: dict[type[ast.AST], str] = {
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
#: The allowed operators, as messages list them.
ALLOWED_OPERATORS = "+ - * / ** and unary -"

#: Constructs refused outright, with a hint that says what to write instead.
FORBIDDEN: dict[type[ast.AST], str] = {
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
