"""Plain English -> the grammar's phrasing: the rewrites the offline composer makes before parsing.

The grammar (:mod:`agentchord.agents.rules.language`) reads imperatives in a fixed order; people
also write typos, other verbs, states, declaratives, temporal clauses and ellipsis. Each rewrite
here maps one of those to the imperative it means, on the normalised (lower-case, separated) text:

- spelling: a word no rule and no scene object knows, one edit (a transposition, a letter
  dropped, doubled or mistyped) from exactly one that is known, is that word (:func:`correct`);
- inflections: ``pouring``, ``poured``, ``emptied`` -> the verb (a table generated from the verbs
  the rules know, :func:`lemma`), where a clause starts with one;
- verb synonyms: ``decant`` -> ``pour``, ``pile`` -> ``stack``, ``double over`` -> ``fold``;
- politeness and frames: ``would you mind ...``, ``your job is to``, ``make sure``, ``in the end``;
- states and declaratives: ``the X ends up in Y``, ``the X is folded``, ``leave the X standing on
  Y``, ``X on Y`` -> ``put the X in Y``, ``fold the X``, ``put the X on Y``;
- temporal clauses: ``A after B-ing C``, ``before B-ing C, A``, ``once S, A``, ``A once S`` ->
  ``B C then A`` (a pronoun of the clause moved first takes the other's object);
- ellipsis: ``..., and the X too``, ``do the same with the X``, ``V the A, and then the B, WHERE``
  -> the previous clause again with the X.

What the rewrites changed is kept (:class:`Rewritten`) for ``plan --explain``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import lru_cache

from agentchord.agents.rules.corrections import read_corrections
from agentchord.agents.rules.discourse import read_sentences
from agentchord.agents.rules.english import is_word
from agentchord.agents.rules.talk import drop_likeness, drop_purpose

#: Verbs people use -> the verb the grammar reads (only where a clause starts with them).
VERB_SYNONYMS = {
    "decant": "pour", "dump": "pour", "tilt": "pour", "pour out": "pour", "spill": "pour",
    "pop": "put", "stick": "put", "rest": "put", "toss": "put", "position": "put", "situate": "put", "plop": "put",
    "pile": "stack", "pile up": "stack", "stack up": "stack", "shove": "push", "relocate": "move", "reposition": "move",
    "double over": "fold", "double": "fold", "fold up": "fold", "halve": "fold", "collect": "pick up", "fetch": "pick up",
    "swap": "switch", "scoot": "move", "scooch": "move", "budge": "move", "load": "put", "slot": "put", "tuck": "put", "lower": "put",
}
#: Verbs whose inflections are read (the grammar's verbs and the synonyms').
VERBS = (
    "pour", "empty", "tip", "fill", "pick", "grasp", "grab", "take", "hold", "lift", "seize", "get", "put", "place", "set",
    "lay", "stand", "leave", "drop", "insert", "deposit", "return", "hand", "pass", "transfer", "give", "switch", "fold",
    "move", "push", "slide", "shift", "carry", "bring", "transport", "nudge", "drag", "stack", "arrange", "rearrange",
    "decant", "dump", "tilt", "pop", "stick", "rest", "toss", "position", "pile", "shove", "relocate", "double", "halve",
    "sit", "lie", "end", "go", "have", "collect", "fetch", "swap", "spill", "turn",
)
_IRREGULAR = {
    "put": "put", "set": "set", "laid": "lay", "lain": "lie", "lying": "lie", "lay": "lay", "stood": "stand", "took": "take",
    "taken": "take", "brought": "bring", "held": "hold", "got": "get", "gotten": "get", "gave": "give", "given": "give",
    "sat": "sit", "went": "go", "gone": "go", "had": "have", "has": "have", "slid": "slide", "left": "leave", "done": "do",
}
#: Participles that say what was done to an object, in a state (``the towel is folded``).
_STATE_VERBS = {"fold": "fold", "fill": "fill", "empty": "empty", "pour": "pour", "hand": "hand", "pass": "pass", "give": "give",
                "transfer": "transfer", "move": "move", "push": "push", "slide": "slide", "shift": "shift", "stack": "stack"}
#: Participles and state verbs that only say where an object is (``placed``, ``sitting``, ``standing``).
_WHERE_VERBS = ("put", "place", "set", "leave", "lay", "lie", "position", "sit", "stand", "rest", "drop", "keep", "insert", "deposit")
#: Words that start a place (the end of a noun phrase a state clause names).
_PLACE = (r"(?:in|into|inside|on|onto|upon|to|at|next to|beside|by|near|behind|between|left of|right of|in front of|"
          r"in back of|on top of|back|forward|forwards|where|down)")
_BE = (r"(?:should end up|must end up|needs? to end up|ends? up|to end up|to be|is|are|was|be|should be|must be|needs? to be|has to be|"
       r"will be|has been|have been|should|must|"
       r"ends? up|should end up|gets?|goes|go|should go|needs? to go|sits?|stands?|lies|rests?|is left|should be left)")
_CLAUSE_START = r"(?:^|(?<=; )|(?<=, )|(?<=\band )|(?<=\bthen ))"
#: Frames around an instruction that add nothing to it.
_FRAMES = [
    r"^(?:hey |ok |okay )?robot(?: ,)? ", r"^hey(?: ,)? ", r"^(?:could|can|would|will) you (?:please )?(?:be so kind as to |mind )?",
    r"^(?:i want|i need|i'd like|i would like|we want|we need) (?:you )?(?:to )?", r"^(?:you should|you need to|you must|you have to) ",
    r"^(?:your|the) (?:job|task|goal) is (?:to )?", r"^(?:your |the )?(?:task|goal|job|end state|final state|target state)(?: ,)? ",
    r"^(?:make sure|ensure|see to it) (?:that )?", r"^(?:in|at) the end(?: ,)? ", r"^get to a state (?:where|in which) ",
    r"^(?:so )?what i (?:want|need|'d like|would like)(?: you to do)? is (?:for you )?(?:to )?(?=\w+ )", r"^kindly ", r"^please ", r"^be so kind as to ", r"^(?:your |the )?(?:task|goal|job|end state|final state|target state)$", r"^(?:the robot|robot) (?:should|must|will) ", r"^let's ", r"^first(?: ,)? (?=the )",
]
_TAILS = [r"(?: ,)? (?:thanks|thank you)(?: very much)?$", r" (?:for me|when you get a chance|if you can|at the end|please)$", r"(?: ,)? please$"]


#: Words of everyday English the rewrites meet that must not be "corrected" into a rule's word.
_COMMON = frozenset("""
a about after again all also an and any are as at away be been before being both but by can could did do does doing done
down each either end every everything first for from get gets go goes going good got had has have having her here him his
how i if in into is it its itself just keep kind last leave let like make me mind more most my need needs next nice no not
now of off ok okay on once one only onto or other our out over own please put quite really same she should so some still
such sure than thank thanks that the their them then there these they thing this those through to too two under until up
upon us very want was we well were what when where which while who why will with without would yes yet you your yours
robot task job goal state final target end ends ending bit little lot much many way side sides table both either each
""".split())


@lru_cache(maxsize=1)
def known_words() -> frozenset[str]:
    """The words the rewrites read (spelling is never corrected away from one of them)."""
    words = set(_COMMON) | set(VERBS) | set(_lemmas()) | set(_STATE_VERBS) | set(_WHERE_VERBS)
    for text in [*VERB_SYNONYMS, _PLACE, _BE, *_FRAMES, *_TAILS]:
        words |= set(re.findall(r"[a-z]+", text))
    return frozenset(words)


@dataclass
class Rewritten:
    """The text the grammar parses, and what was changed on the way (for ``plan --explain``)."""

    text: str
    corrected: dict[str, str] = field(default_factory=dict)
    steps: list[str] = field(default_factory=list)


# --- inflections ------------------------------------------------------------------------------


def _forms(verb: str) -> set[str]:
    stem_e = verb[:-1] if verb.endswith("e") and not verb.endswith("ee") else verb
    doubled = verb + verb[-1] if re.fullmatch(r"[^aeiou]*[aeiou][bdgmnprt]", verb) else verb
    forms = {verb + "s", verb + "es", stem_e + "ed", stem_e + "ing", doubled + "ed", doubled + "ing"}
    if verb.endswith("y") and verb[-2] not in "aeiou":
        forms |= {verb[:-1] + "ied", verb[:-1] + "ies"}
    return forms


@lru_cache(maxsize=1)
def _lemmas() -> dict[str, str]:
    table = {form: verb for verb in VERBS for form in _forms(verb)}
    table.update(_IRREGULAR)
    table.update({v: v for v in VERBS})
    return table


def _verb(word: str) -> str | None:
    """The verb the rules read that ``word`` is a form of (``picks`` -> ``pick``), else None."""
    verb = lemma(word)
    return verb if verb in _VERB_WORDS and verb not in ("up", "down", "end", "go", "have", "leave") else None


def lemma(word: str) -> str:
    """The verb an inflected form is of (``pouring`` -> ``pour``), or the word itself."""
    return _lemmas().get(word, word)


# --- spelling ----------------------------------------------------------------------------------


def _distance(a: str, b: str) -> int:
    """Optimal string alignment distance (an adjacent transposition costs one edit)."""
    previous2: list[int] = []
    previous = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        current = [i] + [0] * len(b)
        for j in range(1, len(b) + 1):
            cost = 0 if a[i - 1] == b[j - 1] else 1
            current[j] = min(previous[j] + 1, current[j - 1] + 1, previous[j - 1] + cost)
            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:
                current[j] = min(current[j], previous2[j - 2] + 1)
        previous2, previous = previous, current
    return previous[-1]


def _subsequence(short: str, long: str) -> bool:
    letters = iter(long)
    return all(c in letters for c in short)


def correct(word: str, vocabulary: frozenset[str]) -> str | None:
    """The one known word ``word`` is a typo of, or ``None``.

    Never an English word (:func:`~agentchord.agents.rules.english.is_word`: "handles" is not a typo
    of "handes"), and never towards a verb form English lacks. One edit, on words of four letters or
    more (three for a transposition: ``cpu``); where two
    known words are one edit away, a letter dropped from one of them wins (``pur`` -> ``pour``,
    not ``put``), and otherwise the word is left alone.
    """
    if word in vocabulary or not word.isalpha() or len(word) < 3 or lemma(word) != word or is_word(word):
        return None  # known, not a word, an inflection, or English: a word people write is not a typo
    generated = _lemmas()
    close = [w for w in vocabulary if abs(len(w) - len(word)) <= 1 and w[0] in (word[0], word[1]) and _distance(word, w) == 1
             and not (w in generated and generated[w] != w and not is_word(w))]  # not an ending English lacks ("handes")
    if len(word) == 3:  # short words: a transposition or a letter dropped only ("cpu", "pur")
        close = [w for w in close if sorted(w) == sorted(word) or (len(w) == 4 and _subsequence(word, w))]
    # Several one edit away: a transposition first, then a letter dropped, then one added.
    for prefer in (lambda w: sorted(w) == sorted(word), lambda w: len(w) > len(word), lambda w: len(w) < len(word)):
        if len(close) > 1:
            close = [w for w in close if prefer(w)] or close
    return close[0] if len(close) == 1 else None


#: Verbs a real word where a clause's verb goes may be a slip for ("poor" -> pour).
_SLIP_VERBS = ("pour", "put", "place", "pick", "grab", "hand", "pass", "give", "move", "push", "slide", "fold", "lift", "hold", "take",
               "drop", "fill", "stack", "carry", "bring", "tip", "empty", "insert")
#: Words a side (left, right) comes before: a word one edit from a side there is that side.
_SIDED = frozenset({"arm", "hand", "gripper", "side", "half", "edge", "corner", "one", "arms", "hands"})
#: Words that start what a verb acts on.
_OBJECT_STARTS = frozenset({"the", "a", "an", "it", "them", "both", "water", "some", "all", "everything", "up", "down"})


def _slip(word: str) -> str | None:
    """The one action verb ``word`` (an English word where a verb goes) is one edit from, or ``None``."""
    close = [v for v in _SLIP_VERBS if len(word) >= 3 and abs(len(v) - len(word)) <= 1 and _distance(word, v) == 1]
    return close[0] if len(close) == 1 else None


#: Nouns of the table itself, the place noun an English word after "the" may be a slip for.
_PLACE_NOUNS = ("table", "tabletop")


def correct_place(word: str) -> str | None:
    """The table noun ``word`` is one edit from ("tale" -> table), or ``None``."""
    close = [w for w in _PLACE_NOUNS if w != word and len(word) >= 4 and _distance(word, w) == 1]
    return close[0] if len(close) == 1 else None


# --- the rewrites ------------------------------------------------------------------------------


def _sub(pattern: str, repl, text: str, steps: list[str], name: str) -> str:
    new = re.sub(pattern, repl, text)
    if new != text:
        steps.append(name)
    return new


def _first_object(text: str, objects: frozenset[str]) -> str | None:
    """The first noun phrase of ``text`` whose head names a scene object (``the red block``)."""
    words = text.split()
    for i, w in enumerate(words):
        if w in objects:
            start = i
            while start > 0 and words[start - 1] not in ("the", "a", "an", "its", "your") and start > i - 3 and \
                    re.fullmatch(r"[a-z]+", words[start - 1]) and words[start - 1] not in _VERB_WORDS and words[start - 1] not in ("and", "then", "of", "from", "into", "in", "on", "to", "with", "it"):
                start -= 1
            return "the " + " ".join(words[start:i + 1])
    return None


_VERB_WORDS = frozenset(VERBS) | {"up", "down"}
#: Words that cannot begin the subject of a verbless clause.
_NOT_SUBJECT = frozenset({"with", "using", "use", "by", "left", "right", "both", "it", "them", "then", "and", "first", "the", "there", "to"})


def _gerund_clause(clause: str) -> str:
    """``pouring it into the cup`` -> ``pour it into the cup``; a state -> its imperative."""
    words = clause.split()
    if words and words[0] in ("being", "having") and len(words) > 1:
        words = words[1:]
    if words and lemma(words[0]) != words[0]:
        words[0] = lemma(words[0])
    return " ".join(words)


def _swap_pronoun(first: str, second: str, objects: frozenset[str]) -> str:
    """``first`` (now said first) with its ``it`` standing for ``second``'s object."""
    if re.search(r"\bit\b", first) is None:
        return first
    np = _first_object(second, objects)
    return re.sub(r"\bit\b", np, first, count=1) if np else first


