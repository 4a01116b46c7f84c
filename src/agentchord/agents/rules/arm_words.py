"""Which arm does a step: the ways people name an arm without the grammar's ``with the left arm``.

Read a sentence at a time by :mod:`~agentchord.agents.rules.discourse` (after its particles), on
normalised text. The grammar reads ``with|using|by the left|right|other arm|hand|gripper`` and
``to the right arm`` after a hand-over; people also write:

- **a side alone**: "with the left", "w/ right", "using your left one", "pass it to right", "give it
  the right one" -> ``with the left arm``, ``to the right arm`` (the side names an arm only where an
  arm is expected: after ``with``, ``using``, ``by`` or a hand-over's ``to``, and not before a part
  word: "with the left side" stays a place);
- **an arm named by what it holds**: "with the bottle in your left hand" -> ``from the bottle with
  the left arm``; "in your right hand" -> ``with the right arm``;
- **an arm referred back to**: "hand it to the left arm and have it put the bottle down", "... to
  the right one and have that one put it in the tray" -> the step ``with the left arm``: ``it``,
  ``that one``, ``that arm``, ``the same one`` after ``have``/``let`` is the arm named last;
- **an arm for each object**: "use your right arm for the blue block and your left for the red one, and put
  both in the cup" -> the step for each object, by its arm (:func:`each_arm`); "the left arm takes the red
  cube and the right arm takes the blue one" -> two steps;
- **a hand-over said from the receiver's side**: "the right hand takes the block from the left hand" -> ``hand the
  block over to the right arm``; "..., passing it from the left hand to the right on the way" -> the hand-over first;
- **a hand-over with no object said**: "pass to the right arm" -> ``pass it to the right arm``;
  "from left to right" -> ``from the left arm to the right arm``.
"""

from __future__ import annotations

import re

from agentchord.agents.rules.rewrite_steps import Note, NotAGoalError, sub

#: Words after a side that make it a part of something, not an arm.
_PART = r"(?:arm|hand|gripper|of|side|half|edge|corner|corners|end|part|area|region)s?"
#: An arm named by its side alone, after a hand-over or "with": "to your right", "with the other".
_ARM_ELLIPSIS = [
    # "move the block from one hand to the other": whatever the verb, the object goes from arm to arm: a hand-over.
    (re.compile(r"\b(?:move|shift|bring|transfer|switch|swap|carry|take|pass|hand|give) (it|them|the [a-z]+(?: [a-z]+)?) "
                r"(?:from one (?:arm|hand|gripper|side) (?:to|into) the other(?: one| arm| hand| gripper| side)?|"
                r"from (?:hand|arm|gripper) to (?:hand|arm|gripper))\b"), r"hand \1 over"),
    # "pass it from one hand to the other", "from hand to hand": a hand-over, the giver the planner's to choose.
    (re.compile(r"\b(?:from one (?:arm|hand|gripper|side) (?:to|into) the other(?: one| arm| hand| gripper| side)?|"
                r"from (?:hand|arm|gripper) to (?:hand|arm|gripper)|between (?:the |your |its )?(?:two )?(?:hands|arms|grippers))\b"), "over"),
    # "give it to right arm", "with left hand": an arm said without its determiner.
    (re.compile(r"\b(to|with|using|from|by|into|over to) (left|right) (arm|hand|gripper)\b"), r"\1 the \2 \3"),
    # "pass to right", "hand over to the left one": the object is the one in hand.
    (re.compile(r"(?:^|(?<= , )|(?<=\band )|(?<=\bthen ))(hand|pass|give|transfer)(e?s?) (?:over |across )?to "
                r"(?=(?:the |your )?(?:left|right|other)(?: one| arm| hand| gripper)?\b(?! (?:side|of|half|edge|corner)))"), r"\1\2 it over to "),
    (re.compile(r"\b((?:hand|pass|give|transfer)\w* (?:it|them|the [a-z]+(?: [a-z]+)?) (?:over |across |off )?to) (?:the |your |my )?"
                rf"(left|right)(?: one)?\b(?! {_PART}\b)"), r"\1 the \2 arm"),
    # "give it the right one": the receiver said without "to".
    (re.compile(r"\b((?:give|hand|pass)\w* (?:it|them)) (?=(?:the|your) (?:left|right|other) (?:one|arm|hand|gripper)\b)"), r"\1 to "),
    (re.compile(rf"\b(with|in|using|by) (?:the |your |my )?(left|right)(?: one)?\b(?! {_PART}\b)(?! (?:the|a|an|it|them)\b)"), r"\1 the \2 arm"),
    (re.compile(r"\b(to|with|in|by|from) (?:the )?(left|right) one\b"), r"\1 the \2 arm"),
    (re.compile(r"\bwith (?:the )?(\w+) in (?:your|the) (left|right)(?: hand| arm| gripper| one)?\b"), r"from the \1 with the \2 arm"),
    (re.compile(r"\bin (?:your|the) (left|right)(?: hand| arm| gripper| one)?\b(?! (?:side|of|corner|half|edge)\b)"), r"with the \1 arm"),
    (re.compile(r"\bin (left|right) (?:hand|arm|gripper)\b"), r"with the \1 arm"),
    (re.compile(r"\b(hand|pass|give|transfer)(\w*(?: (?:it|them|the [a-z]+))?(?: over| across)?) from (?:the |your )?(left|right)"
                r"(?: arm| hand| gripper)? to (?:the |your )?(right|left)(?: arm| hand| gripper| one)?\b"), r"\1\2 from the \3 arm to the \4 arm"),
    # "move the block to the target with a handover, left to right": the hand-over first, then the move.
    (re.compile(r"^(?:move|put|place|bring|get|take) (the [a-z]+(?: [a-z]+)?) (to|onto|on|in|into) ([a-z ]+?) (?:with|via|using|by) (?:a )?handover"
                r"(?: ,)? (?:from )?(?:the )?(left|right)(?: arm| hand)? to (?:the )?(right|left)(?: arm| hand)?\b"),
     r"hand \1 over from the \4 arm to the \5 arm , then put \1 \2 \3"),
    (re.compile(r"\bthe (left|right) one\b(?= (?:put|place|set|pour|take|grab|hold|drop|fill|pick)\b)"), r"the \1 arm"),
    (re.compile(r"\b(left|right) arm (hand|arm|gripper)\b"), r"\1 \2"),
    (re.compile(r"\bhandover (?=to the (?:left|right|other) arm\b)"), "hand it over "),
]
#: "use your right arm for the blue block and your left for the red one, and put both in the cup": the step for each.
_EACH_ARM = re.compile(r"^(?:please )?(?:use|using) (?:your |the )?(left|right) (?:arm|hand|gripper) for (the [a-z]+(?: [a-z]+)?) and "
                       r"(?:your |the )?(left|right)(?: arm| hand| gripper| one)? for (the [a-z]+(?: [a-z]+)?) , (?:and )?(?:then )?"
                       r"(\w+) (?:both of them|them both|both|them|the two) (.+)$")
