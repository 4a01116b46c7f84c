"""Goal specifications: what the offline composer plans for, as predicates over the scene.

A :class:`GoalSpec` is an ordered list of predicates (poured-into, placed, inside, on,
handed-over, folded) plus whether the arms end at home. The order is the order the
instruction states them in: the planner achieves them one after the other, keeping
what it achieved. Goal specs are written by hand (``--goal goal.yaml``) or grounded
from an instruction (:mod:`agentchord.agents.rules.instructions`).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from agentchord.expr.names import ObjectName

Arm = Literal["left", "right"]
#: A table position (m): finite, and on a table two arms can reach (generously).
Coordinate = Annotated[float, Field(allow_inf_nan=False, ge=-2.0, le=2.0)]
#: An offset from an anchor object (m).
Offset = Annotated[float, Field(allow_inf_nan=False, ge=-1.0, le=1.0)]
#: A yaw (deg), as the actions take it.
Yaw = Annotated[float, Field(allow_inf_nan=False, ge=-180.0, le=180.0)]


class _Goal(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    def objects(self) -> list[str]:
        """Scene objects the predicate names."""
        raise NotImplementedError


class Poured(_Goal):
    """``source``'s contents poured into ``target``.

    Attributes:
        source: The object poured from (a bottle, jug).
        target: The container poured into (a cup, glass).
        arm: The arm that pours; ``None`` lets the planner choose.
        hold_target: The other arm holds the target steady while pouring.
    """

    kind: Literal["poured"] = "poured"
    source: ObjectName
    target: ObjectName
    arm: Arm | None = None
    hold_target: bool = False

    def objects(self) -> list[str]:
        return [self.source, self.target]


class Placed(_Goal):
    """``obj`` stands on the table, released, at a place.

    Exactly one way of saying where, or none: ``region`` (a named region of the scene),
    ``at`` (absolute x, y), ``relative_to`` + ``offset`` (beside another object), or none
    of them: put it down where it was taken from (a free spot if that is taken).

    Attributes:
        obj: The object.
        region: Name of a scene region.
        at: Absolute table position (m).
        relative_to: Anchor object for ``offset``.
        offset: (dx, dy) from the anchor's centre (m).
        yaw: World yaw of the object's long axis once placed (deg); ``None``: any.
        arm: The arm that places it; ``None`` lets the planner choose.
    """

    kind: Literal["placed"] = "placed"
    obj: ObjectName
    region: str | None = None
    at: tuple[Coordinate, Coordinate] | None = None
    relative_to: ObjectName | None = None
    offset: tuple[Offset, Offset] = (0.0, 0.0)
    yaw: Yaw | None = None
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj] + ([self.relative_to] if self.relative_to else [])


class Inside(_Goal):
    """``obj`` released inside ``container`` (a capsule in a tray, a block in a cup)."""

    kind: Literal["inside"] = "inside"
    obj: ObjectName
    container: ObjectName
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj, self.container]


class On(_Goal):
    """``obj`` released on top of ``support`` (a stack)."""

    kind: Literal["on_top_of"] = "on_top_of"  # not "on": YAML reads a bare on as true
    obj: ObjectName
    support: ObjectName
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj, self.support]


class HandedOver(_Goal):
    """``obj`` passed from ``giver`` to ``receiver`` (the receiver closes before the giver opens)."""

    kind: Literal["handed_over"] = "handed_over"
    obj: ObjectName
    giver: Arm = "left"
    receiver: Arm = "right"

    def objects(self) -> list[str]:
        return [self.obj]


class Inserted(_Goal):
    """``obj`` inserted into ``into``'s opening along its axis, in mid-air: a peg into a socket, each held by one arm.

    The hands keep holding the mated pair: an insertion ends the task where it happens.

    Attributes:
        obj: The object inserted (held by ``arm``).
        into: The object with the opening (a socket, held by the other arm).
        arm: The arm that inserts; ``None`` lets the planner choose (the one that reaches ``obj``).
    """

    kind: Literal["inserted"] = "inserted"
    obj: ObjectName
    into: ObjectName
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj, self.into]


class Folded(_Goal):
    """A cloth folded in half: its near corners laid on its far corners.

    The cloth is seen through its corner points, named ``{cloth}_bl``, ``_br``,
    ``_tl`` and ``_tr`` (bottom = near the robot's front edge, top = far).
    """

    kind: Literal["folded"] = "folded"
    cloth: ObjectName

    def objects(self) -> list[str]:
        return [f"{self.cloth}_{c}" for c in ("bl", "br", "tl", "tr")]


Goal = Annotated[Poured | Placed | Inside | On | HandedOver | Inserted | Folded, Field(discriminator="kind")]
#: Every goal predicate, in the order the prompts list them.
GOAL_KINDS: tuple[type[_Goal], ...] = (Poured, Placed, Inside, On, HandedOver, Inserted, Folded)


def _kind_name(goal: type[_Goal]) -> str:
    """The ``kind`` a goal class is written with in a goal file."""
    return str(goal.model_fields["kind"].default)


class GoalSpec(BaseModel):
    """An ordered list of goal predicates.

    Attributes:
        goals: Predicates planned in this order, each kept once achieved. Two that meet at one object
            (two placements into one cup) are made one after the other; independent ones the two arms
            may make at once.
        home: Both arms end at home.
    """

    model_config = ConfigDict(extra="forbid")

    goals: list[Goal] = Field(min_length=1, max_length=64)
    home: bool = True

    @model_validator(mode="before")
    @classmethod
    def _kind_read_as_a_boolean(cls, data: object) -> object:
        # YAML reads a bare `on`, `yes` or `true` as a boolean: `kind: on` arrives as True.
        goals = data.get("goals") if isinstance(data, dict) else None
        for k, goal in enumerate(goals if isinstance(goals, list) else []):
            if isinstance(goal, dict) and isinstance(goal.get("kind"), bool):
                raise ValueError(f"goals[{k}].kind: YAML read it as {str(goal['kind']).lower()} (a bare on, yes or true is a "
                                 f"boolean there); the kinds are {', '.join(_kind_name(g) for g in GOAL_KINDS)} (on top of: on_top_of)")
        return data

    @model_validator(mode="after")
    def _coherent(self) -> GoalSpec:
        # Contradictions that no scene can satisfy; what needs the scene (sizes, which
        # objects are containers) is checked by agents.rules.feasibility.
        if problems := static_problems(self):
            raise ValueError("; ".join(problems))
        return self

    def objects(self) -> list[str]:
        """Every object the goals name, first mention first."""
        names: list[str] = []
        for goal in self.goals:
            names += [n for n in goal.objects() if n not in names]
        return names

    def outcome(self) -> frozenset[tuple]:
        """What the goals leave behind, whoever does it and in whatever order.

        Arms and ``home`` are left out: two specs with the same outcome ask for the same end
        state and events (the same pour, the same place to the centimetre), so one success
        check judges both.
        """
        keys = set()
        for goal in self.goals:
            fields = goal.model_dump(exclude={"arm"})
            keys.add(tuple(sorted((k, _rounded(v)) for k, v in fields.items())))
        return frozenset(keys)


def _rounded(value: object) -> object:
    # Places stated in metres compare to the centimetre; yaws to the degree.
    if isinstance(value, float):
        return round(value, 2)
    if isinstance(value, (tuple, list)):
        return tuple(_rounded(v) for v in value)
    return value


def _rests_on(goal: _Goal) -> tuple[str, str, str] | None:
    # (object, what it ends up resting on or in, the relation in words)
    if isinstance(goal, Inside):
        return goal.obj, goal.container, "inside"
    if isinstance(goal, On):
        return goal.obj, goal.support, "on top of"
    return None


def static_problems(spec: GoalSpec) -> list[str]:
    """Contradictions within a goal spec: an object in or on itself, or a cycle of stacking/containment.

    Returns:
        One line per problem, naming the goals (``goals[1]``); empty when coherent.
    """
    problems = []
    edges: dict[str, tuple[str, int, str]] = {}
    for index, goal in enumerate(spec.goals):
        relation = _rests_on(goal)
        if isinstance(goal, Poured) and goal.source == goal.target:
            problems.append(f"goals[{index}]: {goal.source!r} cannot be poured into itself")
        if isinstance(goal, Placed) and goal.relative_to == goal.obj:
            problems.append(f"goals[{index}]: {goal.obj!r} cannot be placed relative to itself")
        if isinstance(goal, Placed) and sum(x is not None for x in (goal.region, goal.at, goal.relative_to)) > 1:
            problems.append(f"goals[{index}]: say where {goal.obj!r} goes one way only: region, at or relative_to")
        if isinstance(goal, Inserted) and goal.obj == goal.into:
            problems.append(f"goals[{index}]: {goal.obj!r} cannot be inserted into itself")
        if isinstance(goal, HandedOver) and goal.giver == goal.receiver:
            problems.append(f"goals[{index}]: the {goal.giver} arm cannot hand {goal.obj!r} over to itself")
        if relation is None:
            continue
        obj, under, words = relation
        if obj == under:
            problems.append(f"goals[{index}]: {obj!r} cannot be {words} itself")
            continue
        edges[obj] = (under, index, words)
    reported: set[str] = set()
    for start in edges:
        chain, node = [start], edges[start][0]
        while node in edges and node not in chain:
            chain.append(node)
            node = edges[node][0]
        if node == start and not reported & set(chain):
            reported |= set(chain)
            steps = " ".join(f"{name} {edges[name][2]}" for name in chain) + f" {start}"
            indices = ", ".join(f"goals[{edges[name][1]}]" for name in chain)
            problems.append(f"{indices}: a cycle: {steps}; nothing can rest on or in what rests on or in it")
    return problems
