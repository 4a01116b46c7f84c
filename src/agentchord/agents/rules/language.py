"""The offline composer's grammar of instructions: English -> clauses, before any scene.

A `lark <https://github.com/lark-parser/lark>`_ Earley grammar over lower-cased words (``instructions.lark``).
An instruction is a sequence of steps (joined by ``then``, ``and``, ``after that``,
``next``, ``finally``, ``;``, ``,`` or numbered ``1.`` ``2.``); a step is one verb phrase:

- *pour*: ``pour|empty [water] [from NP] into NP``, ``pour NP into NP``, ``fill NP [with water] from NP``;
- *pick*: ``pick up|grasp|take|grab|hold|lift NP [ARM] [and NP [ARM]]``;
- *place*: ``put|place|set|lay|stand|leave|drop|return NP [down|back] [WHERE] [ARM]``;
- *hand over*: ``hand|pass|transfer|give|switch NP [over] [from ARM] [to ARM]``;
- *fold*: ``fold NP [in half|in two]``;
- *move*: ``move|push|slide|shift|carry|bring NP [DIRECTION] [WHERE] [ARM]``;
- *stack*: ``stack NP on [top of] NP``; *arrange*: ``arrange NP and NP beside NP``.

``ARM`` is ``with|using [the] left|right|other arm|hand|gripper`` or ``with both arms``;
``use the left arm to ...`` and ``the left arm ...`` put the arm before the verb. ``WHERE``
is a preposition and a noun phrase (``on the table``, ``into the cup``, ``in the front
left corner of the table``, ``next to the cup``, ``to the left of the plate``, ``between the
cup and the bottle``, ``in the target region``). A noun phrase is an optional determiner,
modifiers (colours, sizes, sides, any word) and a head noun, optionally ``of NP``, or a
pronoun (``it``, ``them``, ``both``), or ``the big one`` (an object of the kind last named). A step
may leave its verb out after the first (``fork on the left of the plate, spoon on its right``). The grammar knows no scene: what a noun phrase names
is decided by :mod:`agentchord.agents.rules.instructions`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from lark import Lark, Transformer
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from agentchord.agents.rules.phrasing import Rewritten, rewrite

#: The grammar (``instructions.lark`` beside this module).
GRAMMAR = (Path(__file__).parent / "instructions.lark").read_text(encoding="utf-8")


@dataclass(frozen=True)
class NounPhrase:
    """A noun phrase as written: ``words`` (modifiers then head), an ``of`` phrase, or a pronoun (``it``, ``all``)."""

    words: tuple[str, ...] = ()
    of: NounPhrase | None = None
    pronoun: str = ""

    @property
    def text(self) -> str:
        if self.pronoun:
            return self.pronoun
        return " ".join(self.words) + (f" of {self.of.text}" if self.of else "")


@dataclass(frozen=True)
class Where:
    """Where something goes: ``relation`` (``at``, ``on_top``, ``front_of``, ``behind``, ``next_to``, ``side_of``, ``between``, ``back``) and its phrases."""

    relation: str
    phrases: tuple[NounPhrase, ...] = ()
    side: str = ""
    prep: str = ""


@dataclass
class Clause:
    """One step of an instruction: a verb (``pour``, ``pick``, ``place``, ...) and what it names."""

    verb: str
    text: str = ""
    objects: list[NounPhrase] = field(default_factory=list)
    arms: list[str | None] = field(default_factory=list)
    where: Where | None = None
    source: NounPhrase | None = None
    target: NounPhrase | None = None
    arm: str | None = None
    giver: str | None = None
    receiver: str | None = None
    direction: str = ""
    back: bool = False


#: A direction word that ends a noun phrase of a move -> the direction ("push it back": away from whoever stands
#: where the robot is, towards the table's back, as "the back of the table" is).
_DIRECTIONS = {"forward": "forward", "forwards": "forward", "ahead": "forward", "left": "left", "right": "right", "back": "forward"}


class ParseError(ValueError):
    """The words the grammar cannot read: ``words`` (from the first word it could not fit) and what it expected there."""

    def __init__(self, text: str, column: int, expected: list[str]) -> None:
        self.text, self.column, self.expected = text, column, expected
        self.words = text[column:].strip() or "(the end of the instruction)"
        super().__init__(f"cannot read {self.words!r}")


#: Third-person verb forms ("the right arm pours ...") -> the imperative.
_VERB_FORMS = re.compile(
    r"\b(pour|put|place|set|pick|hand|move|fold|grasp|take|pass|transfer|push|slide|carry|return|stack|lift|grab|empty|hold|give|bring|drop|insert|arrange|rearrange|shift|use)(?:s|es)\b"
)
_PUNCT = re.compile(r"\s*([,;:.])\s*")


def normalise(instruction: str) -> str:
    """Lower case, numbered steps and punctuation as separators, the possessive ``'s`` dropped."""
    text = instruction.lower().replace("\u2019", "'").replace("\n", " ; ")
    text = re.sub(r"(?:^|(?<=\s))(?:step\s*)?\d+\s*[.):]\s+", " ; ", text)  # "1. pick ...", "step 2) ..."
    # "fork n spoon", "cup & bottle", "fork + spoon", "rock 'n' roll": shorthand for "and" between two words.
    text = re.sub(r"(?<=\w)\s+(?:n|&|\+|'n'?|'n)\s+(?=\w)", " and ", text)
    text = re.sub(r"'s\b", "", text)
    # "put your things back down", "the stuff": the objects already named, as "them".
    text = re.sub(r"\b(?:your|the|those|these|all the|both) (?:things|stuff|objects|items)\b", "them", text)
    text = re.sub(r"\bcentre\b", "center", text)
    # fold_towel's how ("bringing its bottom corners onto ...", "so the near edge meets ..."): a purpose clause of a fold only.
    text = re.sub(r",?\s*\b(?:bringing|laying|matching|with its(?! (?:left|right|other|both) )|putting its)\b[^,;.]*", "", text)
    if re.search(r"\bfold", text):
        text = re.sub(r",?\s*\b(?:so that (?=(?:the|its)\b)|so (?=(?:the|its)\b))[^,;.]*", "", text)
    # "Set the table: fork left of the plate, ...": the title is the verb of the steps that follow.
    text = re.sub(r"^(?:set|lay) the table\s*[:,;-]\s*(?=(\w+))", lambda m: "" if _VERB_FORMS.match(m[1] + "s") else "put ", text.strip())
    text = _VERB_FORMS.sub(r"\1", text)
    text = re.sub(r"^(?:could|can|would|will) you\s+|^(?:i want|i'd like|i would like) you to\s+|^(?:please\s+)", "", text.strip())
    # A heading names the arm of every step under it (read by agents.rules.discourse).
    text = re.sub(r"\b([lr])\s+(?=(?:arm|hand|gripper)s?\b)", lambda m: "left " if m[1] == "l" else "right ", text)  # "R arm:"
    text = re.sub(r"(?:^|(?<=[;.]\s))([lr])\s*:", lambda m: "left :" if m[1] == "l" else "right :", text)  # "R: place it ..."
    text = re.sub(r"\b(to|from|with) ([lr])\b(?=\s*(?:[,;.]|$|then\b|and\b))", lambda m: f"{m[1]} the {'left' if m[2] == 'l' else 'right'} arm", text)
    text = re.sub(r"(?:^|(?<=[;.]\s))(?:the\s+)?(left|right|both)(?:\s+(arm|hand|gripper)s?)?\s*:", r"armheading \1 ,", text)
    text = re.sub(r"\b(on|to|at) its (left|right)(?: hand)?(?: side)?\b", r"\1 the \2 of it", text)
    text = re.sub(r"\b(upright|steady|steadily|firmly|securely|safely|upside up)\b", " ", text)
    text = re.sub(r",?\s*\bfor (?:now|the moment|the time being)\b", " ", text)
    text = re.sub(r"\b(please|carefully|gently|slowly|now|just|again)\b", " ", text)
    text = re.sub(r"\b(?:pick|take|lift) up\b", "pick up", text)
    text = re.sub(r"\bset down\b", "put down", text)
    text = re.sub(r"\bhand-?over\b", "handover", text)
    text = re.sub(r"\bleft-hand\b|\bleft hand side\b", "left", text)
    text = re.sub(r"\bright-hand\b|\bright hand side\b", "right", text)
    text = re.sub(r"[!?]+", " ; ", text)  # a question or an exclamation ends a sentence
    text = re.sub(r"[\"()]", " ", text)
    text = re.sub(r"\s+-+\s+", " , ", text)  # "set the table - fork on the left"
    text = _PUNCT.sub(r" \1 ", text)
    text = re.sub(r"(?:\s*[;.:]\s*)(?:[;.:,]\s*)*", " ; ", text)  # sentence ends: one separator
    text = re.sub(r"(?:\s*,\s*)+", " , ", text)
    return re.sub(r"\s+", " ", text).strip(" ;,.")


