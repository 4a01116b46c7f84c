"""The order objects of one step are done in: "put both blocks in the cup, the red one first".

Read by :mod:`~agentchord.agents.rules.discourse`, on normalised text. A step on two objects said
together ("put both blocks in the cup", "pick up the two blocks and put them in the cup") followed by
which goes first is that step for each, in the order said:

- in the same sentence: "..., red first then blue", "..., the red one first" (the other one after);
- in the next sentence: "Put both blocks into the cup. Red one first, then the blue one.";
- the objects listed first, the step after: "First the fork, then the spoon: place each one next to the plate";
- a step said after another but done first: "put it on the target, but first pass it to the right arm" (:func:`first_before`).

Where only the first is said, the second step names both again (``put both blocks in the cup``): the
one already done is not done twice (a goal said twice is one goal).
"""

from __future__ import annotations

import re

from agentchord.agents.rules.rewrite_steps import Note, sub

_STEP = (r"(?:(?:could|can|would|will) you |please )*"
         r"(?:(?:pick up|take|grab|lift) (?:both|the two|the) (\w+?)s and (put|place|drop|set|move) them|"
         r"(put|place|drop|set|move) (?:both|the two|the) (\w+?)s)")
_FIRST = r"(?:the )?(\w+)(?: one)? first(?:(?: ,)?(?: and)?(?: then)? (?:the )?(\w+)(?: one)?)?"
#: "(pick up both blocks and) put them in the cup, red first then blue": each, in the order said.
_EACH_IN_ORDER = re.compile(rf"^{_STEP} (.+?) , {_FIRST}$")
#: A sentence that only says which goes first ("red one first, then the blue one").
_FIRST_ALONE = re.compile(rf"^(?:and )?{_FIRST}$")
_STEP_ALONE = re.compile(rf"^{_STEP} (.+)$")


#: "first the fork, then the spoon" said alone, and "place each one next to the plate" after it.
_LIST = re.compile(r"(?:first )?(?:the )?([a-z]+(?: (?!first\b)[a-z]+)?)(?: first)?(?: ,)? (?:and )?then (?:the )?([a-z]+(?: [a-z]+)?)")
_EACH = re.compile(r"(\w+) (?:each(?: one| of them)?|them(?: each| both)?|both(?: of them)?|the two) (.+)")


#: "doesn't matter which one goes first", "in any order", "order doesn't matter": the order is free (the rules do
#: them in the order named), so the remark states no goal.
ANY_ORDER = re.compile(
    r"(?:^|(?: ,)? )(?:and |but )?(?:(?:it |the order )?(?:doesn't|does not|dont|don't|won't|will not) matter"
    r"(?: (?:which|what|who|in what order|the order|what order|which order|which way)\b[a-z ']*)?|"
    r"(?:the )?order (?:doesn't|does not|dont|don't) matter|(?:in )?(?:any|either|whatever|whichever) order(?: you (?:like|want|prefer))?|"
    r"in no (?:particular )?order|whichever (?:one )?(?:goes )?first|either (?:one )?(?:can go |goes )?first)(?= ,|$)")


def each_of_list(sentences: list[str], note: Note) -> list[str]:
    """``first the fork , then the spoon ; place each one next to the plate`` -> the step for each, in that order."""
    out: list[str] = []
    k = 0
    while k < len(sentences):
        listed = _LIST.fullmatch(sentences[k].strip())
        each = _EACH.fullmatch(sentences[k + 1].strip()) if listed is not None and k + 1 < len(sentences) else None
        if listed is not None and each is not None:
            out.append(f"{each[1]} the {listed[1]} {each[2]} , then {each[1]} the {listed[2]} {each[2]}")
            note("order")
            k += 2
            continue
        out.append(sentences[k])
        k += 1
    return out


def _in_order(step: re.Match[str], where: str, first: str, second: str | None) -> str:
    noun, verb = step[1] or step[4], step[2] or step[3]
    then = f"the {second} {noun}" if second else f"both {noun}s"
    return f"{verb} the {first} {noun} {where} then {verb} {then} {where}"


#: "put the red block and the blue block in the cup, blue first": the two named, one said first.
_TWO_NAMED = re.compile(r"^(put|place|drop|set|move) the (\w+) (\w+) and the (\w+)(?: \3| one)? (.+?) , (?:the )?(\w+)(?: one| \3)? first$")


#: A step said after another but done first: "put it on the target, but first pass it to the right arm".
_FIRST_AFTER = re.compile(r"^(?:but |and )?(?:first|firstly|before that)(?: ,)? (?=[a-z])")
#: The object of a step (what the moved step's "it" stands for).
_OBJECT = re.compile(r"\bthe [a-z]+(?: (?!on\b|onto\b|in\b|into\b|to\b|with\b|next\b|beside\b|and\b)[a-z]+)?")


def first_before(sentence: str, note: Note) -> str:
    """A clause opening with "(but) first" after another is done before it (its ``it``: the other's object)."""
    clauses = sentence.split(" , ")
    for k in range(1, len(clauses)):
        first = _FIRST_AFTER.match(clauses[k])
        if first is None:
            continue
        moved, before = clauses[k][first.end():], clauses[k - 1].removeprefix("then ")
        thing = _OBJECT.search(before)
        if thing is not None:
            moved = re.sub(r"\bit\b", thing[0], moved, count=1)
        clauses[k - 1], clauses[k] = moved, f"then {before}"
        note("order")
    return " , ".join(clauses)


def each_in_order(sentence: str, note: Note) -> str:
    """``put both blocks in the cup , the red one first`` -> each, in the order said."""
    sentence = sub(_EACH_IN_ORDER, lambda m: _in_order(m, m[5], m[6], m[7]), sentence, note, "order")
    two = _TWO_NAMED.match(sentence)
    if two is not None and two[6] in (two[2], two[4]):
        first, second = (two[2], two[4]) if two[6] == two[2] else (two[4], two[2])
        note("order")
        return f"{two[1]} the {first} {two[3]} {two[5]} then {two[1]} the {second} {two[3]} {two[5]}"
    return sentence


def first_of_both(before: str, sentence: str) -> str | None:
    """The step ``before`` for each object in the order ``sentence`` says ("red one first, then the blue one"), or None."""
    first = _FIRST_ALONE.fullmatch(sentence.strip())
    step = _STEP_ALONE.fullmatch(before.strip())
    if first is None or step is None:
        return None
    return _in_order(step, step[5], first[1], first[2])