#: "the left arm takes the red cube and the right arm takes the blue one": two steps, each its arm's.
_SECOND_SUBJECT = re.compile(r"(?<=\w) and (?=(?:the |your )?(?:left|right) (?:arm|hand|gripper) (?!and\b|to\b|with\b)[a-z]+ )")
#: "the right arm then pours ...": the order word before the arm's step.
_ARM_THEN = re.compile(r"(?:^|(?<= , ))((?:the |your )?(?:left|right) (?:arm|hand|gripper)) (?:then|next|afterwards|after that) (?=[a-z]+)")
#: "the right hand takes the block from the left hand", "take it from the left arm with the right": a hand-over.
_TAKE_FROM = [
    re.compile(r"(?:^|(?<= , ))(?:the |your )?(left|right) (?:arm|hand|gripper) (?:take|grab|receive|get|accept)s? (it|the [a-z]+(?: [a-z]+)?) "
               r"from (?:the |your )?(?:left|right|other) (?:arm|hand|gripper|one)\b"),
    re.compile(r"(?:^|(?<= , ))(?:take|grab|receive|get|accept) (it|the [a-z]+(?: [a-z]+)?) from (?:the |your )?(?:left|right|other) (?:arm|hand|gripper|one) "
               r"with (?:the |your )?(left|right) (?:arm|hand|gripper)\b"),
]
#: "move the block onto the target, passing it from the left hand to the right on the way": the hand-over first.
_PASSING = re.compile(r"^(.+?) , (?:by )?(?:passing|handing|transferring|giving|switching) (?:it|them) (?:over )?from (?:the |your )?(left|right)"
                      r"(?: arm| hand| gripper)? to (?:the |your )?(left|right)(?: arm| hand| gripper)?(?: (?:on the way|along the way|first|in between))?$")
#: "have it put the bottle down", "let that one place it in the tray": the arm said last does the step.
_ARM_AGAIN = re.compile(r"\b(?:have|let|make) (?:it|that one|that arm|that hand|this one|the same one|the same arm|that gripper) (\w+)\b([^,]*)")
_LAST_ARM = re.compile(r"\b(left|right) (?:arm|hand|gripper)\b")