def _state_to_imperative(clause: str, objects: frozenset[str]) -> str:
    """A state an object should be in -> the imperative that brings it about (or the clause unchanged)."""
    clause = clause.strip()
    m = re.match(rf"^(?:the |both the )?((?:[a-z_]+ ){{0,3}}?[a-z_]+(?: and the (?:[a-z_]+ ){{0,2}}?[a-z_]+)?) {_BE}(?: (?:been|being|left|then|also))? ?(.*)$", clause)
    if m is None:  # a participle without a verb: "the towel folded", "the tray pushed forward"
        m = re.match(r"^(?:the )?((?:[a-z_]+ ){0,3}?[a-z_]+) ((?:\w+ed|\w+en|put|set|slid|laid)\b.*)$", clause)
        if m is None or lemma(m[2].split()[0]) == m[2].split()[0]:
            return clause
    subject, rest = m[1], m[2]
    if not any(w in objects for w in subject.split()) or any(lemma(w) in _VERB_WORDS or w in _NOT_SUBJECT for w in subject.split()):
        return clause
    subject = "the " + subject
    verb, _, tail = rest.partition(" ")
    base = lemma(verb)
    if base in _STATE_VERBS:
        if base in ("hand", "pass", "give", "transfer") and not tail.startswith("over"):
            return f"{base} {subject} {tail}".strip()
        return f"{_STATE_VERBS[base]} {subject} {tail}".strip()
    if base in _WHERE_VERBS and tail:
        rest = tail
    if re.match(r"(?:forward|forwards|ahead|further|closer)\b", rest):
        return f"move {subject} {rest}"
    if re.match(_PLACE + r"\b", rest) or rest in ("down", "back"):
        return f"put {subject} {rest}"
    return clause


