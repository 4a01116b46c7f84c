"""The one way the sentence readers rewrite text: a pattern substituted, and the step named for ``plan --explain``;
and the one way they refuse (:class:`NotAGoalError`: recognised, but no goal the rules can state).

Shared by :mod:`~agentchord.agents.rules.discourse` and the readers it calls (places, arms, pours), so a
rewrite anywhere is recorded the same way and leaves the text's spacing the same.
"""

from __future__ import annotations

import re
from collections.abc import Callable

Note = Callable[[str], None]


class NotAGoalError(ValueError):
    """A sentence asks for something the rules recognise but cannot do (the reason is the message)."""


def sub(pattern: re.Pattern[str], repl: str | Callable[[re.Match[str]], str], text: str, note: Note, name: str) -> str:
    """``text`` with ``pattern`` replaced by ``repl`` (spaces collapsed); ``name`` noted when anything changed."""
    new = re.sub(r"\s+", " ", pattern.sub(repl, text)).strip()
    if new != text.strip():
        note(name)
    return new


def drop(pattern: re.Pattern[str], text: str, note: Note, name: str) -> str:
    """``text`` without what ``pattern`` matches (``name`` noted when anything was dropped)."""
    return sub(pattern, "", text, note, name)
