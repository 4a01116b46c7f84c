"""Ground an instruction in the scene: the offline composer's reading of English.

The words are parsed by the grammar of :mod:`agentchord.agents.rules.language` into
clauses (a verb, its noun phrases, an arm, a place); this module decides which goal predicates
each clause states, with what each noun phrase names in the scene read by
:mod:`agentchord.agents.rules.references`:

- objects by name, category word or synonym (``mug`` for a cup), colour, size (``the tall
  bottle``, ``the small block``, ``the big one``: of the kind last named), or a pronoun for the
  last one mentioned (``it``; in ``put it down``, the object last taken in hand; ``both``,
  ``them``: the objects of the instruction so far);
- the table, which every scene has, and its regions (sides, edges, corners, centre), and
  places relative to objects (in front of, behind, next to, left or right of, between);
- the scene's named regions (``the target region``, ``forward``);
- arms: ``left``, ``right``, ``both`` or unsaid (the planner chooses); an arm that picks an
  object up is the arm that pours, places or hands it over later.

What cannot be read is an :class:`~agentchord.agents.exceptions.InstructionNotGroundedError`
naming the exact words, the closest instructions that would be understood in this scene,
and the goal-spec alternative.
"""

from __future__ import annotations

import re

import difflib
from dataclasses import dataclass, field

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.observe import COLOURS
from agentchord.agents.scene import Scene
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.goals import Folded, Goal, GoalSpec, HandedOver, Inserted, Inside, Placed, Poured
from agentchord.agents.rules.language import Clause, NounPhrase, ParseError, grammar_words, parse_prepared, prepare
from agentchord.agents.rules.phrasing import Rewritten, known_words as phrasing_words
from agentchord.agents.rules.placing import SPOT_WORDS, direction_region, place_at
from agentchord.agents.rules.references import (
    CLOTH_PART_WORDS,
    CLOTH_SIDE_WORDS,
    FILLER_WORDS,
    GROUP_WORDS,
    POSITION_WORDS,
    SIZE_WORDS,
    Context,
)
from agentchord.robot.aloha import other_arm
from agentchord.agents.rules.discourse import NotAGoalError

@dataclass
class Reading:
    """What the composer read: the clauses, the goal predicates each one states, and how each phrase was read.

    Attributes:
        instruction: The words as written.
        clauses: The grammar's clauses (a last one puts back down what is still in hand).
        goals: The goal predicates of each clause.
        prepared: The text the grammar parsed and what was rewritten on the way.
        words: How each phrase was read: (words, role, what): role is ``object``, ``place``, ``arm`` or ``verb``.
    """

    instruction: str
    clauses: list[Clause]
    goals: list[list[Goal]] = field(default_factory=list)
    prepared: Rewritten | None = None
    words: list[tuple[str, str, str]] = field(default_factory=list)

    @property
    def goal(self) -> GoalSpec:
        # A goal said twice ("fold the towel in half, near edge onto far edge") is one goal.
        goals = [g for part in self.goals for g in part]
        placed = {g.obj for g in goals if isinstance(g, Placed) and not _put_down(g)}

        def said(k: int, g: Goal) -> bool:
            # "carry the tray forward, then put it down": the put-down is the placement already said.
            return g in goals[:k] or (_put_down(g) and g.obj in placed)

        # "put them down, and the cup a bit to the left": the cup's put-down is its placement, in the put-downs' turn
        # (a run of put-downs states no order: the one with a place said goes first).
        kept = [g for k, g in enumerate(goals) if not said(k, g)]
        out: list[Goal] = []
        for k, g in enumerate(goals):
            if _put_down(g) and g.obj in placed and g not in goals[:k]:
                later = next((p for p in goals[k + 1:] if isinstance(p, Placed) and p.obj == g.obj and not _put_down(p)), None)
                if later is not None and later not in out:
                    run = len(out)
                    while run > 0 and _put_down(out[run - 1]):
                        run -= 1
                    out.insert(run, later)
            elif g in kept and g not in out:
                out.append(g)
        return GoalSpec(goals=out)


def _put_down(goal: Goal) -> bool:
    """A placement with no place: the object put down where it was."""
    return isinstance(goal, Placed) and goal.at is None and goal.region is None and goal.relative_to is None