def rewrite(text: str, vocabulary: frozenset[str] = frozenset(), objects: frozenset[str] = frozenset()) -> Rewritten:
    """The normalised ``text`` in the grammar's phrasing.

    Args:
        text: The instruction, normalised (:func:`agentchord.agents.rules.language.normalise`).
        vocabulary: Words known to the rules and the scene (spelling is corrected towards them).
        objects: The words that name scene objects (heads of noun phrases: ``block``, ``cup``).
    """
    out = Rewritten(text)
    steps = out.steps
    # Spelling first: every later rewrite matches known words.
    if vocabulary:
        words = text.split(" ")
        for i, word in enumerate(words):
            fixed = correct(word, vocabulary)
            if fixed is None and i > 0 and words[i - 1] == "the" and is_word(word):
                # An English word heading a noun phrase may still be a slip for the one place noun it is
                # an edit from ("of the tale" -> table): places are not objects, whose names stay exact.
                fixed = correct_place(word)
            if fixed is None and (i == 0 or words[i - 1] in (",", ";", "then", "and")) and i + 1 < len(words) \
                    and words[i + 1] in _OBJECT_STARTS and word not in vocabulary and is_word(word):
                fixed = _slip(word)  # "poor water into the cup": a real word where a verb goes, one edit from one
            if fixed is None and i + 1 < len(words) and words[i + 1] in _SIDED and word not in ("left", "right"):
                sides = [s for s in ("left", "right") if _distance(word, s) == 1]  # "the lift arm", "rite hand": a side
                fixed = sides[0] if len(sides) == 1 and len(word) >= 3 else None
            if fixed is not None:
                out.corrected[word] = fixed
                words[i] = fixed
        text = " ".join(words)
    text = read_corrections(text, objects, _verb, steps.append)
    text = " ; ".join(_mind(sentence, steps) for sentence in text.split(" ; "))
    text = drop_likeness(text, objects, steps.append)
    text = drop_purpose(text, objects, steps.append)
    if objects:
        # "move that orange block", "this cup": a demonstrative before what names an object is its determiner.
        names = "|".join(sorted(map(re.escape, objects), key=len, reverse=True))
        text = _sub(rf"(?<!\bso )(?<!\bsure )(?<!\bafter )(?<!\bbefore )\b(?:that|this)( (?:[a-z]+ )?)(?=(?:{names})\b)",
                    lambda m: m[0] if _verb(m[1].strip() or "-") else f"the{m[1]}", text, steps, "pronoun")
    read = read_sentences(text.split(" ; "), objects, steps.append, _verb)
    sentences = [_sentence(sentence, steps, objects) for sentence in read if sentence]
    out.text = _ellipsis(" ; ".join(s for s in sentences if s).replace(" , ; ", " , "), steps, objects)
    return out


