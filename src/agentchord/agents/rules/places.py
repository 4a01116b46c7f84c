"""Where things go and which way: the place and direction phrases people write, in the grammar's words.

Read a sentence at a time by :mod:`~agentchord.agents.rules.discourse`, on normalised text (clauses
separated by `` , ``). People say where an object goes relative to themselves ("further away from
you", "a bit closer to me"), as a direction where the grammar expects a place ("put it down a little
further away"), and with words around the place that only say how much or why ("over a bit to the
right", "so it's right next to the plate", "to the left side, near the fork"). Each rule maps a kind
of such phrasing to the one place or direction it means:

- **towards and away from the robot**: "further (away) (from you)", "farther back", "more far",
  "towards the back" -> ``forward``; "closer to you", "towards me" -> ``closer`` (the front);
- **a direction as the destination**: "put it (back) (down) further away" -> ``move it forward``
  (a put with no place but a way is a move that way); "forward, to the forward spot" and "forward to
  the spot" are the one place (the scene region the direction names is chosen at grounding);
- **how far, not where**: "a bit", "a little", "slightly", "way" before a direction are dropped (a
  nudge is the rules' nudge; a region is where it is);
- **next to**: "near (to) X", "close to X", "a bit closer to X" -> ``next to X``; "next to X on the
  right" -> ``to the right of X``; "to the left (side), near X" and "to the left so it's beside X"
  -> ``next to X`` (the way there is not the side it ends on);
- **back where it was**: "where you found them", "where you got it from" -> ``where they were``;
- **a learner's prepositions**: "next of X" -> ``next to X``; "beside of", "inside of", "into of" -> the preposition;
  "the target place" -> the target; "the far right (side)" -> the right side (the far right corner stays the back one);
- **a place said again** alone after the step ("..., like right beside it", "..., just beside"): no
  step of its own (:func:`restates`);
- **what a move is for is where it goes**: "so it's (lying) right next to the plate" -> ``next to
  the plate``.
"""

from __future__ import annotations

import re

from agentchord.agents.rules.rewrite_steps import Note, sub

#: Verbs that move an object some way.
_MOVES = r"(?:move|slide|shift|push|nudge|bring|carry|drag|scoot)"
#: How far, said before a direction or a place: dropped (the rules' nudge, or the place itself).
_HOW_FAR = (r"(?:(?:a (?:little |tiny |wee )?bit|a little|slightly|somewhat|way|just|a tad|a touch|"
            r"(?:about |roughly |around )?(?:a few|a couple of|\d+|one|two|three|five|ten) ?(?:cm|centimet(?:er|re)s|inch(?:es)?|mm))(?: more)? )")
#: Words that start an amount (never the last word of the object before it: "carry the tray about ten cm forward").
_AMOUNT_WORD = r"(?:about|roughly|around|a|just|slightly|way|one|two|three|five|ten|\d+)\b"
#: Direction phrases that mean "away from the robot".
_AWAY = re.compile(rf"\b{_HOW_FAR}?(?:further|farther|more far)(?: away| out)?(?: back)?(?: from (?:me|you|the robot))?"
                   r"(?: than (?:it is|it does|it was|they are)(?: now| right now| at the moment)?)?\b|\baway from (?:me|you|the robot)\b|"
                   r"\btowards? the (?:back|far side|far end)\b|\bto the back\b(?! of the table| edge| of the)")
#: "a little closer to you", "towards the robot": the robot's side of the table.
_TOWARD_YOU = re.compile(rf"\b{_HOW_FAR}?(?:closer|nearer) (?:to|towards?) (?:you|me|the robot|yourself)\b|"
                         r"\btowards? (?:you|me|the robot|yourself)\b")
#: "back a little , forward" (back, then said again as away from the robot): the one direction.
_BACK_THEN_AWAY = re.compile(rf"\bback (?:{_HOW_FAR}|a little |a bit )?(?:, )?forward\b")
#: "pushed back a little, still centred": the side it stays on is where it is (how, not a place).
_STILL_CENTRED = re.compile(r"(?: ,)? (?:and )?(?:still|staying|kept|keeping it) (?:centred|centered|in the (?:middle|centre|center))(?= ,|$)")
#: "forward on the table than it is now": the comparison and the table add nothing to the direction.
_THAN_NOW = re.compile(r"\b(forward|closer)(?: on the table)?(?: than (?:it is|it was|they are)(?: now)?)?(?= ,|$| then\b| and\b| with\b)")
#: "so it's (lying) right next to the plate": what the move is for is where it goes.
_SO_IT = re.compile(r"(?: ,)? so (?:that )?(?:it|they)(?:'s|'re| is| are| ends? up| sits?| lies| lie)?(?: (?:lying|sitting|standing))?"
                    r"(?: (?:right|just|directly))? (?=(?:next to|beside|near|in|inside|into|on|onto|at|to the|behind|in front of)\b)")
