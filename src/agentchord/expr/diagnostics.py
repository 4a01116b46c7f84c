"""Errors located in an expression's source: the part that is wrong, its column, a suggestion."""

from __future__ import annotations

import ast
import difflib
from collections.abc import Iterable
from typing import NoReturn

from agentchord.expr.exceptions import ExprError


class SourceLocator:
    """Points at the source of an ast node, and raises errors located there.

    Attributes:
        source: The expression as written.
        text: What was parsed: ast positions refer to it.
        shift: Column of ``text``'s first character in ``source``.
    """

    def __init__(self, source: str, text: str, shift: int) -> None:
        self.source = source
        self.text = text  # what was parsed: ast positions refer to it
        self.shift = shift  # column of text's first character in source

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


def shorten(text: str, limit: int = 40) -> str:
    """``text`` cut to ``limit`` characters, ending in ``...`` when cut (for messages)."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def suggest(name: str, known: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the known name closest to ``name``, or ``""`` when none is close."""
    close = difflib.get_close_matches(name, list(known), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""