def each_arm(s: str, note: Note) -> str:
    """``use your right arm for X and your left for Y , and put both in Z`` -> ``put X in Z with the right arm , put Y in
    Z with the left arm`` (read before the arm a whole sentence asks for)."""
    return sub(_EACH_ARM, lambda m: f"{m[5]} {m[2]} {m[6]} with the {m[1]} arm , {m[5]} {m[4]} {m[6]} with the {m[3]} arm", s, note, "arm")


#: "..., then use both hands to carry the tray": an arm asked for inside a sentence, for the step after it.
_USE_TO = re.compile(r"(?:(?<= , )|(?<=\bthen )|(?<=\band ))(?:use|using) (?:your |the )?(left|right|both|two) (?:arm|hand|gripper)s? "
                     r"(?:to|and) (\w+)\b([^,]*?)(?= ,|$| then\b)")


#: "pick up both of them, the cup in your left and the bottle in your right": the pronoun is the list after it.
_EACH_NAMED = re.compile(r"\b(pick up|pick|take|grab|grasp|hold|lift)(?: up)? (?:both|them|them both|the two|both of them)(?: up)? , "
                         r"(?:the )?([a-z]+) with the (left|right) arm(?: ,)? and (?:the )?([a-z]+) with the (left|right) arm\b")


def _with(arm: str) -> str:
    return "with both arms" if arm in ("both", "two") else f"with the {arm} arm"


def read_arms(s: str, note: Note) -> str:
    """``s`` (one sentence) with the arms it names in the grammar's words (see the module)."""
    s = sub(_USE_TO, lambda m: f"{m[2]}{m[3]} {_with(m[1])}", s, note, "arm")
    s = sub(_SECOND_SUBJECT, " , ", s, note, "arm")
    s = sub(_ARM_THEN, r"then \1 ", s, note, "order")
    s = sub(_TAKE_FROM[0], r"hand \2 over to the \1 arm", s, note, "arm")
    s = sub(_TAKE_FROM[1], r"hand \1 over to the \2 arm", s, note, "arm")
    passing = _PASSING.match(s)
    thing = re.search(r"\bthe [a-z]+(?: (?!on\b|onto\b|in\b|into\b|to\b|with\b)[a-z]+)?", passing[1]) if passing is not None else None
    if passing is not None and thing is not None:
        s = f"hand {thing[0]} over from the {passing[2]} arm to the {passing[3]} arm , then {passing[1]}"
        note("order")
    for pattern, repl in _ARM_ELLIPSIS:
        s = sub(pattern, repl, s, note, "arm")
    s = sub(_EACH_NAMED, r"\1 the \2 with the \3 arm and the \4 with the \5 arm", s, note, "arm")
    while (again := _ARM_AGAIN.search(s)) is not None:
        arms = _LAST_ARM.findall(s[: again.start()])
        if not arms:
            break
        s = s[: again.start()] + f"{again[1]}{again[2].rstrip()} with the {arms[-1]} arm" + s[again.end():]
        note("arm")
    return s


#: "..., not the right one", "but not with your left hand": the arm the step is not done with.
_NOT_ARM = re.compile(r"(?: ,)? (?:and |but )?(?:please )?(?:not (?:with |using )?|(?:do not|don't|dont|never) (?:use|move) |without (?:using )?)"
                      r"(?:the |your )?(left|right)(?: one| arm| hand| gripper)(?: (?:at all|for (?:this|that|it)))?(?= ,|$)|"
                      r"(?: ,)? (?:and |but )?not (?:with |using )?(?:the |your )?(left|right)(?= ,|$)")
_ARM_NAMED = re.compile(r"\b(left|right) (?:arm|hand|gripper)\b")


def not_this_arm(s: str, note: Note) -> str:
    """``s`` (one sentence) with an arm it says not to use read: said beside the other arm, it adds nothing (dropped);
    alone, the step is the other arm's.

    Raises:
        NotAGoalError: The arm not to use is the one the sentence names for the step.
    """
    m = _NOT_ARM.search(s)
    if m is None:
        return s
    arm = m[1] or m[2]
    named = set(_ARM_NAMED.findall(s[: m.start()] + s[m.end():]))
    if arm in named:
        raise NotAGoalError(f"says to use the {arm} arm and not to use it")
    note("arm")
    other = "" if named else f" with the {'right' if arm == 'left' else 'left'} arm"
    return (s[: m.start()] + other + s[m.end():]).strip()
