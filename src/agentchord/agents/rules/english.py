"""Which words are English: a real word is never taken for a typo.

The offline composer corrects spelling towards the words it knows (:func:`~agentchord.agents.rules.phrasing.correct`);
a word people write that it does not know may still be English ("tidy", "line", "handles", "bother"),
and "correcting" it into a known word changes the meaning ("tiny", "lie", "handes", "other"). The
list is ``data/english_words.txt``: 25k lower-case words of a public frequency list (its header
says which), read once, the first time a word outside the rules' vocabulary is checked.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

WORDS_FILE = Path(__file__).parent / "data" / "english_words.txt"


@cache
def _words() -> frozenset[str]:
    lines = WORDS_FILE.read_text(encoding="ascii").splitlines()
    return frozenset(line for line in lines if line and not line.startswith("#"))


def is_word(word: str) -> bool:
    """Whether ``word`` (lower case) is an English word of the list."""
    return word in _words()