def _poured_into(c: Clause, ctx: Context) -> str:
    """What a pour pours into: the vessel said, else the one container in hand (or the scene's one) that is no vessel
    to pour from ("grab the cup and the bottle and pour")."""
    if c.target is not None:
        if c.target.pronoun and c.source is None and re.search(r"\bwater\b", c.text) \
                and not any(kb.is_pourable(ctx.objects[o]) for o in ctx.held_by):
            # "move the cup next to the bottle, then pour some water in it": the water said and no source, the source is
            # the scene's vessel to pour from, so "it" is not that vessel but what was named before it. (Without the
            # water said, "pour into it" keeps the plain reading: "it" may be the vessel just named, to pour from.)
            return ctx.resolve(c.target, exclude=tuple(o.name for o in ctx.scene.objects if kb.is_pourable(o)))
        return ctx.resolve(c.target)
    held = [o for o in [*ctx.held_by, *ctx.in_hand] if kb.is_container(ctx.objects[o]) and not kb.is_pourable(ctx.objects[o])]
    scene = [o.name for o in ctx.scene.objects if kb.is_container(o) and not kb.is_pourable(o)]
    into = list(dict.fromkeys(held)) or scene
    if len(into) != 1 or c.source is None and not any(kb.is_pourable(o) for o in ctx.scene.objects):
        raise ctx.error(c.text, "does not say what to pour into (say 'into the cup')")
    ctx.note(c.text, "object", f"poured into: {into[0]}")
    return ctx.mention(into[0])


def _pour(c: Clause, ctx: Context) -> list[Goal]:
    target = _poured_into(c, ctx)
    if c.source is not None:
        source = ctx.resolve(c.source)
    else:
        held = [o for o in ctx.held_by if kb.is_pourable(ctx.objects[o])]
        vessels = held or [o.name for o in ctx.scene.objects if kb.is_pourable(o) and o.name != target]
        if len(vessels) != 1:
            raise ctx.error(c.text, "does not say what to pour from (say 'from the bottle')")
        source = ctx.mention(vessels[0])
        ctx.mention(target)
    hold_target = c.arm == "both" or target in ctx.held_by or target in ctx.in_hand  # a cup picked up is poured into in hand
    arm = ctx.arm_of(c.arm, source)
    if hold_target and target not in ctx.in_hand:
        ctx.take(target)  # the other arm holds it: it is put down too
    ctx.take(source)
    if arm in ("left", "right"):  # who holds what, for "both of you set them down"
        ctx.pour_arms[source] = arm
        if hold_target and target not in ctx.held_by:
            ctx.pour_arms[target] = other_arm(arm)
    return [Poured(source=source, target=target, arm=arm, hold_target=hold_target)]


def _cloth_of(np: NounPhrase, ctx: Context) -> str | None:
    """The cloth a phrase names a part of (``the bottom corners of the towel``, ``its top corners``), if any."""
    words = [kb.SYNONYMS.get(w, w) for w in np.words]
    if not words or words[-1] not in CLOTH_PART_WORDS or not set(words[:-1]) <= CLOTH_SIDE_WORDS:
        return None
    if np.of is not None:
        of = [kb.SYNONYMS.get(w, w) for w in np.of.words]
        return next((c for c in ctx.cloths if c in of), ctx.cloths[0] if np.of.pronoun and len(ctx.cloths) == 1 else None)
    return ctx.cloths[0] if len(ctx.cloths) == 1 else None


def _pick(c: Clause, ctx: Context) -> list[Goal]:
    for np, arm in zip(c.objects, c.arms or [c.arm] * len(c.objects), strict=False):
        if (cloth := _cloth_of(np, ctx)) is not None:
            ctx.cloth_taken = cloth
            ctx.note(np.text, "object", f"a part of the {cloth}")
            continue
        for name in ctx.resolve_all(np):
            if arm in ("left", "right"):
                ctx.held_by[name] = arm
            ctx.take(name)
    return []


