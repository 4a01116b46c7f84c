"""Parsing an expression, after cheap bounds on its size and nesting (before the parser sees it)."""

from __future__ import annotations

import ast
import warnings

from agentchord.expr.exceptions import ExprForbiddenError, ExprSyntaxError

#: Longest accepted source, in characters.
MAX_SOURCE_LENGTH = 2000
#: Deepest accepted nesting, of brackets or of the expression tree.
MAX_DEPTH = 50


def parse_bounded(source: str) -> tuple[ast.Expression, str, int]:
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
        with warnings.catch_warnings():
            # "1if", "0.5and": Python only warns (on stderr) of a number run into a keyword; here it
            # is an error like any other, reported with the expression.
            warnings.simplefilter("error", SyntaxWarning)
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
