"""Telegraphic and learner's steps: verbs run together, a particle before its object, a verb made a noun.

Read a sentence at a time by :mod:`~agentchord.agents.rules.verbs` (first, before its frames), on normalised
text. People writing fast or in a second language leave out the words the grammar needs:

- **steps run together**: "pick up capsule put in tray", "take the fork place it beside the plate" -> a step
  per verb (``..., then put in tray``): a bare verb right after a noun, with words after it, starts a new step (never
  after an arm, a number, a pronoun or "you": "have the right arm put it", "the cup you lift", "the target place" are
  one step; "hand" is never read so, it is as often the noun);
- **a particle before its object**: "put back bottle standing", "set back the cup" -> ``put the bottle back``;
- **a verb made a noun**: "make pour to the cup", "do a pour into the cup", "make a fold" -> ``pour water into the
  cup``, ``fold``; "pour to the cup" -> ``pour water into the cup`` (a pour goes into, never to, a vessel);
- **a comparative said with "more"**: "bring more far", "a bit more close to you" -> ``further away``, ``closer``.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.rules.rewrite_steps import Note, sub

#: Verbs that open a step of their own when they follow a noun with nothing between (their base form only).
_STEP_VERBS = frozenset({"put", "place", "set", "drop", "pour", "fill", "take", "grab", "grasp", "lift", "hold", "give",
                         "pass", "move", "push", "carry", "bring", "stand", "fold", "stack", "slide", "shift"})
#: Words after which a verb is not a new step: arms, pronouns, "you", function words.
_NOT_A_STEP_END = frozenset("""
arm arms hand hands gripper grippers one ones it them you i we me us he she they both and then or to not don't do did
can could would will should must please let have make help just also first a an the your my its their this that
left right other after before once when while if so as then now again back up down over off out in on into onto at
with from by of for two three one some each every
""".split())
#: What a verb that starts a step is followed by: its object or its particle ("a proper place setting" is no step).
_STEP_GOES_ON = frozenset("""
the a an it them both this that your my in into inside on onto to up down back over next beside water
""".split())
_PARTICLE_FIRST = re.compile(r"\b(put|set|place|stand) back (?:the )?((?!it\b|them\b|down\b|up\b|on\b|in\b|to\b)[a-z]+)\b(?: (?:standing|upright|up))?")
_VERB_AS_NOUN = re.compile(r"\b(?:make|do|perform) (?:a |the )?(pour|fold|handover|hand-over)(?:ing)?\b")
_POUR_TO = re.compile(r"\bpour(?: water)? (?:to|towards|at) (?=the |it\b)")
#: A move said with its direction and no object: "take tray and bring forward" (the object taken).
_DIRECTION_LEFT_OUT = re.compile(r"(?:(?<= and )|(?<= then )|(?<= , ))(bring|move|carry|push|slide|shift|take) "
                                 r"(?=(?:it )?(?:forward|forwards|further away|farther away|back|backwards)\b)(?!it\b)")
_MORE = [(re.compile(r"\bmore (?:far|farther|further)(?: away)?\b"), "further away"),
         (re.compile(r"\bmore (?:close|near|closer|nearer)\b"), "closer")]


def _verb_since_boundary(words: list[str], verb: Callable[[str], str | None]) -> bool:
    """Whether the words since the clause began hold a verb: "pick up capsule put ..." is two steps, while "and the blue
    cube put it beside ..." is a topic said before its step (read by the verb frames)."""
    for word in reversed(words):
        if word in (",", ";", "and", "then"):
            return False
        if verb(word) is not None:
            return True
    return False


def _run_together(s: str, verb: Callable[[str], str | None]) -> str:
    words = s.split(" ")
    out: list[str] = []
    for k, word in enumerate(words):
        # A verb with no object or particle after it ("the target place", "a place setting") is a noun, not a step.
        if (k >= 2 and k + 1 < len(words) and words[k + 1] in _STEP_GOES_ON
                and word in _STEP_VERBS and verb(word) == word and words[k - 1].isalpha()
                and words[k - 1] not in _NOT_A_STEP_END and verb(words[k - 1]) is None
                and _verb_since_boundary(words[:k - 1], verb)):
            out.append(", then")
        out.append(word)
    return " ".join(out)


def read_telegraphic(s: str, note: Note, verb: Callable[[str], str | None]) -> str:
    """``s`` (one sentence) with its telegraphic steps in the grammar's words (see the module)."""
    s = sub(_VERB_AS_NOUN, lambda m: "hand it over" if m[1].startswith("hand") else m[1], s, note, "verb")
    s = sub(_POUR_TO, "pour water into ", s, note, "verb")
    s = sub(_PARTICLE_FIRST, r"\1 the \2 back", s, note, "particle")
    for pattern, repl in _MORE:
        s = sub(pattern, repl, s, note, "direction")
    s = sub(_DIRECTION_LEFT_OUT, r"\1 it ", s, note, "verb")
    split = _run_together(s, verb)
    if split != s:
        note("order")
    return split
