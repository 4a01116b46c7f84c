"""How a step's verb is said: frames around the grammar's verbs that people use and the grammar lacks.

Read a sentence at a time by :mod:`~agentchord.agents.rules.discourse`, on normalised text, before the
arms and places are read. Each rule maps a kind of verb frame to the imperative it means:

- **a subject "you"** (or an arm said as "it", "they"): "you take the bottle", "with the left hand you hold the cup",
  "then it passes it to the right arm" -> the imperative
  (only where a clause starts, after ``and`` or after an arm: "after you put" keeps its meaning of order);
- **"let's"**: "let's put ..." -> ``put ...``;
- **causatives**: "make water go in the cup", "get some water into the cup" -> ``pour water into the
  cup``; "make the block end up in the cup" -> ``put the block in the cup``;
- **the receiver before the thing**: "pour it some water", "pour the cup a little water", "give the cup a
  splash of water" -> ``pour water into it`` (water given is poured, never a hand-over of the cup);
- **the object left out**: "place in the target area", "drop into the cup" -> ``place it in ...`` (the
  object in hand); a bare "lift" or "pick up" after the object was taken says nothing and is dropped;
- **amounts of a pour**: "tip some of it into the cup", "pour a little into the cup", "a splash of water into
  the cup" -> ``pour water into the cup`` (a vague amount is a pour; a fraction is not read, and is refused);
- **a pour said by its motion**: "tip the bottle over the cup so some water goes in" -> ``pour the bottle into the
  cup``; a bare "... and pour" pours into the vessel in hand (chosen at grounding);
- **particles**: "drop it off in the cup" -> ``drop it in the cup``;
- **a topic said first**: "the blue cube, put it beside the red one", "and the bottle pour it into the cup" -> the
  verb with the topic in the pronoun's place (never an arm: "and the right hand put it in the tray");
- **phrasal verbs of arranging**: "line them up beside the plate" -> ``put them beside the plate``;
  "tidy up the cutlery so it's laid out around the plate" -> ``arrange the cutlery around the plate``
  (tidying with a place said is arranging there; with none it is refused);
- **swapping**: "swap the bottle and the cup" -> each put where the other was (:func:`read_swap`); where the
  sentence goes on to say where each goes, that is read instead;
- **bringing together to pour**: "bring them together over the table and pour" -> ``pour`` (both in hand);
- **turning to point away**: "turn them so they point away from you" -> nothing (a utensil beside a
  plate is laid pointing away anyway).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.rules.rewrite_steps import Note, sub
from agentchord.agents.rules.telegraphic import read_telegraphic

#: "you" as the subject of a clause's verb (not after "after", "before", "once", "while", "if", "when").
_YOU = re.compile(r"(^|, |\band |\bthen |\b(?:arm|hand|gripper) (?:, )?)(?:you|u) (\w+)\b")
#: "then it passes it to the right arm": "it" the arm said before, as the subject of a verb with its own object.
_IT_DOES = re.compile(r"(^|, |\band |\bthen )(?:it|they) (\w+)\b(?= (?:it|them|the|both)\b)")
_LETS = re.compile(r"(?:^|(?<= , )|(?<=\band )|(?<=\bthen ))(?:actually |just |so )*let(?:'s| us)? (?=(\w+)\b)")
_CAUSE_WATER = re.compile(r"\b(?:make|get|let) (?:some |a little |the )?water (?:go |flow |run |get )?(?:in|into|inside) ")
_CAUSE_PUT = re.compile(r"\b(?:make|get) (the [a-z]+(?: [a-z]+)?|it|them) (?:to )?(?:go|end up|get|sit|land) (?=(?:in|into|inside|on|onto|next to|beside)\b)")
_POUR_DATIVE = re.compile(r"\bpour (it|them|the [a-z]+(?: [a-z]+)?) (?:some |a little |a bit of |a splash of )?(?:water|of water)\b")
_OBJECT_LEFT_OUT = re.compile(r"(?:^|(?<= , )|(?<=\band )|(?<=\bthen ))(put|place|set|drop|lay|insert|stand|deposit) "
                              r"(?=(?:in|into|inside|on|onto|next to|beside|in front of|behind) )")
_BARE_PICK = re.compile(r"(?:^|(?<= , ))(?:and )?(?:then )?(?:lift|raise|pick up|pick|grab|grasp|take|lift up)(?: up)?(?= ,|$)")
_LINE_UP = re.compile(r"\bline (it|them|the [a-z]+(?: (?!up\b|and\b)[a-z]+)?(?: and (?:the )?[a-z]+(?: (?!up\b)[a-z]+)?)?)"
                      r"(?: both| all)? up (?=(?:beside|next to|by|along|alongside|near|around|on|to)\b)|"
                      r"\bline up (?=the |them\b|both\b)")
_TIDY = re.compile(r"\b(?:tidy|tidy up|straighten|straighten up|sort out|organi[sz]e|neaten) (the [a-z]+(?: and (?:the )?[a-z]+)?|them|it)"
                   r"(?: so (?:that )?(?:it|they)(?:'s|'re| is| are)?)? (?:(?:laid out|lying|arranged|placed|set out|sitting|set|laid)"
                   r"(?: properly| neatly| nicely)? )?(?=(?:around|beside|next to|by|on either side of|on each side of)\b)")
#: "drop it off in the cup": the particle adds nothing to where it goes.
_OFF = re.compile(r"\b(drop|put|set|leave|place) (it|them|the [a-z]+(?: [a-z]+)?) off (?=(?:in|into|inside|on|onto|at|by|next to|beside)\b)")
#: "give the cup a splash of water": a pour into it (never a hand-over of the cup).
_GIVE_WATER = re.compile(r"\b(?:give|hand|pass|offer) (it|them|the [a-z]+(?: (?!a\b|some\b|water\b)[a-z]+)?) (?:(?:a (?:little|splash|drop|bit|dash|touch)"
                         r"(?: bit)?(?: of)?|some|a little bit of|more|a bit of) )?water\b|"
                         # "give the cup a drink (from the bottle)": a drink given to a vessel is water poured into it.
                         r"\b(?:give|offer) (the [a-z]+(?: (?!a\b|some\b)[a-z]+)?) (?:a |some )?(?:little )?(?:drink|fill|top-up|refill)\b")
#: "hand it off", "pass the block off": a hand-over (to the other arm).
_HAND_OFF = re.compile(r"\b(hand|pass) (it|them|the [a-z]+(?: [a-z]+)?) off\b(?! to\b)")
#: "tip some of it into the cup", "pour a little into the cup": a vague amount is a pour (the goal has no amount; a
#: fraction, "half of it", is not read here and is refused).
_SOME_OF_IT = re.compile(r"\b(pour|tip|empty|decant) (?:just |only )?(?:some|a little|a bit|a splash|a drop|a dash|a touch)(?: more)?"
                         r"(?: of (?:it|the water|its water|its contents|water))? (?=(?:into|in|from|out)\b)")
#: "a splash of water into the cup", "some water in the cup, please": a pour said without its verb.
_WATER_INTO = re.compile(r"(?:^|(?<= , ))(?:and )?(?:then )?(?:just )?(?:a (?:little|splash|drop|bit|dash|touch)(?: of)?|some) water (?=(?:into|in)\b)")
#: "tip the bottle over the cup (so some water goes in)": a pour from one into the other.
_TIP_OVER = re.compile(r"\b(?:tip|tilt|pour|hold) (the [a-z]+|it) over (the [a-z]+|it)(?: (?:so|until) (?:that )?(?:some |the )?(?:water|it) "
                       r"(?:goes|runs|pours|flows|gets|comes out and goes) in(?:to it|side)?)?(?= ,|$| then\b| and\b| with\b)")
#: "place it on the blue block so they're stacked": what the step is for, said again.
_SO_DONE = re.compile(r"(?: ,)? so (?:that )?(?:they|it)(?:'re|'s| are| is| end up| ends up) (?:stacked|on top|inside|in there|together|folded|"
                      r"side by side|next to each other|in place)$")
#: "pour into the cup with the bottle": the vessel a pour is done with is what it pours from.
_POUR_WITH = re.compile(r"\b(pour(?: water)?(?: (?:into|in) (?:the [a-z]+|it))?) (?:with|using) (the (?:bottle|jug|pitcher|kettle|carafe|flask))\b")
#: "..., right arm": an arm said after the step.
_ARM_AFTER = re.compile(r" , (?:the |your )?(left|right) (?:arm|hand|gripper)(?= ,|$| then\b)")
#: "bring them together (over the table) and pour": how a pour is done, with both in hand.
_BRING_TO_POUR = re.compile(r"\bbring (?:them|both|the two)(?: together)?(?: (?:over|above) the table| in the air| in front of you)?(?: ,)? and (?=pour\b)")
_TURN_AWAY = re.compile(r"(?:^|(?<= , ))(?:and )?(?:then )?(?:turn|rotate|orient|twist|spin) (?:them|it|both|them both|the [a-z]+(?: [a-z]+)?)"
                        r"(?: both| around| round)? (?:so (?:that )?(?:they|it)(?: both)? (?:point|face|are pointing|are facing|points|faces)|"
                        r"to (?:point|face)|(?:pointing|facing)) (?:away(?: from (?:me|you|the robot))?|forwards?|ahead|straight ahead)(?= ,|$)")


#: "swap the bottle and the cup (around) (so the cup ends up where ...)": each where the other was.
_SWAP = re.compile(r"^(?:(?:would you mind|could you|can you|please|mind) )*(?:swap|swapping|switch|switching|exchange|exchanging|trade|trading) "
                   r"(?:the (?:places?|positions?|spots?) of |where )?(the [a-z]+(?: (?!and\b|around\b|round\b)[a-z]+)?|them)"
                   r"(?: and (the [a-z]+(?: (?!around\b|round\b|over\b|so\b|are\b|is\b)[a-z]+)?))?(?: (?:around|round|over))?"
                   r"(?: (?:places|positions|are|is))?(?:(?: ,)? (?:so(?: that)?|,) (.+))?$")


#: "give water in the cup", "add some water to the mug", "put water from the bottle into the cup": water is what moves,
#: the cup where it goes: a pour (the verb of giving or putting says nothing else here).
_WATER_TO = re.compile(r"\b(?:give|add|put|get|bring|serve|provide|transfer|move) (?:some |a little |a bit of |a splash of |more |a little bit of )?"
                       r"water(?: from (the [a-z]+))? (?:into|in|to|inside)\b")
#: "pour me a little water", "could you get us some water into the cup": who it is for is no part of the goal.
_FOR_ME = re.compile(r"\b(pour|fill|get|fetch|make) (?:me|us|him|her|yourself|myself) (?=(?:a |an |some |water\b|the |just ))")
#: "a splash in the cup", "a little into the mug" (a pour said before): the amount poured, and where.
_AMOUNT_INTO = re.compile(r"(?:^|(?<= , ))(?:and )?(?:then )?(?:just |only )?(?:a (?:little|splash|drop|bit|dash|touch|little bit)|some)"
                          r"(?: more)? (?=(?:into|in)\b)")


def read_swap(s: str, note: Note) -> str:
    """``swap the X and the Y`` -> ``put the X where the Y was , put the Y where the X was``; where the sentence goes on
    to say where each goes ("so the cup ends up where ...", "- I want the fork on the right ..."), that is read instead."""
    m = _SWAP.match(s)
    if m is None:
        return s
    if m[3]:
        note("verb")
        return m[3]
    if m[2] is None:
        return s
    note("verb")
    return f"put {m[1]} where {m[2]} was , put {m[2]} where {m[1]} was"


#: A topic said first and taken up by a pronoun: "the blue cube, put it beside the red one", "and the bottle pour it
#: into the cup" -> the verb, then the topic in the pronoun's place.
_TOPIC_FIRST = re.compile(r"(?:^|(?<= , )|(?<=\band ))((?:the |that |this )[a-z]+(?: [a-z]+)?)(?: ,)? ([a-z]+) (?:it|them)\b(?! (?:and|with)\b)")


def _topic_first(m: re.Match[str], verb: Callable[[str], str | None]) -> str:
    said = verb(m[2])
    return m[0] if said is None or m[1].split()[-1] in ("arm", "hand", "gripper", "one") else f"{said} {m[1]}"


def read_verbs(s: str, note: Note, verb: Callable[[str], str | None]) -> str:
    """``s`` (one sentence) with its verb frames as the grammar's imperatives (see the module)."""
    s = read_telegraphic(s, note, verb)
    s = sub(_TOPIC_FIRST, lambda m: _topic_first(m, verb), s, note, "verb")
    s = sub(_TURN_AWAY, "", s, note, "how")
    s = sub(_BRING_TO_POUR, "", s, note, "how")
    s = sub(_GIVE_WATER, lambda m: f"pour water into {m[1] or m[2]}", s, note, "verb")
    s = sub(_OFF, r"\1 \2 ", s, note, "particle")
    s = sub(_HAND_OFF, r"\1 \2 over", s, note, "particle")
    s = sub(_SO_DONE, "", s, note, "how")
    s = sub(_POUR_WITH, r"\1 from \2", s, note, "verb")
    s = sub(_ARM_AFTER, r" with the \1 arm", s, note, "arm")
    s = sub(_TIP_OVER, r"pour \1 into \2", s, note, "verb")
    s = sub(_SOME_OF_IT, r"\1 water ", s, note, "amount")
    s = sub(_WATER_INTO, "pour water ", s, note, "amount")
    s = sub(_WATER_TO, lambda m: f"pour water {'from ' + m[1] + ' ' if m[1] else ''}into", s, note, "verb")
    s = sub(_FOR_ME, r"\1 ", s, note, "verb")
    if re.search(r"\b(?:pour|water)\b", s):
        s = sub(_AMOUNT_INTO, "pour water ", s, note, "amount")
    s = sub(_YOU, lambda m: m[0] if verb(m[2]) is None else m[1] + m[2], s, note, "verb")
    s = sub(_IT_DOES, lambda m: m[0] if verb(m[2]) is None else m[1] + m[2], s, note, "verb")
    s = sub(_LETS, lambda m: "" if verb(m[1]) is not None else m[0], s, note, "verb")
    s = sub(_CAUSE_WATER, "pour water into ", s, note, "verb")
    s = sub(_CAUSE_PUT, r"put \1 ", s, note, "verb")
    s = sub(_POUR_DATIVE, r"pour water into \1", s, note, "verb")
    s = sub(_OBJECT_LEFT_OUT, r"\1 it ", s, note, "verb")
    if re.search(r"\b(?:pick|take|grab|grasp|hold|lift)\w* (?:up )?\w", s):  # taken already: a bare "lift" adds nothing
        s = sub(_BARE_PICK, "", s, note, "how")
    s = sub(_LINE_UP, lambda m: f"put {m[1]} " if m[1] else "put ", s, note, "verb")
    return sub(_TIDY, r"arrange \1 ", s, note, "verb")
