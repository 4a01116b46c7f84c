"""The safe constraint/monitor expression language.

Constraints and monitors of task graphs are strings such as
``"dist(bottle.pos, cup.top + [0.05, -0.10, 0.10]) - 0.03"``. They are parsed
with :mod:`ast`, checked against a whitelist and compiled into closures over a
:class:`~agentchord.features.frame.FeatureFrame`; nothing is ever passed to
``eval`` or ``exec``. An expression evaluates to a float: <= 0 means satisfied
(constraint) or normal (monitor), > 0 violated or failure present.

Example:
    >>> from agentchord.expr import Vocabulary, compile_expr
    >>> from agentchord.features.frame import make_static_frame
    >>> expr = compile_expr("tilt(bottle) - 20", Vocabulary(objects={"bottle"}))
    >>> expr.scalar(make_static_frame({"bottle": {}}))
    -20.0
"""

from agentchord.expr.compiler import CompiledExpr, compile_expr
from agentchord.expr.exceptions import (
    ExprError,
    ExprEvalError,
    ExprForbiddenError,
    ExprNameError,
    ExprSyntaxError,
    ExprTypeError,
    ExprValueError,
)
from agentchord.expr.library import ArgKind, Function, Param
from agentchord.expr.parse import MAX_DEPTH, MAX_SOURCE_LENGTH
from agentchord.expr.templates import TEMPLATES, TemplateInfo
from agentchord.expr.vocabulary import CALLABLES, FUNCTIONS, Vocabulary
from agentchord.expr.whitelist import MAX_EXPONENT

__all__ = [
    "CALLABLES",
    "FUNCTIONS",
    "MAX_DEPTH",
    "MAX_EXPONENT",
    "MAX_SOURCE_LENGTH",
    "TEMPLATES",
    "ArgKind",
    "CompiledExpr",
    "ExprError",
    "ExprEvalError",
    "ExprForbiddenError",
    "ExprNameError",
    "ExprSyntaxError",
    "ExprTypeError",
    "ExprValueError",
    "Function",
    "Param",
    "TemplateInfo",
    "Vocabulary",
    "compile_expr",
]
