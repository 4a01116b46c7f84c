"""A pour into a vessel held up: said as a condition on the pour, anywhere in the instruction.

The grammar reads a held pour as two steps, ``hold the cup , pour water into it`` (the pour's
``hold_target``). People say the holding as a condition on the pour instead, before or after it, in
the same sentence or another:

- "pour water into the cup while holding it up";
- "hold it up off the table while you pour", "keep the cup in the air while pouring";
- "the cup should be held up off the table while you pour, not sitting on it";
- "do the pour with the cup held up, not on the table";
- "pour me some water but hold the cup up while you do it" (what is done, in a sentence with a pour, is the pour).

:func:`take_conditions` removes such a condition from a sentence and returns what is held (a noun
phrase, or ``it``); :func:`hold_before_pour` then puts ``hold X , then`` before the instruction's
first pour (``it`` is the pour's vessel poured into), unless the instruction already takes X in hand
before it. Without a pour the condition is left where it was (and refused there).
"""

from __future__ import annotations

import re

from agentchord.agents.rules.rewrite_steps import Note

_NP = r"(?:it|them|(?:the )?[a-z]+(?: (?!held|lifted|kept|up|should|must|needs?|has|will|while)[a-z]+)?)"
_UP = r"(?: up)?(?: (?:in the air|in mid-? ?air|off the table|above the table|in (?:your|the) hand))?(?: up)?"
#: "while you pour", and "while you do it" said in the sentence of a pour (the pour is what is done).
_WHILE_POUR = (r"(?:while|as|when) (?:you(?:'re| are)? |u )?(?:pour|pouring|fill|filling|tip|tipping|do it|do that|are doing it|'re doing it)"
               r"(?: it| into it| in)?(?: though)?(?: (?:lol|haha|yeah|ok|okay|pls|please))*")
_NOT_ON = r"(?: , not (?:sitting |standing |resting )?on (?:the table|it|the surface))?"
_ARM = r"(?P<arm> with (?:the |your )?(?:left|right) (?:arm|hand|gripper))?"
#: A condition on a pour that the vessel poured into is held (group ``np``: what is held).
_CONDITIONS = [
    re.compile(rf"(?:^|(?<= , )|(?<= )(?=but ))(?:and |but )?(?:please )?(?:hold|lift|keep|have) (?P<np>{_NP})(?: held| lifted| raised)?{_UP}{_ARM} "
               rf"{_WHILE_POUR}"
               rf"{_NOT_ON}(?= ,|$)"),
    re.compile(rf"(?:^|(?<= , ))(?:and |but )?(?P<np>{_NP}) (?:should|must|needs? to|has to|will) be (?:held|lifted|kept){_UP} "
               rf"{_WHILE_POUR}{_NOT_ON}(?= ,|$)"),
    re.compile(rf"(?:^|(?<= , ))(?:and |but )?(?:please )?(?:do|make) (?:the|your) pour(?:ing)? with (?P<np>{_NP}) (?:held|lifted|kept|up){_UP}"
               rf"{_NOT_ON}(?= ,|$)"),
    re.compile(rf"(?: ,)? (?:while|whilst) (?:you(?:'re| are)? )?(?:holding|lifting|you hold) (?P<np>{_NP}){_UP}{_ARM}{_NOT_ON}(?= ,| then\b|$)"),
    re.compile(rf"(?: ,)? (?:while|whilst|as) (?P<np>it|the [a-z]+)(?:'s| is) (?:held|lifted|raised|kept){_UP}{_ARM}{_NOT_ON}(?= ,| then\b|$)"),
    # "don't put the cup down while you're pouring, just hold it up": the vessel not put down is held.
    re.compile(rf"(?:^|(?<= , ))(?:and |but )?(?:don't|do not|dont|never) (?:put|set|place|rest) (?P<np>{_NP}) down {_WHILE_POUR}"
               rf"(?: , (?:just |only )?(?:hold|keep) (?:it|them)(?: held)?{_UP})?(?= ,|$)"),
    # "don't pour while the cup's sitting on the table, lift it up first": the pour not to be done on the table.
    re.compile(r"(?:^|(?<= , ))(?:and |but )?(?:don't|do not|dont|never) (?:pour|fill it|tip) (?:while|when|with) (?P<np>it|the [a-z]+)"
               r"(?:'s| is)? (?:sitting |standing |resting |still )?on the table"
               r"(?: , (?:just |only )?(?:lift|hold|pick|keep) (?:it|them) up(?: first)?)?(?= ,|$)"),
    # "pour while the cup's off the table, not on it": the condition said after the pour's verb (the pour stays).
    re.compile(rf"(?<=\bpour)(?: water)? (?:while|with|when) (?P<np>it|the [a-z]+)(?:'s| is)? (?:held |lifted |kept |raised )?"
               rf"(?:up|off the table|in the air|above the table|lifted|held up){_NOT_ON}(?= ,|$)"),
]
_POUR = re.compile(r"\b(?:the [a-z]+ )?(?:pour|fill|tip|empty|decant)(?:s|ed|ing)?\b")


def take_conditions(sentence: str, note: Note) -> tuple[str, list[tuple[str, str]]]:
    """``sentence`` without its held-pour conditions, and what each holds (a noun phrase, and the arm said or ``""``)."""
    held: list[tuple[str, str]] = []
    for pattern in _CONDITIONS:
        while (m := pattern.search(sentence)) is not None:
            held.append((m["np"], (m.groupdict().get("arm") or "").strip()))
            sentence = (sentence[: m.start()] + sentence[m.end():]).strip(" ,")
            sentence = re.sub(r"\s*,(?:\s*,)+", " ,", sentence)
            note("held pour")
    return sentence, held


def hold_before_pour(sentences: list[str], held: list[tuple[str, str]]) -> list[str] | None:
    """``sentences`` with ``hold X , then`` before the first pour, or ``None`` where nothing pours."""
    for k, sentence in enumerate(sentences):
        pour = _POUR.search(sentence)
        if pour is None:
            continue
        clause = sentence[pour.start():].split(" , ")[0]
        target = re.search(r"\b(?:into|in|inside) (the [a-z]+(?: (?!with\b|from\b|then\b|and\b)[a-z]+)?|it)\b|"
                           r"^fill (?:up )?(the [a-z]+|it)\b|^(the [a-z]+) filled\b", clause)
        np, arm = held[0]
        if np in ("it", "them"):
            if target is None:
                return None
            np = target[1] or target[2] or target[3]
        elif not np.startswith("the "):
            np = f"the {np}"
        before = " ".join(sentences[:k]) + " " + sentence[: pour.start()]
        taken = r"\b(?:hold|pick up|pick|take|lift|grab|grasp)\w* (?:up )?"
        if re.search(taken + re.escape(np) + r"\b", before) or (held[0][0] in ("it", "them") and re.search(taken, before)):
            return sentences  # taken in hand already: the pour reads it held
        out = list(sentences)
        out[k] = f"{sentence[: pour.start()]}hold {np}{' ' + arm if arm else ''} , then {sentence[pour.start():]}"
        return out
    return None