@lru_cache(maxsize=1)
def parser() -> Lark:
    """The Earley parser of :data:`GRAMMAR` (built once)."""
    return Lark(GRAMMAR, parser="earley", lexer="basic", ambiguity="resolve", propagate_positions=True)


class _ToClauses(Transformer):
    # words
    def left(self, _):
        return "left"

    def right(self, _):
        return "right"

    def side(self, items):
        return items[0]

    def word(self, items):
        return str(items[0])

    def pronoun(self, items):
        return str(items[0])

    def p_on(self, _):
        return "on"

    def p_in(self, _):
        return "in"

    def p_at(self, _):
        return "at"

    def back(self, _):
        return ("back", True)

    # noun phrases
    def it(self, items):
        return NounPhrase(pronoun=items[0])

    def all(self, _):
        return NounPhrase(pronoun="all")

    def noun(self, items):
        words = tuple(w for w in items if isinstance(w, str))
        of = next((i for i in items if isinstance(i, NounPhrase)), None)
        return NounPhrase(words=words, of=of)

    def one_of_kind(self, items):
        # "the big one": modifiers of an object of the kind last named.
        return NounPhrase(words=(*(w for w in items if isinstance(w, str)), "one"))

    def np_list(self, items):
        return list(items)

    # arms
    def one_arm(self, items):
        return items[0]

    def other_arm(self, _):
        return "other"

    def both_arms(self, _):
        return "both"

    def arm(self, items):
        return ("arm", items[0])

    def from_arm(self, items):
        return ("from", items[0])

    def to_arm(self, items):
        return ("to", items[0])

    # directions and places
    def forward(self, _):
        return ("direction", "forward")

    def backward(self, _):
        return ("direction", "backward")

    def front_way(self, _):
        # "carry it to the front": towards the table's front edge, or (as people say it) forward: which is decided at grounding.
        return ("direction", "front")

    def to_side(self, items):
        return ("direction", items[0])

    def direction(self, items):
        return ("direction", items[0])

    def at(self, items):
        return Where("at", (items[1],), prep=items[0])

    def on_top(self, items):
        return Where("on_top", (items[0],))

    def front_of(self, items):
        return Where("front_of", (items[0],))

    def behind(self, items):
        return Where("behind", (items[0],))

    def next_to(self, items):
        return Where("next_to", (items[0],))

    def between(self, items):
        return Where("between", (items[0], items[1]))

    def side_of(self, items):
        return Where("side_of", (items[-1],), side=items[0])

    def back_where(self, _):
        return Where("back")

    def spot_of(self, items):
        # "where the cup was": the spot another object stands on (at the start).
        return Where("spot_of", (NounPhrase(words=tuple(w for w in items if isinstance(w, str))),))

    def held(self, items):
        arm = next((i[1] for i in items if isinstance(i, tuple)), None)
        return (items[0], arm)

    # clauses
    @staticmethod
    def _clause(verb: str, items) -> Clause:
        clause = Clause(verb=verb)
        for item in items:
            if isinstance(item, tuple) and item[0] == "arm":
                clause.arm = item[1]
            elif isinstance(item, tuple) and item[0] == "from":
                clause.giver = item[1]
            elif isinstance(item, tuple) and item[0] == "to":
                clause.receiver = item[1]
            elif isinstance(item, tuple) and item[0] == "direction":
                clause.direction = item[1]
            elif isinstance(item, tuple) and item[0] == "back":
                clause.back = True
            elif isinstance(item, Where):
                clause.where = item
            elif isinstance(item, list):
                clause.objects += item
            elif isinstance(item, NounPhrase):
                clause.objects.append(item)
        return clause

    def src(self, items):
        return ("src", items[0])

    def dst(self, items):
        return ("dst", items[0])

    def _pour_parts(self, items) -> tuple[Clause, NounPhrase | None, NounPhrase | None]:
        """The clause without its ``from`` / ``into`` phrases, and those phrases."""
        c = self._clause("pour", [i for i in items if not (isinstance(i, tuple) and i[0] in ("src", "dst"))])
        src = next((i[1] for i in items if isinstance(i, tuple) and i[0] == "src"), None)
        dst = next((i[1] for i in items if isinstance(i, tuple) and i[0] == "dst"), None)
        return c, src, dst

    @staticmethod
    def _poured(c: Clause, source: NounPhrase | None, target: NounPhrase | None) -> Clause:
        c.source, c.target = source, target
        c.objects = [o for o in (source, target) if o is not None]
        return c

    def pour(self, items):
        c, source, target = self._pour_parts(items)
        direct = c.objects[0] if c.objects else None
        if direct is not None and set(direct.words) <= {"water", "contents", "some", "all"}:
            direct = None  # "pour water ...": the liquid, not an object
        if source is None and target is not None and direct is not None:
            source = direct  # "pour the bottle into the cup"
        elif target is None and direct is not None:
            target = direct  # "pour it from the bottle" (the target named first)
        return self._poured(c, source, target)

    def fill(self, items):
        # "fill the cup with water from the bottle": the filled object is the target.
        c, source, target = self._pour_parts(items)
        return self._poured(c, source, target or (c.objects[0] if c.objects else None))

    def pick(self, items):
        c = Clause(verb="pick")
        for np, arm in items:
            c.objects.append(np)
            c.arms.append(arm)
        return c

    def pick_up(self, items):
        c = self._clause("pick", items)
        c.arms = [c.arm]
        return c

    def place(self, items):
        return self._clause("place", items)

    def placement(self, items):
        return self._clause("place", items)

    def place_each(self, items):
        return list(items)

    def place_return(self, items):
        c = self._clause("place", items)
        c.back = True
        return c

    def handover(self, items):
        return self._clause("handover", items)

    def fold(self, items):
        return self._clause("fold", items)

    def move(self, items):
        c = self._clause("move", items)
        last = c.objects[-1] if c.objects else None
        # "move the tray forward" read as one phrase "tray forward": the last word is the direction.
        if not c.direction and last is not None and len(last.words) > 1 and last.of is None and last.words[-1] in _DIRECTIONS:
            c.objects[-1] = NounPhrase(words=last.words[:-1])
            c.direction = _DIRECTIONS[last.words[-1]]
        return c

    def stack(self, items):
        c = self._clause("place", items)
        c.where = Where("on_top", (c.objects.pop(),))
        return c

    def arrange(self, items):
        return self._clause("place", items)

    def step(self, items):
        return items[0]

    def step_arm(self, items):
        arm, clause = items[0], items[1]
        arm = arm[1] if isinstance(arm, tuple) else arm
        if isinstance(clause, list):
            return [self.step_arm([arm, c]) for c in clause]
        clause.arm = clause.arm or arm
        if clause.verb == "pick":
            clause.arms = [a or arm for a in clause.arms]
        if clause.verb == "handover" and not clause.giver:
            clause.giver = arm
        return clause

    def start(self, items):
        out = []
        for item in items:
            out += item if isinstance(item, list) else [item]
        return out


