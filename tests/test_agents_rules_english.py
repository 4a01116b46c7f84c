"""A real English word is never taken for a typo (issue 59); a typo still is."""

from agentchord.agents.rules.english import is_word
from agentchord.agents.rules.phrasing import correct, correct_place

VOCABULARY = frozenset({"bottle", "tray", "handes", "tiny", "lie", "other", "pour", "put", "table", "cup"})


def test_english_words_are_words_and_typos_are_not():
    assert all(is_word(w) for w in ("tidy", "line", "handles", "bother", "load", "fill", "quickly"))
    assert not any(is_word(w) for w in ("botle", "handes", "capsul", "hlaf", "placeing"))


def test_a_real_word_is_not_corrected_into_a_known_one_but_a_typo_is():
    for word in ("tidy", "line", "handles", "bother"):
        assert correct(word, VOCABULARY) is None, word
    assert correct("botle", VOCABULARY) == "bottle"
    assert correct("trya", VOCABULARY) == "tray"


def test_after_the_an_english_word_one_edit_from_the_table_is_the_table():
    assert correct_place("tale") == "table" and correct_place("cable") == "table" and correct_place("cup") is None