def _handover(c: Clause, ctx: Context) -> list[Goal]:
    obj = ctx.resolve(c.objects[0])
    obj_ = ctx.objects[obj]
    giver = c.giver if c.giver in ("left", "right") else None
    receiver = c.receiver if c.receiver in ("left", "right") else None
    giver = giver or ctx.held_by.get(obj) or (other_arm(receiver) if receiver else kb.near_arm(obj_))
    receiver = receiver or other_arm(giver)
    if giver == receiver:
        raise ctx.error(c.text, f"hands the {obj} from the {giver} arm to itself")
    ctx.held_by[obj] = receiver
    ctx.take(obj)
    return [HandedOver(obj=obj, giver=giver, receiver=receiver)]


def _fold(c: Clause, ctx: Context) -> list[Goal]:
    np = c.objects[0]
    words = [kb.SYNONYMS.get(w, w) for w in np.words]
    cloth = next((w for w in reversed(words) if w in ctx.cloths), None)
    if cloth is None and len(ctx.cloths) == 1 and words and words[-1] == "towel":
        cloth = ctx.cloths[0]
    if cloth is None and np.pronoun == "it" and ctx.cloth_taken:
        cloth = ctx.cloth_taken  # "grab the near corners, fold it": the cloth whose part is in hand
    if cloth is None and np.pronoun == "it" and not ctx.mentioned and len(ctx.cloths) == 1:
        cloth = ctx.cloths[0]  # "fold it" with nothing named before: the scene's one cloth is all a fold can mean
    if cloth is None:
        raise ctx.error(np.text, f"is not a cloth of the scene (cloths: {', '.join(ctx.cloths) or 'none'})")
    for corner in kb.CLOTH_CORNERS:
        ctx.mention(f"{cloth}_{corner}")
    return [Folded(cloth=cloth)]


def _folds(c: Clause, ctx: Context) -> str | None:
    """The cloth a clause folds by laying one part of it on another (``lay the bottom corners of the towel on its top corners``)."""
    if c.where is None or not c.where.phrases:
        return None
    target = c.where.phrases[0]
    if c.where.relation == "on_top" and target.of is not None and target.words == ("top",):
        target = target.of
    moved = [_cloth_of(np, ctx) if not np.pronoun else ctx.cloth_taken for np in c.objects]
    cloth = moved[0] if moved and len(set(moved)) == 1 else None
    if cloth is None or _cloth_of(target, ctx) != cloth:
        return None
    # The one fold the rules make lays the near part (both near corners, the near edge or half) on the far one;
    # a single corner laid on another, or a side on the other side, is another fold: refused, not read as this one.
    moved_words = {kb.SYNONYMS.get(w, w) for np in c.objects if not np.pronoun for w in np.words}
    target_words = {kb.SYNONYMS.get(w, w) for w in target.words}
    sides = {"left", "right"}
    if moved_words & sides or target_words & sides or "top" in moved_words or "top" not in target_words \
            or (moved_words and "bottom" not in moved_words):
        raise ctx.error(c.text, f"lays a part of the {cloth} on another part, not its near edge on its far edge "
                                "(both near corners onto the far ones): the only fold the rules make")
    return cloth


def _place(c: Clause, ctx: Context) -> list[Goal]:
    if (cloth := _folds(c, ctx)) is not None:
        ctx.note(c.text, "verb", f"fold the {cloth} (one part laid on another)")
        return [Folded(cloth=cloth)]
    names = list(dict.fromkeys(n for np in c.objects for n in ctx.resolve_put_down(np)))
    ctx.in_hand = [n for n in ctx.in_hand if n not in names]
    goals = place_at(names, c.where, c, ctx)
    ctx.touched.update(names)
    return goals