_MIND = r"^(?:(?:hey|hi|hello|ok|okay|so)(?: there)?(?: ,)? )*(?:(?:would|could|do) you )?(?:please )?mind (\w+ing)\b"


def _mind(s: str, steps: list[str]) -> str:
    """``would you mind dropping X, and then moving Y`` -> ``drop X , and then move Y``: each step the frame governs
    is an -ing form."""
    if not re.match(_MIND, s.strip()):
        return s
    s = _sub(_MIND, lambda m: lemma(m[1]), s.strip(), steps, "politeness")
    return _sub(r"(?<= , )(?:and |then |and then )*(\w+ing)\b(?= (?:the|it|them|both|that|this|your|my)\b)",
                lambda m: m[0].replace(m[1], lemma(m[1])) if lemma(m[1]) in _VERB_WORDS else m[0], s, steps, "politeness")


def _sentence(s: str, steps: list[str], objects: frozenset[str]) -> str:
    for _ in range(2):  # frames nest: "could you please make sure ..."
        for frame in _FRAMES:
            s = _sub(frame, "", s, steps, "frame")
    for tail in _TAILS:
        s = _sub(tail, "", s, steps, "frame")
    # An arm said as a sentence of its own ("With both hands: pour ..."); a third-person verb after an arm.
    s = _sub(r"^((?:with|using) (?:both|the left|the right|your left|your right) (?:arm|hand|gripper)s?)$", r"\1 ,", s, steps, "arm")
    s = _sub(r"\b(arm|hand|gripper) (\w+)\b", lambda m: f"{m[1]} {lemma(m[2]) if lemma(m[2]) in _VERB_WORDS and lemma(m[2]) != 'leave' else m[2]}", s, steps, "arm")
    s = _sub(r"\b(?:the two of them|both of them|the pair of them)\b", "both", s, steps, "pronoun")
    # Parts of a cloth: near and far are the bottom and the top.
    s = _sub(r"\bnear (corners?|edges?|side|end|hem)\b", r"bottom \1", s, steps, "synonym")
    s = _sub(r"\bfar (corners?|edges?|side|end|hem)\b", r"top \1", s, steps, "synonym")
    s = _sub(r"^there is (?:some )?water in (the \w+) from (the \w+)$", r"pour water from \2 into \1", s, steps, "declarative")
    s = _sub(r"^both (the [a-z ]+?) and (the [a-z ]+?) (?:go|should go|end up|should end up|are|belong) ", r"put \1 and \2 ", s, steps, "declarative")
    # Possessives before an arm or a side: "the robot's right arm", "the plate's left side".
    s = _sub(r"\b(?:the )?(?:robot|robot's) (?=(?:left|right|other) (?:arm|hand|gripper))", "the ", s, steps, "possessive")
    s = _sub(r"\b(?:by|beside|next to|on|at) the (\w+) (left|right) side\b", r"to the \2 of the \1", s, steps, "possessive")
    s = _sub(r"\b(?:on |at |to )?(?:either|each|both) sides? of\b", "beside", s, steps, "reference")
    s = _sub(r"^(?:bimanual(?:ly)?|two-?handed|two-?arm(?:ed)?|dual-?arm) (?=pour|fold|handover)", "with both arms , ", s, steps, "arm")
    s = _sub(r"^(?:one-?handed|single-?arm(?:ed)?|one-?arm(?:ed)?) (?=pour|fold|handover)", "", s, steps, "arm")
    # Spatial selection: "the block on the left" -> "the left block" before another place.
    s = _sub(r"\bthe (\w+) (?:on|at|to) the (left|right|front|back)(?= (?:into|in|onto|on|next|beside|to|behind|near)\b)", r"the \2 \1", s, steps, "reference")
    s = _sub(r"\bthe (\w+) (?:nearer|closer to|nearest to|closest to) the (front|back)\b", r"the \2 \1", s, steps, "reference")
    s = _sub(r"\b(left|right|front|back)most\b", r"\1", s, steps, "reference")
    # Verb synonyms and inflected verbs where a clause starts.
    for word, verb in sorted(VERB_SYNONYMS.items(), key=lambda kv: -len(kv[0])):
        s = _sub(rf"{_CLAUSE_START}{word}\b", verb, s, steps, "synonym")
    s = _sub(rf"{_CLAUSE_START}double (.+?) over\b", r"fold \1", s, steps, "synonym")
    s = _sub(rf"{_CLAUSE_START}get (the [a-z ]+?) (?=(?:into|in|inside|onto|on|to|next to|beside)\b)", r"put \1 ", s, steps, "synonym")
    s = _sub(r"\bup to meet\b|\bto meet\b|\bup onto\b|\bover onto\b", "onto", s, steps, "synonym")
    # Temporal clauses (a sentence at a time): the clause done first is said first.
    s = _temporal(s, steps, objects)
    # States and declaratives, a clause at a time.
    parts = re.split(r"( , (?:and )?(?:then )?| and then | then | and (?=the ))", s)
    for i in range(0, len(parts), 2):
        clause = parts[i]
        after_and = i > 0 and parts[i - 1] == " and "
        clause = _sub(r"^(?:leave|have|get|keep) (the .+?) (?:sitting|standing|lying|resting|placed|put|positioned|set|left|laid)\b ?(?:so (?:that )?it(?: is|'s)? (?:standing|lying|sitting|upright) )?", r"put \1 ", clause, steps, "state")
        clause = _sub(r"^(put|set|place|lay) (the .+?) down so (?:that )?it(?: is|'s)? (?:standing|lying|sitting|resting) ", r"\1 \2 ", clause, steps, "state")
        clause = _sub(r" (?:standing|sitting|lying|resting|upright)(?= (?:on|in|where|back|at|inside|next|beside)\b)", "", clause, steps, "state")
        then = "then " if clause.startswith("then ") else ""  # "Then the tray goes forward."
        state = then + _state_to_imperative(clause.removeprefix("then "), objects)
        if state != clause:
            steps.append("declarative")
            clause = state
        elif objects and not after_and and (head := re.match(rf"^(?:the )?((?:[a-z_]+ ){{0,2}}?([a-z_]+)) (?={_PLACE}\b|left of|right of)", clause)):
            # "red block on blue block": a scene without a verb.
            if head[2] in objects and not any(lemma(w) in _VERB_WORDS or w in _NOT_SUBJECT for w in head[1].split()):
                verb = "move " if re.search(r" (?:forward|forwards|ahead|closer)$", clause) else "put "  # "the tray forward": a way
                clause = verb + (clause if clause.startswith("the ") else "the " + clause)
                steps.append("declarative")
        parts[i] = clause.strip()
    return "".join(parts)


