"""Self-corrections: the speaker takes back what they just said ("— no wait, the right one —", ", no, the red one",
"— sorry, I mean hold the cup —", "— actually, pick it up with the left first ...").

Read on the normalised text, before the sentences are read (:mod:`~agentchord.agents.rules.discourse`).
A correction marker (``no``, ``wait``, ``sorry``, ``actually``, ``i mean``, ``scratch that``, ``or rather``,
``make that``, in any run) after a separator, and what follows it up to the next dash or sentence end:

- a **clause** (it starts with a verb): it replaces the clause before the marker with the same verb, which is dropped
  (another verb may amend rather than replace it: refused)
  (a pronoun the new clause opens with is the dropped clause's object: "fold the towel left to right — no,
  fold it front to back");
- a **noun phrase**: it replaces the phrase of its kind in the clause before: an arm (``the right one``,
  ``the left hand``) the arm named there; a colour, size or side (``the red one``) the word of that kind
  in an object's phrase; an object noun (``the tray``) the one phrase with that head, or the only object
  phrase. A correction that fits nothing, or more than one phrase, is refused (:class:`NotAGoalError`),
  never guessed.

A restart after the correction ("use the left arm to pour — no wait, the right one — pour water ...")
says the verb again: it is said once.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.observe import COLOURS
from agentchord.agents.rules.rewrite_steps import Note, NotAGoalError

#: One word of a correction marker.
_MARK_WORD = r"(?:no|nope|wait|sorry|oops|actually|i mean|i meant|scratch that|or rather|rather|make that|correction|my bad|hold on)"
#: A correction: a marker run after a separator (a dash, a comma), then the new words up to the next dash or sentence end.
_CORRECTION = re.compile(rf"(?: ,| —| -)(?: ,)? (?:{_MARK_WORD}(?: ,)? )*{_MARK_WORD}(?: ,| —)? (?P<new>[^—;,]+?)(?P<end> —(?= |$)| ;| ,|$)")
#: A bare "no" is a correction only before a comma, another marker or a noun phrase ("no rush", "no water" are not).
_NO_BEFORE = re.compile(r"(?:the|your|a|an|left|right|it|them)\b")
#: Where the clause a correction takes back starts.
_CLAUSE_START = re.compile(r"(?:^| ; | , | then | and )")
#: An arm as a correction: "the right one", "left hand", "your right".
_ARM = re.compile(r"(?:the |your )?(left|right)(?: (?:one|arm|hand|gripper))?")
#: The arm a clause names.
_ARM_IN = re.compile(r"\b(left|right)(?= (?:arm|hand|gripper|one)\b)")
#: A noun phrase as a correction: "the red one", "the big block", "the tray".
_PHRASE = re.compile(r"(?:the |a |your )?(?:(?P<mod>[a-z]+) )?(?P<head>[a-z]+)")
_SIDES = frozenset({"left", "right"})
#: Size words (the references' own table is not imported here: it would import the parser this runs before).
_SIZES = frozenset("tall taller tallest short shorter shortest big bigger biggest large larger largest small smaller smallest "
                   "little tiny huge high low".split())


def _kind(word: str) -> str | None:
    """What kind of modifier ``word`` is (a colour, a size, a side), if any."""
    if word in COLOURS:
        return "colour"
    if word in _SIZES:
        return "size"
    return "side" if word in _SIDES else None


def _clause_before(text: str) -> tuple[str, str]:
    """``text`` split where its last clause starts: (what comes before it, the clause)."""
    starts = [m.end() for m in _CLAUSE_START.finditer(text)]
    cut = starts[-1] if starts else 0
    return text[:cut], text[cut:]


def _replace_phrase(clause: str, new: str, objects: frozenset[str]) -> str | None:
    """The clause with the phrase ``new`` corrects replaced by it, else None (it fits nothing, or more than one)."""
    arm = _ARM.fullmatch(new)
    arms = list(_ARM_IN.finditer(clause))
    if arm is not None and arms and (arm[0].endswith(("one", "arm", "hand", "gripper")) or not re.search(r"\b(?:left|right) (?!arm|hand|gripper|one)", clause)):
        last = arms[-1]
        return clause[: last.start()] + arm[1] + clause[last.end():]
    phrase = _PHRASE.fullmatch(new)
    if phrase is None:
        return None
    mod, head = phrase["mod"], phrase["head"]
    if head == "one" and mod is not None and (kind := _kind(mod)) is not None:
        # "the red one": the word of that kind in an object's phrase ("the blue block").
        found = [m for m in re.finditer(r"\b([a-z]+) ([a-z]+)\b", clause) if _kind(m[1]) == kind and m[2] in objects]
        if len(found) != 1:
            return None
        return clause[: found[0].start(1)] + mod + clause[found[0].end(1):]
    if head in objects:
        # "the tray": the phrase with that head, else the clause's only object phrase.
        heads = [m for m in re.finditer(r"\bthe (?:[a-z]+ )?([a-z]+)\b", clause) if m[1] in objects]
        same = [m for m in heads if m[1] == head]
        target = same if same else heads
        if len(target) != 1:
            return None
        return clause[: target[0].start()] + f"the {mod + ' ' if mod else ''}{head}" + clause[target[0].end():]
    return None


def read_corrections(text: str, objects: frozenset[str], verb: Callable[[str], str | None], note: Note) -> str:
    """``text`` with each self-correction applied (see the module docstring).

    Args:
        text: The normalised instruction.
        objects: The words naming scene objects.
        verb: The rules' verb a word is a form of, else None.
        note: Records the step's name (``correction``) for ``plan --explain``.

    Raises:
        NotAGoalError: A correction that replaces nothing said before it, or could replace several things.
    """
    pos = 0
    while (m := _CORRECTION.search(text, pos)) is not None:
        marker = text[m.start(): m.start("new")]
        new = m["new"].strip(" ,")
        before, clause = _clause_before(text[: m.start()])
        if re.fullmatch(r"(?: ,| —| -)(?: ,)? no ", marker) and not _NO_BEFORE.match(new) \
                or not set(clause.split()) & (objects | _SIDES | {"it", "them"}):
            # "no rush"; "hello, sorry for bothering you", "hmm, actually let's ...": nothing said before to take back.
            pos = m.end("new")
            continue
        rest = text[m.end("new"):]
        words = new.split()
        if words and verb(words[0]) is not None:
            # A clause: the one before is taken back, where it has the same verb ("hold the bottle — sorry, I mean hold
            # the cup"); another verb may amend it rather than replace it ("put it on the target — actually, pick it up
            # with the left first and hand it across"): refused, not guessed.
            said = clause.split()
            if not said or verb(said[0]) != verb(words[0]):
                raise NotAGoalError(f"'{new}' corrects '{clause.strip()}', but it is unclear whether it replaces it or adds to it")
            # The clause's object is what an opening pronoun of the new one means.
            obj = re.search(r"^\S+(?: up)? (the (?:[a-z]+ )?[a-z]+)\b", clause.strip())
            if obj is not None and obj[1].split()[-1] in objects:
                new = re.sub(r"^(\S+) (?:it|them)\b", rf"\1 {obj[1]}", new)
            fixed = before + new
        else:
            replaced = _replace_phrase(clause, new, objects)
            if replaced is None:
                raise NotAGoalError(f"'{new}' corrects something said before it, but not one thing it could replace")
            fixed = before + replaced
        rest = re.sub(r"^ —(?: |$)", " ", rest)
        last = fixed.split()[-1] if fixed.split() else ""
        if last and rest.split() and rest.split()[0] == last:
            fixed = fixed[: fixed.rfind(last)].rstrip()  # "to pour — ... — pour water": the verb said again, once
        text = re.sub(r"\s+", " ", f"{fixed} {rest}").strip()
        pos = len(fixed)
        note("correction")
    return text