def _move(c: Clause, ctx: Context) -> list[Goal]:
    if (cloth := _folds(c, ctx)) is not None:
        return [Folded(cloth=cloth)]
    names = [n for np in c.objects for n in ctx.resolve_put_down(np)]
    ctx.in_hand = [n for n in ctx.in_hand if n not in names]
    ctx.touched.update(names)
    if c.direction and c.where is not None and c.where.relation == "at" and c.where.phrases[0].of is None \
            and set(c.where.phrases[0].words) <= SPOT_WORDS:
        # "carry it forward to the spot": the place the direction names, the scene's region of that name.
        region = direction_region(c.direction, ctx)
        if region is None:
            raise ctx.error(c.text, f"names a spot {c.direction} but the scene has no region there")
        return [Placed(obj=n, region=region, arm=ctx.arm_of(c.arm, n)) for n in names]
    if c.where is not None or not c.direction:
        return place_at(names, c.where, c, ctx)
    goals: list[Goal] = []
    for name in names:
        # A scene region the direction names ("forward" in the coffee scene) is where it goes.
        region = direction_region(c.direction, ctx)
        if region is not None:
            goals.append(Placed(obj=name, region=region, arm=ctx.arm_of(c.arm, name)))
            continue
        if c.direction == "front":
            # "to the front" is the table's near edge to the robot, and forward to whoever faces it: only a scene region
            # called the front says which.
            raise ctx.error(c.text, "says 'to the front': towards you (the table's near edge) or away from you? "
                                    "say 'forward' or 'to the front edge of the table'")
        obj = ctx.objects[name]
        ux, uy = kb.DIRECTION_WORDS[c.direction]
        point = (round(obj.pos[0] + ux * kb.NUDGE, 3), round(obj.pos[1] + uy * kb.NUDGE, 3))
        goals.append(Placed(obj=name, at=point, arm=ctx.arm_of(c.arm, name)))
    return goals


_BUILD = {"pour": _pour, "pick": _pick, "place": _place, "handover": _handover, "fold": _fold, "move": _move}


def read_instruction(instruction: str, scene: Scene) -> Reading:
    """The clauses of an instruction and the goal predicates each one states in ``scene``.

    Raises:
        InstructionNotGroundedError: Words the grammar cannot read, or a noun phrase that
            names no scene object (or several); the message names the words, the closest
            instructions understood in this scene, and the goal-spec alternative.
    """
    known, objects = vocabulary(scene)
    try:
        prepared = prepare(instruction, known, objects)
    except NotAGoalError as exc:
        raise InstructionNotGroundedError(instruction, str(exc)) from None
    try:
        clauses = parse_prepared(prepared.text)
    except ParseError as exc:
        raise InstructionNotGroundedError(instruction, _not_understood(exc, scene)) from None
    ctx = Context(scene, instruction)
    reading = Reading(instruction, clauses, prepared=prepared, words=ctx.read)
    for text in dict.fromkeys(c.text for c in clauses):
        unread = _unread_words(text, [c for c in clauses if c.text == text], known)
        if unread is not None:
            raise InstructionNotGroundedError(instruction, f"no rule reads {unread!r} in the clause {text!r} (what it names would be lost)")
    for clause in clauses:
        reading.goals.append([_into_socket(goal, ctx) for goal in _BUILD[clause.verb](clause, ctx)])
        if clause.arm or clause.giver or clause.receiver:
            for role, arm in (("arm", clause.arm), ("from", clause.giver), ("to", clause.receiver)):
                if arm:
                    ctx.note(f"{role} arm", "arm", arm)
    if not any(reading.goals):
        raise InstructionNotGroundedError(instruction, "it states no goal (what should be true at the end? e.g. where to put what is picked up)")
    # What is still in hand is put back where it was: the arms end at home, empty.
    rest = [Placed(obj=n, arm=ctx.held_by.get(n)) for n in ctx.in_hand if n in ctx.objects and not kb.is_cloth_corner(n)]
    if rest:
        reading.clauses.append(Clause(verb="place", text="(still in hand: put back where it was)", objects=[NounPhrase(words=(g.obj,)) for g in rest]))
        reading.goals.append(rest)
    return reading


def _unread_words(text: str, clauses: list[Clause], known: frozenset[str]) -> str | None:
    """A word of a clause's text that no rule knows and no part of its parse holds ("the marked circle on the
    right": the grammar kept "on the right" and passed over the circle), so the goal would silently lose it."""
    parsed: set[str] = set()
    for clause in clauses:
        phrases = [*clause.objects, *(clause.where.phrases if clause.where is not None else ()), clause.source, clause.target]
        for np in phrases:
            while np is not None:
                parsed.update(np.words)
                np = np.of
    unread = [w for w in re.findall(r"[a-z]+", text) if w not in known and w not in parsed and w not in FILLER_WORDS]
    return " ".join(dict.fromkeys(unread)) or None


