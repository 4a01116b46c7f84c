"""Ground an instruction in the scene: the offline composer's reading of English.

A small, explicit grammar, not a language model: the instruction is split into
clauses (``, then``, ``and then``, ``and``), each clause is matched against the
patterns below, and every noun phrase is resolved to a scene object by its name
or the words of its description (``the red block``). What no pattern matches, or
a noun phrase that names no object (or several), is an
:class:`~agentchord.agents.exceptions.InstructionNotGroundedError` that says which
words failed and suggests a goal spec or ``--reasoner llm``.
"""

from __future__ import annotations

import re
from collections.abc import Callable

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.observe import COLOURS
from agentchord.agents.reasoner import Scene
from agentchord.agents.rules.goals import Folded, Goal, GoalSpec, HandedOver, Inside, On, Placed, Poured
from agentchord.agents.rules.knowledge import BESIDE_DISTANCE, cloth_names
from agentchord.agents.rules.knowledge import words as kb_words

_ARTICLES = re.compile(r"\b(the|a|an|its|it's|some|water|of)\b")
_VERB = r"(?:pick|place|put|pour|hand|move|fold|stack|set|carry|bring|grasp|take|slide|insert|drop)\b"
_CLAUSE_SPLIT = re.compile(
    rf"\s*(?:,\s*and then|,\s*then|\band then\b|\bthen\b|;|,\s*and\b|\band\b(?= {_VERB})|,(?=\s*{_VERB}))\s*"
)
_ARM = r"(?:(?:with|using) (?:the )?(?P<arm>left|right) (?:arm|hand|gripper))"


class _Context:
    """What the clauses of one instruction share: the scene and the last objects named."""

    def __init__(self, scene: Scene, instruction: str) -> None:
        self.scene = scene
        self.instruction = instruction
        self.mentioned: list[str] = []
        self.held_by: dict[str, str] = {}

    def resolve(self, phrase: str) -> str:
        """The scene object a noun phrase names (pronouns name the last object mentioned)."""
        words = _ARTICLES.sub(" ", phrase.lower()).split()
        if not words:
            raise self.error(phrase, "names no object")
        if words in (["it"], ["one"]):
            if not self.mentioned:
                raise self.error(phrase, "'it' has nothing to refer to")
            return self.mentioned[-1]
        candidates = []
        for obj in self.scene.objects:
            if obj.name.lower() == "_".join(words) or all(w in kb_words(obj) for w in words):
                candidates.append(obj.name)
        if len(candidates) != 1:
            # The head noun alone (the last word) may still be unique: "coffee capsule" -> capsule.
            head = [o.name for o in self.scene.objects if words[-1] in kb_words(o)]
            # A colour that does not match is a contradiction, not a modifier to ignore.
            if len(candidates) == 0 and len(head) == 1 and not set(words[:-1]) & set(COLOURS):
                candidates = head
        if not candidates:
            raise self.error(phrase, f"names no scene object (the scene has {', '.join(self.scene.object_names)})")
        if len(candidates) > 1:
            raise self.error(phrase, f"is ambiguous: it could be {', '.join(candidates)}; name one by colour or name")
        self.mentioned.append(candidates[0])
        return candidates[0]

    def error(self, phrase: str, problem: str) -> InstructionNotGroundedError:
        return InstructionNotGroundedError(self.instruction, f"{phrase.strip()!r} {problem}")


Rule = tuple[re.Pattern[str], Callable[[re.Match[str], _Context], list[Goal]]]


def _pour(m: re.Match[str], ctx: _Context) -> list[Goal]:
    source, target = ctx.resolve(m["src"]), ctx.resolve(m["dst"])
    both = bool(re.search(r"\b(both arms|both hands|two arms|bimanual)", ctx.instruction.lower()))
    return [Poured(source=source, target=target, arm=m["arm"], hold_target=both)]


def _put_down(m: re.Match[str], ctx: _Context) -> list[Goal]:
    phrase = m["obj"].strip().lower()
    if phrase in ("both", "them", "both of them", "everything"):
        objects = list(dict.fromkeys(ctx.mentioned[-2:]))
    else:
        objects = [ctx.resolve(phrase)]
    return [Placed(obj=name) for name in objects]


def _beside(m: re.Match[str], ctx: _Context) -> list[Goal]:
    first, second, anchor = ctx.resolve(m["a"]), ctx.resolve(m["b"]), ctx.resolve(m["anchor"])
    # Table-setting convention: the first utensil named goes on the anchor's left (-x), the second on its right.
    return [
        Placed(obj=first, relative_to=anchor, offset=(-BESIDE_DISTANCE, 0.0), yaw=90.0),
        Placed(obj=second, relative_to=anchor, offset=(BESIDE_DISTANCE, 0.0), yaw=90.0),
    ]


def _pick(m: re.Match[str], ctx: _Context) -> list[Goal]:
    obj = ctx.resolve(m["obj"])
    if m["arm"]:
        ctx.held_by[obj] = m["arm"]
    return []


def _handover(m: re.Match[str], ctx: _Context) -> list[Goal]:
    obj = ctx.resolve(m["obj"])
    receiver = m["to"]
    giver = ctx.held_by.get(obj, "left" if receiver == "right" else "right")
    ctx.held_by[obj] = receiver
    return [HandedOver(obj=obj, giver=giver, receiver=receiver)]