#: "next to the plate on the right": on that side of it (not the table's right side).
_BESIDE_ON_SIDE = re.compile(r"\b(?:right |just )?(?:next to|beside|by|near|near to|close to) ((?:the )?[a-z]+(?: [a-z]+)?)(?: ,)? "
                             r"(?:on|to|at) (?:the|its) (left|right)"
                             r"(?: side| hand side)?(?: of it)?(?= ,|$| then\b| and\b| with\b)")
#: "a bit to the left (side), so it's beside the cup", "over to the left side, near the fork": beside it (the way there
#: is not the side: coming from its right, the bottle ends on the cup's right).
_SIDE_BESIDE = re.compile(rf"\b{_HOW_FAR}?(?:over )?to the (left|right)(?: side)?(?: ,)? (?:so )?(?:right |just )?"
                          r"(?:beside|next to|by|near to|near|close to) "
                          r"(the [a-z]+(?: [a-z]+)?)(?= ,|$| then\b| and\b| with\b)")
#: "near to the fork", "close to it": next to it.
_NEAR_TO = re.compile(r"\b(?:near|close)(?: to)? (?=the |it\b|them\b)")
#: "a bit closer to the bottle": next to it.
_CLOSER = re.compile(rf"\b{_HOW_FAR}?(?:closer|nearer) to\b")
#: "move the cup over a bit to the right", "slide it a little forward": how far a move goes (the rules' nudge).
_HOW_FAR_BEFORE = re.compile(rf"\b({_MOVES} (?:it|them|the [a-z]+(?: (?!{_AMOUNT_WORD})[a-z]+)?))(?: over)? {_HOW_FAR}(?:over )?"
                             r"(?=(?:to the (?:left|right)|forward|closer|left|right)\b)")
#: "the cup goes a bit more to the left": said as a state, how far makes it a move that way (not the table's left side).
_GOES_A_BIT = re.compile(rf"^(?:and )?(?:then )?((?:the )?[a-z]+(?: [a-z]+)?) (?:goes|should go|needs to go|moves|should move|should be) "
                         rf"(?:over )?{_HOW_FAR}(?:over )?(?:to the )?(left|right|forward|closer)$")
#: "put it (back) (down) forward": a put with a way and no place is a move that way.
_PUT_A_WAY = re.compile(r"\b(?:put|set|place|lay|stand|drop) (it|them|the [a-z]+(?: [a-z]+)?) (?:back )?(?:down )?(forward|closer)"
                        r"(?= ,|$| then\b| and\b| with\b)")
#: "put it back where it was, a bit to the right": how far makes it a nudge that way (without it, the table's right side).
_PUT_A_BIT = re.compile(rf"\b(?:put|set|place|lay|stand|drop) (it|them|the [a-z]+(?: [a-z]+)?) (?:back )?(?:down )?"
                        rf"(?:where (?:it|they) (?:was|were) )?(?:, )?{_HOW_FAR}(?:over )?(?:to the )?(left|right)(?= ,|$| then\b| and\b| with\b)")
#: "forward, to the forward spot", "forward to the spot": the one place the direction names.
_FORWARD_TO_SPOT = re.compile(r"\bforward(?: ,)? (?:to|into|onto|in|at) the (?:(forward) )?(region|spot|position|area|place|zone|mark)\b")


#: A place said again, alone, to insist: "like right beside it", "just beside", "i mean next to it".
_RESTATED = re.compile(r"(?:and )?(?:(?:like|i mean|that is|so) )*(?:(?:right|just|directly|really) )*(?:beside|next to|by|near|close to)"
                       r"(?: (?:it|them|the [a-z]+))?")
_BESIDE = re.compile(r"\b(?:next to|beside|by|near|to the (?:left|right) of)\b")


#: "where you found them", "where you got it from": where they were.
_WHERE_FOUND = re.compile(r"\bwhere (?:you|i|we) (?:found|got|took|picked up|picked) (it|them)(?: from| up)?\b")


#: "right next to", "just behind", "directly in front of": how exactly, not which side ("right" is no side here:
#: it is not "the right", "to the right", "your right", and a place follows it).
_EXACTLY = re.compile(r"(?<!the )(?<!to )(?<!your )(?<!its )(?<!on )\b(?:right|directly|exactly|immediately|just|squarely) "
                      r"(?=(?:next to|beside|behind|in front of|on top of|between|by|near|against|into|inside|onto|over|under|"
                      r"where|back (?:where|in|on|to))\b)")
#: "side by side to the left of the cup", "next to each other in front of it": a row at that place (read at grounding).
_ROW = re.compile(r"\b(?:side by side|next to each other|beside each other|alongside each other|in a row|together) "
                  r"(?=(?:on|to|at|in front of|behind|left of|right of)\b)")
#: "beside the target , not on it": the place said, then what it is not (no other place).
_NOT_ON = re.compile(r"(\b(?:next to|beside|by|near|to the (?:left|right) of|in front of|behind) [a-z ]+?)"
                     r"(?: ,)? (?:but )?not (?:on|in|inside|into|onto|on top of) (?:it|them|the [a-z]+)(?= ,|$| then\b| and\b)")