def _into_socket(goal: Goal, ctx: Context) -> Goal:
    """"Put X into Y" where Y is a socket (its opening at its ends, not on top): X is inserted, in the air."""
    if isinstance(goal, Inside) and goal.container in ctx.objects and kb.is_socket(ctx.objects[goal.container]):
        return Inserted(obj=goal.obj, into=goal.container, arm=goal.arm)
    return goal


_VOCABULARY: dict[tuple[str, ...], tuple[frozenset[str], frozenset[str]]] = {}


def vocabulary(scene: Scene) -> tuple[frozenset[str], frozenset[str]]:
    """The words the rules and ``scene`` know (spelling is corrected towards them), and the words naming its objects."""
    key = tuple(sorted(f"{o.name}:{o.description}" for o in scene.objects) + sorted(f"{r.name}:{r.description}" for r in scene.regions))
    if key not in _VOCABULARY:
        names = {w for o in scene.objects for w in kb.words(o)} | {o.name for o in scene.objects}
        regions = {w for r in scene.regions for w in f"{r.name} {r.description}".lower().replace("_", " ").split()}
        objects = {w for w in names if w not in COLOURS and w not in SIZE_WORDS and not kb.is_cloth_corner(f"x_{w}")}
        objects |= {k for k, v in kb.SYNONYMS.items() if v in objects} | {g for g, kinds in GROUP_WORDS.items() if kinds & objects}
        objects |= {w + "s" for w in objects}
        known = (names | regions | objects | set(COLOURS) | set(SIZE_WORDS) | FILLER_WORDS | kb.TABLE_WORDS | kb.PART_WORDS
                 | set(kb.DIRECTION_WORDS) | set(kb.SYNONYMS) | CLOTH_PART_WORDS | CLOTH_SIDE_WORDS | set(POSITION_WORDS) | grammar_words()
                 | set(kb.CONTAINER_WORDS) | set(kb.POURABLE_WORDS) | set(GROUP_WORDS))
        _VOCABULARY[key] = (frozenset(known | phrasing_words()), frozenset(objects))
    return _VOCABULARY[key]


def ground_instruction(instruction: str, scene: Scene) -> GoalSpec:
    """The goal spec an instruction states about a scene (see :func:`read_instruction`)."""
    return read_instruction(instruction, scene).goal


# --- refusals that help ---------------------------------------------------------------------


def examples(scene: Scene) -> list[str]:
    """Instructions this reader understands in ``scene``, built from its objects (for refusals and docs)."""
    objects = [o for o in scene.objects if not kb.is_cloth_corner(o.name)]
    names = [o.name.replace("_", " ") for o in objects]
    out: list[str] = []
    vessels = [o.name for o in objects if kb.is_pourable(o)]
    containers = [o.name for o in objects if kb.is_container(o)]
    for v in vessels:
        for c in containers:
            out.append(f"pour water from the {v} into the {c}")
    for c in kb.cloth_names(o.name for o in scene.objects):
        out.append(f"fold the {c} in half")
    for n in names:
        out += [f"pick up the {n} with the left arm", f"put the {n} on the left side of the table",
                f"hand the {n} over to the right arm", f"move the {n} forward"]
    for r in scene.regions:
        out += [f"place the {names[0]} in the {r.name} region"] if names else []
    for c in containers:
        out += [f"put the {n} into the {c.replace('_', ' ')}" for n in names if n != c.replace("_", " ")]
    if len(names) >= 2:
        out += [f"stack the {names[0]} on the {names[1]}", f"put the {names[0]} next to the {names[1]}"]
    return out


def _not_understood(exc: ParseError, scene: Scene) -> str:
    words = exc.words
    # The clause the unread words belong to: from the last separator before them to the next one.
    start = max(exc.text.rfind(sep, 0, exc.column + 1) for sep in (" , ", " ; ", " then ", " and "))
    clause = exc.text[start:].split(" , ")[0].split(" then ")[0].strip(" ,;") if start >= 0 else exc.text
    clause = clause.removeprefix("then ").removeprefix("and ").strip() or words
    close = difflib.get_close_matches(clause, examples(scene), n=2, cutoff=0.0)
    return f"no rule reads the clause {clause!r}: not understood: {words!r}; closest understood: " + "; ".join(repr(c) for c in close)