def _into(m: re.Match[str], ctx: _Context) -> list[Goal]:
    obj, container = ctx.resolve(m["obj"]), ctx.resolve(m["dst"])
    return [Inside(obj=obj, container=container, arm=m["arm"] or ctx.held_by.get(obj))]


def _in_region(m: re.Match[str], ctx: _Context) -> list[Goal]:
    obj = ctx.resolve(m["obj"])
    region = _region(m["region"], ctx)
    return [Placed(obj=obj, region=region, arm=ctx.held_by.get(obj))]


def _on(m: re.Match[str], ctx: _Context) -> list[Goal]:
    obj, support = ctx.resolve(m["obj"]), ctx.resolve(m["dst"])
    return [On(obj=obj, support=support, arm=m["arm"])]


def _move_direction(m: re.Match[str], ctx: _Context) -> list[Goal]:
    obj = ctx.resolve(m["obj"])
    return [Placed(obj=obj, region=_region(m["dir"], ctx))]


def _fold(m: re.Match[str], ctx: _Context) -> list[Goal]:
    word = m["cloth"].strip().lower().split()[-1]
    cloths = cloth_names(ctx.scene.object_names)
    if word not in cloths:
        raise ctx.error(m["cloth"], f"is not a cloth of the scene (cloths: {', '.join(cloths) or 'none'})")
    ctx.mentioned += [f"{word}_{c}" for c in ("bl", "br", "tl", "tr")]
    return [Folded(cloth=word)]


def _region(phrase: str, ctx: _Context) -> str:
    words = _ARTICLES.sub(" ", phrase.lower()).split()
    for region in ctx.scene.regions:
        vocabulary = set(region.name.lower().replace("_", " ").split()) | set(region.description.lower().split())
        if all(w in vocabulary for w in words):
            return region.name
    names = ", ".join(r.name for r in ctx.scene.regions) or "none"
    raise ctx.error(phrase, f"names no region of the scene (regions: {names})")


_NP = r"(?P<{}>[\w\s-]+?)"
RULES: list[Rule] = [
    (re.compile(rf"^pour (?:water |the water |.*? )?from {_NP.format('src')} into {_NP.format('dst')}(?: {_ARM}| using both arms| with both arms)?$"), _pour),
    (re.compile(rf"^(?:put|set|place) {_NP.format('obj')} (?:back )?down$"), _put_down),
    (re.compile(rf"^(?:put|set|place) down {_NP.format('obj')}$"), _put_down),
    (re.compile(rf"^(?:rearrange|arrange|place|put|set) {_NP.format('a')} and {_NP.format('b')} (?:beside|next to|around|by) {_NP.format('anchor')}$"), _beside),
    (re.compile(rf"^(?:pick up|grasp|take|grab) {_NP.format('obj')}(?: {_ARM})?$"), _pick),
    (re.compile(rf"^hand {_NP.format('obj')} over to (?:the )?(?P<to>left|right) (?:arm|hand)$"), _handover),
    (re.compile(rf"^hand over {_NP.format('obj')} to (?:the )?(?P<to>left|right) (?:arm|hand)$"), _handover),
    (re.compile(rf"^(?:put|place|set) {_NP.format('obj')} (?:in|into|at|on) (?P<region>[\w\s]*region|[\w\s]*area|[\w\s]*zone)$"), _in_region),
    (re.compile(rf"^(?:put|place|drop|insert) {_NP.format('obj')} (?:into|in|inside) {_NP.format('dst')}(?: {_ARM})?$"), _into),
    (re.compile(rf"^(?:stack|put|place|set) {_NP.format('obj')} (?:on top of|onto|on) {_NP.format('dst')}(?: {_ARM})?$"), _on),
    (re.compile(rf"^(?:move|slide|carry|push) {_NP.format('obj')} (?P<dir>forward|backward|back|left|right)$"), _move_direction),
    (re.compile(r"^fold (?:the )?(?P<cloth>\w+)(?: in half)?(?:,? .*)?$"), _fold),
]


def ground_instruction(instruction: str, scene: Scene) -> GoalSpec:
    """The goal spec an instruction states about a scene.

    Args:
        instruction: English, e.g. ``Pour water from the bottle into the cup, then put the bottle down.``
        scene: The first observation (objects with names and descriptions, named regions).

    Raises:
        InstructionNotGroundedError: A clause matches no pattern, or a noun phrase names
            no scene object (or several); the message names the words and suggests
            ``--goal`` or ``--reasoner llm``.
    """
    text = instruction.strip().rstrip(".!").lower()
    text = re.sub(r"\s+", " ", text)
    ctx = _Context(scene, instruction)
    goals: list[Goal] = []
    for clause in filter(None, (c.strip(" ,") for c in _CLAUSE_SPLIT.split(text))):
        for pattern, build in RULES:
            match = pattern.match(clause)
            if match:
                goals += build(match, ctx)
                break
        else:
            raise InstructionNotGroundedError(instruction, f"no rule reads the clause {clause!r}")
    if not goals:
        raise InstructionNotGroundedError(instruction, "it states no goal (what should be true at the end?)")
    return GoalSpec(goals=goals)

