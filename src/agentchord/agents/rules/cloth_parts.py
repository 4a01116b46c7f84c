"""A cloth said by its parts: which corners, edges and halves people name, and the one fold the rules make.

Read a sentence at a time by :mod:`~agentchord.agents.rules.discourse`. The rules fold a cloth in half
near edge onto far edge (the towel's bottom corners onto its top corners). People name the parts
from where they stand: near/front/closer corners are the bottom ones, far/back the top ones
(:data:`_CLOTH_PARTS`); a sentence bringing the bottom corners (edge, half) onto the top ones is the
fold (:func:`read_cloth_parts`); which way the fold goes, said of that fold ("toward the back",
"front to back"), adds nothing (:func:`drop_fold_way`); a fold across the cloth (left onto right) is
refused with the reason (:func:`refuse_fold_across`), not read as the fold the rules know.
"""

from __future__ import annotations

import re

from agentchord.agents.rules.rewrite_steps import Note, NotAGoalError, drop, sub

#: What a sentence that folds by parts reads as.
FOLD = "fold the towel"


#: A fold across the cloth (left onto right), which no rule makes.
_ACROSS = re.compile(r"\b(?:from )?(?:the )?(?:left|right)(?: half| side| edge| corners?)?(?: of it)? (?:to|onto|over|over to|on top of|towards?) "
                     r"(?:the )?(?:right|left)(?: half| side| edge| corners?)?\b|\bside to side\b|\blengthwise\b|\bsideways\b|\bleft-right\b")
#: Which way a fold goes, said of the only fold the rules make (near edge onto far edge).
_FOLD_WAY = re.compile(r"(?:^|(?: ,)? )(?:towards? |to )(?:the )?(?:top|far|back) (?:side|edge|end|half)(?= ,|$)|(?: ,)? forward(?= ,|$)|"
                       r"(?:^|(?: ,)? )(?:from )?(?:near|front|bottom)(?: edge| side)?(?: to| onto| over)? (?:far|back|top)(?: edge| side)?(?= ,|$)")
#: A cloth's parts, as the rules name them (bottom = near the robot, top = far).
_CLOTH_PARTS = [
    (re.compile(r"\b(?:the )?(?:two )?corners?(?: of (?:the (?:towel|cloth|napkin)|it))? (?:closest|nearest|nearer|closer) to (?:you|me|the robot)\b"),
     "the bottom corners"),
    (re.compile(r"\b(?:the )?(?:two )?corners?(?: of (?:the (?:towel|cloth|napkin)|it))? (?:farthest|furthest) (?:from|away from) (?:you|me|the robot)\b"),
     "the top corners"),
    # "bring them over to the other side": of a cloth whose near part is moved, the far side.
    (re.compile(r"\b(?:to|onto|over to|across to) the (?:other|opposite) (side|edge|end)\b"), r"onto the top \1"),
    (re.compile(r"\b(?:the )?(?:two )?(?:far|farthest|furthest) ones\b"), "the top corners"),
    (re.compile(r"\b(?:near|front|bottom)[- ](left|right) corner\b"), r"bottom \1 corner"),
    (re.compile(r"\b(?:far|back|top)[- ](left|right) corner\b"), r"top \1 corner"),
    (re.compile(r"\b(?:front|near|nearer|closer) (corners|edge|side|half|end)\b"), r"bottom \1"),
    (re.compile(r"\b(?:back|far|farther|further) (corners|edge|side|half|end)\b"), r"top \1"),
]
#: A cloth's edge said from where the robot stands (not the folded edge, which says which way it is folded).
_EDGE_FROM_YOU = [
    (re.compile(r"\b(?:the )?(edge|side|half|end) (?:closest|nearest|nearer|closer) to (?:you|me|the robot)\b"), r"the bottom \1"),
    (re.compile(r"\b(?:the )?(edge|side|half|end|corners) (?:farthest|furthest) (?:from|away from) (?:you|me|the robot)\b"), r"the top \1"),
]
#: A whole fold said by its parts: the bottom (near) corners, edge or half brought onto the top ones.
_FOLD_BY_PARTS = re.compile(r"\bbottom (?:corners|edge|side|half|end)\b.*\b(?:top (?:corners|edge|side|half|end)|them)\b|"
                            r"\bthem\b.*\btop (?:corners|edge|side|half)\b")