def _temporal(s: str, steps: list[str], objects: frozenset[str]) -> str:
    s = _sub(r"(?: ,)? (?:and )?(?:once|when|after) (?:that(?: is|'s)?|this(?: is|'s)?|it(?: is|'s)?) (?:done|finished|complete)\b ,?|(?: ,)? (?:and )?,? (?:once|when) done ,?", " then ", s, steps, "temporal")
    s = re.sub(r"^(?:once|when|after) (?:that|this)(?: is|'s)? (?:done|finished|complete)(?: ,)? ", "", s)
    s = _sub(r"^first(?: ,)? (.+?)(?: ,)? (?:then|and then|afterwards) ", r"\1 then ", s, steps, "temporal")
    # "put it on the target, but first pass it to the right arm": the step said "first" is done first.
    m = re.match(r"^(.+?) , (?:but |and )?first(?: ,)? (\w+) (.+)$", s)
    if m and lemma(m[2]) in VERBS:
        steps.append("temporal")
        return f"{_swap_pronoun(f'{lemma(m[2])} {m[3]}', m[1], objects)} then {m[1]}"
    # "A while the left arm holds B": the holding starts first.
    m = re.match(r"^(.+?)(?: ,)? while (the (?:left|right|other) (?:arm|hand|gripper) (?:hold|keep|grasp|grip)s? .+)$", s)
    if m:
        steps.append("temporal")
        holding = re.sub(r"\b(?:keep|grasp|grip)s?\b", "hold", m[2])
        return f"{_swap_pronoun(holding, m[1], objects)} then {m[1]}"
    # "A, but only after B-ing C" / "A after B-ing C" / "A after being B-ed".
    m = re.match(r"^(.+?)(?: ,)? (?:but )?(?:only )?after (?:you(?:'ve| have)? )?(\w+ing|\w+ed|being \w+) (.+)$", s)
    if m and lemma(m[2].split()[-1]) != m[2].split()[-1]:
        first = _gerund_clause(f"{m[2]} {m[3]}")
        if m[2].startswith("being"):
            subject = _first_object(m[1], objects)
            first = f"{lemma(m[2].split()[1])} {subject} {m[3]}" if subject else first
        steps.append("temporal")
        return f"{_swap_pronoun(first, m[1], objects)} then {m[1]}"
    m = re.match(r"^(?:after|once) (?:you(?:'ve| have)? )?(\w+ing|\w+ed) (.+?) , (.+)$", s)
    if m and lemma(m[1]) != m[1]:
        steps.append("temporal")
        return f"{lemma(m[1])} {m[2]} then {m[3]}"
    m = re.match(r"^before (?:you )?(\w+) (.+?) , (.+)$", s)
    if m and lemma(m[1]) in VERBS:
        steps.append("temporal")
        second = f"{lemma(m[1])} {m[2]}"
        return f"{_swap_pronoun(m[3], second, objects)} then {second}"
    m = re.match(r"^(.+?)(?: ,)? before (?:you )?(\w+) (.+)$", s)
    if m and lemma(m[2]) in VERBS:
        steps.append("temporal")
        return f"{m[1]} then {lemma(m[2])} {m[3]}"
    m = re.match(r"^(?:once|when|as soon as) (.+?) , (.+)$", s)
    if m:
        steps.append("temporal")
        return f"{_once(m[1], objects)} then {m[2]}"
    m = re.match(r"^(.+?)(?: ,)? (?:once|as soon as) (.+)$", s)
    if m:
        steps.append("temporal")
        first = _once(m[2], objects)
        return f"{_swap_pronoun(first, m[1], objects)} then {m[1]}"
    return s