#: "in there", "on there": the place last said (what a container or support was last named as).
_THERE = re.compile(r"\b(in|into|inside|on|onto) there\b")
_HOSTS = re.compile(r"\b(?:in|into|inside|on|onto|on top of) (the [a-z]+(?: (?!with\b|then\b|and\b|too\b|there\b)[a-z]+)?)\b")
#: "... in there too", "... as well": the step is said whole, so the word adds nothing.
_TOO_AFTER_PLACE = re.compile(r"(\b(?:in|into|inside|on|onto|on top of) the [a-z]+(?: [a-z]+)?)(?: ,)? (?:too|as well|also)(?= ,|$| then\b)")


def there_is_last_place(sentences: list[str], note: Note) -> list[str]:
    """``put the blue block in the cup ; put the red block in there too`` -> ``... put the red block in the cup``:
    ``there`` after a preposition is the container or support named last, in this sentence or an earlier one."""
    out: list[str] = []
    for sentence in sentences:
        while (m := _THERE.search(sentence)) is not None:
            hosts = _HOSTS.findall(" ; ".join([*out, sentence[: m.start()]]))
            if not hosts:
                break
            sentence = f"{sentence[: m.start()]}{m[1]} {hosts[-1]}{sentence[m.end():]}"
            sentence = sub(_TOO_AFTER_PLACE, r"\1", sentence, note, "place")
            note("place")
        out.append(sentence)
    return out


def restates(clause: str, before: str) -> bool:
    """Whether ``clause`` only says again that the step ``before`` it puts something beside something."""
    return _RESTATED.fullmatch(clause.strip()) is not None and _BESIDE.search(before) is not None


#: Prepositions as a learner says them: "next of", "beside of", "inside of", "near of" (the ``of`` doubled with
#: a preposition that takes none, or takes ``to``).
_LEARNER_PREP = [(re.compile(r"\bnext of\b"), "next to"), (re.compile(r"\b(beside|inside|near|behind|onto|into) of\b"), r"\1"),
                 (re.compile(r"\bin the front of\b"), "in front of")]
#: "the far right side", "the far left": the extreme of that side, not the back ("far" alone is the far edge; "the far
#: right corner" stays the back corner).
_FAR_SIDE = re.compile(r"\b(?:far|very|extreme|outer) (left|right)(?! corner)\b")
#: "the target place", "the target position": the scene's target region, a generic place noun after its name.
_NAMED_PLACE = re.compile(r"\b(the (?:target|marked|goal)) (?:place|position|location)\b")


def read_places(s: str, note: Note) -> str:
    """``s`` (one sentence) with its place and direction phrases in the grammar's words (see the module)."""
    for pattern, repl in _LEARNER_PREP:
        s = sub(pattern, repl, s, note, "place")
    s = sub(_NAMED_PLACE, r"\1", s, note, "place")
    s = sub(_FAR_SIDE, r"\1", s, note, "place")
    s = sub(_EXACTLY, "", s, note, "place")
    s = sub(_ROW, "", s, note, "place")
    s = sub(_NOT_ON, r"\1", s, note, "place")
    s = sub(_TOO_AFTER_PLACE, r"\1", s, note, "place")
    s = sub(_AWAY, "forward", s, note, "direction")
    s = sub(re.compile(r"\bforward(?: ,)? forwards?\b"), "forward", s, note, "direction")  # "a bit further forward": one way
    s = sub(_TOWARD_YOU, "closer", s, note, "direction")
    s = sub(_BACK_THEN_AWAY, "forward", s, note, "direction")
    s = sub(_STILL_CENTRED, "", s, note, "how")
    s = sub(_THAN_NOW, r"\1", s, note, "direction")
    s = sub(_CLOSER, "next to", s, note, "direction")
    s = sub(_SO_IT, " ", s, note, "place")
    s = sub(_BESIDE_ON_SIDE, r"to the \2 of \1", s, note, "place")
    s = sub(_SIDE_BESIDE, r"next to \2", s, note, "place")
    s = sub(_NEAR_TO, "next to ", s, note, "place")
    s = sub(_HOW_FAR_BEFORE, r"\1 ", s, note, "amount")
    s = " , ".join(sub(_GOES_A_BIT, lambda m: f"move {_the(m[1])} {m[2]}", c, note, "direction") for c in s.split(" , "))
    s = sub(_PUT_A_WAY, r"move \1 \2", s, note, "direction")
    s = sub(_PUT_A_BIT, r"move \1 \2", s, note, "direction")
    s = sub(_FORWARD_TO_SPOT, lambda m: f"to the forward {m[2]}" if m[1] else f"forward to the {m[2]}", s, note, "direction")
    s = sub(re.compile(r"\bforward(?: ,)? (to the \w+ region)\b"), r"\1", s, note, "direction")
    s = sub(_WHERE_FOUND, lambda m: "where it was" if m[1] == "it" else "where they were", s, note, "place")
    return sub(re.compile(r"\bto (inside|into|onto)\b"), r"\1", s, note, "place")


def _the(np: str) -> str:
    return np if np.startswith("the ") else f"the {np}"
