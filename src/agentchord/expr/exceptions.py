"""Exceptions of the expression language.

Every refusal names the offending part of the source (``part``) and, where the
parser knows it, its column, so that a human or an LLM can repair the
expression from the message alone.
"""

from __future__ import annotations

#: Longest source excerpt quoted in a message; task-graph expressions are short.
_QUOTE_LIMIT = 120


class ExprError(ValueError):
    """Base class: an expression was refused or could not be evaluated.

    Attributes:
        message: What is wrong, naming the offending part.
        source: The whole expression source.
        part: The offending text (``__import__``, ``lambda``, ``bottle.mass``),
            or ``None`` when the whole source is at fault.
        col: 0-based column of ``part`` in its line of ``source``, or ``None``.
    """

    def __init__(
        self,
        message: str,
        *,
        source: str = "",
        part: str | None = None,
        col: int | None = None,
    ) -> None:
        self.message = message
        self.source = source
        self.part = part
        self.col = col
        super().__init__(message)

    def __str__(self) -> str:
        if not self.source:
            return self.message
        quoted = self.source if len(self.source) <= _QUOTE_LIMIT else self.source[:_QUOTE_LIMIT] + "..."
        where = f"at column {self.col} of" if self.col is not None else "in"
        return f"{self.message} ({where} {quoted!r})"

    def __reduce__(self) -> tuple[object, ...]:
        # Keyword-only fields would be lost by the default pickling of exceptions
        # (the bench runner ships errors between processes).
        return (_rebuild, (type(self), self.message, self.source, self.part, self.col))


def _rebuild(cls: type[ExprError], message: str, source: str, part: str | None, col: int | None) -> ExprError:
    return cls(message, source=source, part=part, col=col)


class ExprSyntaxError(ExprError):
    """The source is not a well-formed Python expression."""


class ExprForbiddenError(ExprError):
    """The source uses a construct the language does not allow (lambda, comparison, ...)."""


class ExprNameError(ExprError):
    """The source names an unknown object, arm, feature attribute or function."""


class ExprTypeError(ExprError):
    """Wrong argument count or kind, or a non-scalar result, detected at compile time."""


class ExprValueError(ExprError):
    """A constant part of the source is NaN or infinite where finite numbers are required."""


class ExprEvalError(ExprError):
    """A compiled expression could not be evaluated on a frame (missing object, ...)."""