def _once(clause: str, objects: frozenset[str]) -> str:
    """What a ``once``-clause says is done first, as an imperative."""
    clause = re.sub(r"^you(?:'ve| have)? (?:got |picked up |grasped |grabbed )?(?=the )", "pick up ", clause)
    clause = re.sub(r"^you (?:have|hold) ", "pick up ", clause)
    m = re.match(r"^the (left|right) (?:arm|hand|gripper) (?:has|holds|has got) (.+?) from the (left|right) (?:arm|hand|gripper)$", clause)
    if m:
        return f"hand {m[2]} from the {m[3]} arm to the {m[1]} arm"
    if re.match(r"^(?:the )?\w+ (?:is|are|has been|have been|gets|sits) ", clause) or re.match(r"^it (?:is|has been) ", clause):
        return _state_to_imperative(clause, objects)
    return _gerund_clause(clause)


#: "put the red one in (with the left arm)": into what was last put into.
_IN_ALONE = re.compile(r"\b((?:put|place|drop|set|insert|pop|toss) (?:the [a-z]+(?: [a-z]+)?|it|them) (?:in|into|inside))(?= with\b| ,| ;| then\b|$)")


def _container_again(s: str, steps: list[str]) -> str:
    """``drop the blue block in the cup ; put the red one in`` -> ``... put the red one in the cup``."""
    while (m := _IN_ALONE.search(s)) is not None:
        hosts = re.findall(r"\b(?:in|into|inside) (the [a-z]+(?: (?!with\b|then\b|and\b)[a-z]+)?)\b", s[: m.start()])
        if not hosts:
            break
        steps.append("ellipsis")
        s = f"{s[: m.end()]} {hosts[-1]}{s[m.end():]}"
    return s