@lru_cache(maxsize=1)
def grammar_words() -> frozenset[str]:
    """The words the grammar spells out (its keywords), for spelling correction."""
    return frozenset(re.findall(r'"([a-z]+)"', GRAMMAR))


def prepare(instruction: str, vocabulary: frozenset[str] = frozenset(), objects: frozenset[str] = frozenset()) -> Rewritten:
    """The instruction normalised and rewritten into the grammar's phrasing (:mod:`~agentchord.agents.rules.phrasing`)."""
    return rewrite(normalise(instruction), vocabulary, objects)


def parse(instruction: str, vocabulary: frozenset[str] = frozenset(), objects: frozenset[str] = frozenset()) -> list[Clause]:
    """The clauses of an instruction, in order.

    Args:
        instruction: The words as written.
        vocabulary: Words known in the scene and to the rules (typos are corrected towards them).
        objects: Words that name scene objects (for ellipsis and declaratives).

    Raises:
        ParseError: Words the grammar cannot read (``words``) and what it expected there.
    """
    return parse_prepared(prepare(instruction, vocabulary, objects).text)


def parse_prepared(text: str) -> list[Clause]:
    """The clauses of an instruction already rewritten by :func:`prepare`."""
    clauses: list[Clause] = []
    # Sentences, and the steps a "then" starts, are parsed one at a time: Earley parsing
    # costs more than linearly in the length, and "then" never joins anything else.
    for sentence in text.split(" ; "):
        for piece in re.split(r"(?:\s*,)?(?:\s+and)?\s+then\s+(?:,\s*)?", f" {sentence} "):
            piece = re.sub(r"^(?:\s*,|\s*(?:and|then)\b)+|(?:\s*,|\s+and)+\s*$", "", f" {piece.strip()}").strip()
            if piece:
                clauses += _parse_sentence(piece)
    return clauses


def _parse_sentence(text: str) -> list[Clause]:
    try:
        tree = parser().parse(text)
    except UnexpectedInput as exc:
        column = max(0, getattr(exc, "column", 1) - 1) if not isinstance(exc, UnexpectedEOF) else len(text)
        expected = sorted(getattr(exc, "expected", None) or getattr(exc, "allowed", None) or [])
        if isinstance(exc, UnexpectedToken):
            column = max(0, exc.token.start_pos if exc.token.start_pos is not None else column)
        elif isinstance(exc, UnexpectedCharacters):
            column = exc.pos_in_stream
        raise ParseError(text, column, [str(e) for e in expected]) from None
    clauses: list[Clause] = []
    for child in tree.children:
        step = _ToClauses().transform(child)
        for clause in step if isinstance(step, list) else [step]:
            # The words of each clause, for messages and --explain.
            if getattr(child.meta, "start_pos", None) is not None:
                clause.text = clause.text or text[child.meta.start_pos : child.meta.end_pos]
            clauses.append(clause)
    return clauses