#: The two near corners named one at a time: "the bottom left corner ..., the bottom right one".
_BOTTOM_PAIR = re.compile(r"\bbottom (left|right) corner\b.*\bbottom (?!\1)(?:left|right) (?:corner|one)\b")
#: Where the near corners go in the fold: the far corners, edge or side.
_ONTO_TOP = re.compile(r"\btop (?:corners|edge|side|end)\b|\bonto (?:them|the top)\b")
#: "like folding a napkin", "the way you'd fold a towel": how, said by likeness.
_LIKE_FOLDING = re.compile(r"(?: ,)? (?:like|as if|the way(?: you(?:'d| would)?)?)(?: when)? (?:(?:you|we|i|people)(?:'re|'d|'m| are| am| would| do)? )?"
                           r"(?:folding|fold)(?: (?:a|an|the|some))? [a-z]+(?= ,|$)")
#: "with the fold on my side", "fold nearest you": the crease at the near side, where the rules' fold puts it.
_NEAR_CREASE = re.compile(r"(?: ,)? with the (?:fold|crease|folded edge|fold line|folded side) (?:on|at|towards?|facing) (?:my|your|the robot's) "
                          r"(?:side|end|edge)\b")


#: The fold's crease said to end away from the robot: the far half laid onto the near one, the other fold.
_FAR_CREASE = re.compile(r"\b(?:fold|crease|folded edge|fold line|folded side) (?:on the side |at the side )?"
                         r"(?:farthest|furthest|far|farther|further) (?:from|away from) (?:you|me|the robot)\b")


def refuse_fold_across(s: str) -> None:
    """Raise :class:`NotAGoalError` where ``s`` folds a cloth across (left onto right) or far half onto near half,
    which no rule makes."""
    if re.search(r"\bfold", s) and (far := _FAR_CREASE.search(s)) is not None:
        raise NotAGoalError(f"'{far[0]}': the rules fold a cloth near edge onto far edge only (its crease nearest to you)")
    if re.search(r"\bfold", s) and (across := _ACROSS.search(s)) is not None:
        raise NotAGoalError(f"'{across[0].strip()}': the rules fold a cloth in half near edge onto far edge only, "
                            "not across it (left onto right)")


def read_cloth_parts(s: str, objects: frozenset[str], note: Note) -> str:
    """``s`` with the cloth's parts named as the rules name them; :data:`FOLD` where it brings the bottom ones onto the top."""
    if not (re.search(r"\b(?:towel|cloth|corners?|fold)", s) or ("towel" in objects or "cloth" in objects) and re.search(r"\b(?:edge|side|half)\b", s)):
        return s
    for pattern, repl in [*_CLOTH_PARTS, *(_EDGE_FROM_YOU if "folded edge" not in s else [])]:
        s = sub(pattern, repl, s, note, "cloth part")
    s = drop(_LIKE_FOLDING, s, note, "how")
    s = drop(_NEAR_CREASE, s, note, "cloth part")
    if (pair := _BOTTOM_PAIR.search(s)) is not None and _ONTO_TOP.search(s[pair.end():]):
        note("cloth part")
        return FOLD  # each near corner taken (by its own arm, say), then brought to the far edge: the fold
    corners = s.replace("bottom left corner", "").replace("bottom right corner", "").replace("top left corner", "").replace("top right corner", "")
    if _FOLD_BY_PARTS.search(s) and not re.search(r"\b(?:left|right) (?:corner|half|side|edge)\b(?!s)", corners):
        note("cloth part")
        return FOLD  # the bottom corners (or edge, or half) onto the top ones: the fold
    return s


def drop_fold_way(out: str, objects: frozenset[str], note: Note) -> str:
    """``out`` without which way the fold goes ("fold it in half, towards the far side": the only fold the rules make)."""
    if re.search(r"\bfold", out) or "towel" in objects:
        out = drop(_FOLD_WAY, out, note, "cloth part")
    return out