def _ellipsis(s: str, steps: list[str], objects: frozenset[str]) -> str:
    """``V the A WHERE , and the B too`` -> ``V the A WHERE , V the B WHERE``."""
    def previous_clause(head: str) -> tuple[str, str] | None:
        start = max(head.rfind(" then "), head.rfind(" ; "), head.rfind(" , "))
        clause = head[start:].strip(" ,;").removeprefix("then ").strip() if start >= 0 else head.strip()
        if clause.startswith(("with ", "using ")) and " , " in head:
            return None
        np = _first_object(clause, objects)
        if np is None:
            return None
        word = np.rsplit(" ", 1)[-1]
        where = clause.partition(f" {word}")[2]
        verb = clause.split(" ")[0]
        return verb, where.strip()

    def again(m: re.Match) -> str:
        found = previous_clause(m[1])
        if found is None:
            return m[0]
        steps.append("ellipsis")
        verb, where = found
        return f"{m[1]} then {verb} {m[2]} {where}".rstrip()

    s = re.sub(r"^(.+?)(?: ,| ;)? (?:and )?(?:then )?(?:do )?(?:the )?same (?:with|for) (the [a-z ]+?)$", again, s)
    s = _container_again(s, steps)
    s = re.sub(r"^(.+?)(?: ,)? (?:and )?(the [a-z ]+?) (?:too|as well|also)$", again, s)
    m = re.match(r"^(.+?) , (?:and )?then (the [a-z ]+?)(?: (with the (?:left|right|other) arm))?$", s)
    found = previous_clause(m[1]) if m and any(w in objects or w == "one" for w in m[2].split()[1:]) else None
    if m and found is not None:  # "put the red block in the cup with the right arm, then the blue one with the left arm"
        steps.append("ellipsis")
        verb, where = found
        where = re.sub(r"\s*\bwith the (?:left|right|other) arm\b", "", where)
        s = f"{m[1]} then {verb} {m[2]} {where} {m[3] or ''}".strip()
    m = re.match(r"^(\w+) (the [a-z ]+?) , (?:and )?then (the [a-z ]+?) , (.+)$", s)
    if m and (lemma(m[4].removeprefix("and ").split()[0]) in VERBS):  # "grab the fork, then the spoon, and line them up ...": a step of its own
        steps.append("ellipsis")
        s = f"{m[1]} {m[2]} then {m[1]} {m[3]} then {m[4].removeprefix('and ')}"
    elif m:
        steps.append("ellipsis")
        s = f"{m[1]} {m[2]} {m[4]} then {m[1]} {m[3]} {m[4]}"
    return s
