"""What should be true at the end: end states said as states, and steps said without a verb, as imperatives.

Read a clause at a time by :mod:`~agentchord.agents.rules.discourse` (after its arms and places), on
normalised text. People describe the end state instead of the steps; each kind maps to the step that
brings it about:

- **a frame** that says "the end state is" ("End result:", "I'd like", "what I want is", "what I'm after is",
  after a time clause: "when you're done I want", "when I come back I want", "by the time I'm back"): dropped
  (:data:`END_STATE`), the state after it read as usual;
- **water in a vessel**: "water in the cup", "the cup with water in it", "cup has water", "the cup
  full of water" -> ``pour water into the cup``;
- **back as it was**: "the bottle standing back where it was", "it's back in the same spot", "both
  cup and bottle (upright) on the table" -> ``put the bottle back`` (an object never taken is already
  there: the grounding states no goal for it);
- **a place said of an object**: "the capsule should end up in the tray", "the blue one goes in the
  cup", "the capsule put in the tray" -> ``put ...``; "leave the bottle standing" -> put it back;
- **a thing said to be in another**: "push the tray forward with the capsule in it" -> ``put the
  capsule in the tray , push the tray forward`` (what is inside goes in first);
- **a step without its verb**: "red into cup", "blue next to the cup" -> ``put the red into cup``.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.rules.rewrite_steps import Note, sub

#: Frames that say "the end state is": dropped, the state that follows is read as usual.
#: When the state is to hold, said before the frame: "when you're done", "when I come back", "by the time I'm back",
#: "once you've finished", "at the end".
_WHEN_DONE = (r"(?:(?:when|once|by the time|after) (?:you(?:'re| are|'ve| have)?|ur|i(?:'m| am)?) (?:all )?(?:done|finished|through|back)|"
              r"(?:when|once|by the time|after) i (?:come|get|am|'m) back|in the end|at the end|by the end|afterwards)(?: ,)? ")
END_STATE = re.compile(r"^(?:" + _WHEN_DONE + r")?(?:(?:the )?end result|result|the goal|goal|in the end|at the end|by the end|when you're done|"
                        r"(?:it |everything |things )?(?:should|must) (?:look|be) like|"
                        r"what i(?:'m| am) (?:after|going for|looking for|hoping for)(?: here)? is|"
                        r"what i (?:want|need|'d like|would like) (?:to end up with|to see|to have)(?: at the end| in the end)? is|"
                        r"what i(?:'d| would) like (?:in the end |at the end )?is|what i want (?:in the end |at the end )?is|"
                        r"(?:at the end |in the end )?i(?: just| really)?(?: want| need| would like|'d like)|"
                        r"what i(?:'d| would)? (?:want|like|need|hope) to see is|i(?:'d| would)? (?:want|like|need) to see|"
                        r"want|i'd like)(?: ,| :)? (?=the |a |an |there |both |my |water |some water )")

#: "there to be water in the cup", "the cup with water in it", "cup has water in it": a pour into the cup.
_WATER_IN = [
    (re.compile(r"^(?:there (?:to be|is|should be) )?(?:some )?water in (?:the |my )?(\w+(?: \w+)?)(?: (?:at the end|in the end))?$"),
     r"pour water into the \1"),
    (re.compile(r"^(?:the |my )?(\w+(?: \w+)?) (?:with|has|should have|to have|having|ends up with|to end up with) (?:some )?water(?: in it)?"
                r"(?: (?:at the end|in the end))?$"), r"pour water into the \1"),
    (re.compile(r"^(?:the |my )?(\w+(?: \w+)?) (?:is |should be |to be )?(?:full of|filled with) water(?: (?:at the end|in the end))?$"),
     r"pour water into the \1"),
]

#: "bottle standing back where it was", "the cup back in the same spot": put back.
_BACK_AS_IT_WAS = re.compile(r"^(?:and )?(?:then )?(?:the )?(\w+)(?: of them)?(?: and (?:the )?(\w+))?(?: both)?(?: is| are| should be| to be)?(?: both)?"
                             r"(?: standing| sitting| upright| stood| back| again)*"
                             r" (?:about |roughly |more or less |right |exactly |just )?(?:where (?:it|they) (?:was|were|started|stood|is|are)"
                             r"(?: now| before| at the start)?|where you found (?:it|them)|in the same (?:spot|place|position)|"
                             r"in (?:its|their) (?:old |original )?(?:place|places|spot|spots)|back where (?:it|they) (?:was|were|started))$")

#: "the capsule should end up in the tray", "the blue one goes in the cup", "the block to end up inside the target".
_SHOULD_BE = re.compile(r"^(?:and )?((?:the |my )?[a-z]+(?: (?!should|must|needs?|has|is|will|to|shall)[a-z]+)?(?: and (?:the |my )?[a-z]+)?) "
                        r"(?:should|must|needs? to|has to|is to|will|to|shall)? ?(?:still )?"
                        r"(?:end up|be|go|goes|sit|sits|stay|get|gets|belong|belongs|land|lands)(?: back)? "
                        r"(in|inside|into|on|onto|at|next to|beside|on top of|where) ")

#: "both back on table (after)": the two put back.
_BOTH_BACK = re.compile(r"^(?:and )?(?:then )?both(?: of them)?(?: (?:can |should |must )?go)?(?: back)?(?: down)?(?: on (?:the )?table)?"
                        r"(?: after(?:wards)?)?$")

#: An end state said with a participle: "the cup moved over to the right", "the capsule put in the tray".
_PARTICIPLE = re.compile(r"^(?:and )?((?:the )?[a-z]+(?: [a-z]+)?) (moved|put|placed|pushed|slid|shifted|set|laid|stacked|dropped) (?!back$)(.+)$")

#: "leave the bottle standing up afterwards": put it back.
_LEAVE_STANDING = re.compile(r"^(?:and )?(?:then )?leave (the \w+|it) (?:standing|upright|standing up|up)(?: (?:afterwards|after|after that|at the end))?$")

#: A step said without its verb: "red into cup", "blue next to the cup on the right".
_VERBLESS = re.compile(r"^(?:and )?(then )?((?:the |both |both the |the two )?[a-z]+(?: one)?) "
                       r"(into|inside|in|onto|on top of|next to|beside|to the (?:left|right) of|behind|in front of|where(?= the)) (.+)$")

#: "the tray sitting a little further from you" (the distance read as ``forward`` already): a move that way.
_SITTING_WAY = re.compile(r"^(?:and )?(then )?((?:the )?[a-z]+(?: [a-z]+)?) (?:(?:is|should be|to be|must be|ends? up|should end up) )?"
                          r"(?:sitting|standing|lying|resting|placed|set|moved|pushed|positioned) (forward|closer|left|right)$")


def _put_back(m: re.Match[str]) -> str:
    first = "put it back" if m[1] == "it" else "put them back" if m[1] in ("they", "them", "both") else f"put the {m[1]} back"
    return first if m[2] is None else f"{first} , put the {m[2]} back"


#: "both cup and bottle (upright) on the table": each put back.
_BOTH_ON_TABLE = re.compile(r"^(?:and )?(?:both )?(?:the )?(\w+) and (?:the )?(\w+)(?: both)?(?: back)? (?:on|onto) (?:the )?table$")
#: "... with the capsule (sitting) in it": the thing inside, in first.
_WITH_IN_IT = re.compile(r"^(.+?)(?: ,)? with (the [a-z]+(?: [a-z]+)?) (?:sitting |lying |resting |standing |placed |put )?(in|inside|on) (?:it|there)$")


#: A place said of "it", the host of a ``with`` phrase: "the fork on the left of it", "the cup next to it".
_OF_IT = (r"(?:on|to|at) the (?:left|right) of it|next to it|beside it|behind it|in front of it|in it|inside it|on it|on top of it")
#: "the plate with the fork on its left and the spoon on its right": each thing placed so, the host staying where it is.
_WITH_AROUND = re.compile(rf"^(the [a-z]+) with (the [a-z]+(?: [a-z]+)?) ({_OF_IT})(?:(?: ,)? and (the [a-z]+(?: [a-z]+)?) ({_OF_IT}))?$")


def _with_around(clause: str, objects: frozenset[str], note: Note) -> str:
    """``the plate with the fork on the left of it and the spoon on the right of it`` -> ``put the fork on the left of
    the plate , put the spoon on the right of the plate``."""
    m = _WITH_AROUND.match(clause)
    if m is None or m[1].split()[-1] not in objects:
        return clause
    note("end state")
    places = [(m[2], m[3]), *([(m[4], m[5])] if m[4] else [])]
    return " , ".join(f"put {thing} {re.sub(r'it$', m[1], place)}" for thing, place in places)


def _with_in_it(clause: str, objects: frozenset[str], note: Note) -> str:
    """``push the tray forward with the capsule in it`` -> ``put the capsule in the tray , push the tray forward``."""
    m = _WITH_IN_IT.match(clause)
    if m is None:
        return clause
    host = next((w for w in m[1].split() if w in objects), None)
    if host is None or host in m[2].split():
        return clause
    note("end state")
    then = "then " if m[1].startswith("then ") else ""
    return f"{then}put {m[2]} {m[3]} the {host} , {m[1].removeprefix('then ')}"


def read_end_state(clause: str, objects: frozenset[str], note: Note, verb: Callable[[str], str | None]) -> str:
    """One clause's end state or verbless step as the imperative that brings it about (see the module)."""
    clause = _with_around(clause, objects, note)
    clause = _with_in_it(clause, objects, note)
    if " , " in clause:  # two steps now: each read on its own
        return " , ".join(read_end_state(c, objects, note, verb) for c in clause.split(" , "))
    for pattern, repl in _WATER_IN:
        clause = sub(pattern, repl, clause, note, "end state")
    clause = sub(_BACK_AS_IT_WAS, _put_back, clause, note, "end state")
    clause = sub(_BOTH_ON_TABLE, r"put the \1 back , put the \2 back", clause, note, "end state")
    clause = sub(_LEAVE_STANDING, r"put \1 back", clause, note, "end state")
    clause = sub(_SITTING_WAY, lambda m: f"{m[1] or ''}move {m[2] if m[2].startswith('the ') else 'the ' + m[2]} {m[3]}", clause, note, "end state")
    verbless = _VERBLESS.match(clause)
    if verbless is not None and verb(verbless[2].split()[-1]) is None and verbless[2].split()[-1] not in ("it", "them", "they"):
        thing = verbless[2] if verbless[2].startswith(("the ", "both ")) else f"the {verbless[2]}"
        clause = f"{verbless[1] or ''}put {thing} {verbless[3]} {verbless[4]}"
        note("verb")
    participle = _PARTICIPLE.match(clause)
    if (participle is not None and verb(participle[2]) is not None
            and (participle[1].startswith("the ") or participle[1].split()[-1] in objects)):
        subject = participle[1] if participle[1].startswith("the ") else f"the {participle[1]}"
        clause = f"{verb(participle[2])} {subject} {participle[3].removeprefix('over ')}"
        note("end state")
    clause = sub(_SHOULD_BE, r"put \1 \2 ", clause, note, "end state")
    return sub(_BOTH_BACK, "put them back", clause, note, "end state")
