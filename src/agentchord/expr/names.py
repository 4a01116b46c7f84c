"""Which names an object may have: those the expression language can read.

Constraints and monitors name objects as bare identifiers (``dist(bottle.pos, cup.top)``),
so an object called ``my bottle``, ``__import__``, ``right`` (an arm) or ``dist`` (a
function) could never be named in one, or would mean something else. The graph models
and goal specs refuse such names when they are read, with the reason.
"""

from __future__ import annotations

import keyword
from typing import Annotated

from pydantic import AfterValidator, Field

from agentchord.expr.vocabulary import CALLABLES
from agentchord.features.frame import ARMS

#: Longest object name accepted.
MAX_NAME_LENGTH = 64


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot name an object, or ``None`` when it can."""
    if not isinstance(name, str):
        return f"an object name must be a string, got {type(name).__name__}"
    if not name:
        return "an object name cannot be empty"
    if len(name) > MAX_NAME_LENGTH:
        return f"object name {name[:20]!r}... is longer than {MAX_NAME_LENGTH} characters"
    if not name.isidentifier() or not name.isascii():
        return (
            f"object name {name!r} is not an identifier: use ASCII letters, digits and '_', "
            "not starting with a digit (e.g. my_bottle)"
        )
    if name.startswith("__") or name.endswith("__"):
        return f"object name {name!r} cannot start or end with '__'"
    if keyword.iskeyword(name):
        return f"object name {name!r} is a reserved word"
    if name in ARMS:
        return f"object name {name!r} is the name of an arm ({', '.join(ARMS)})"
    if name in CALLABLES:
        return f"object name {name!r} is the name of a function of the expression language"
    return None


def check_object_name(name: str) -> str:
    """``name`` unchanged when it can name an object.

    Raises:
        ValueError: Why it cannot (see :func:`name_problem`).
    """
    problem = name_problem(name)
    if problem is not None:
        raise ValueError(problem)
    return name


#: A ``str`` field holding an object name, checked by :func:`check_object_name`; its JSON Schema
#: carries the pattern, so that structured output (an LLM's reply) follows it too.
ObjectName = Annotated[
    str,
    AfterValidator(check_object_name),
    Field(json_schema_extra={"pattern": "^[A-Za-z_][A-Za-z0-9_]*$", "maxLength": MAX_NAME_LENGTH}),
]
