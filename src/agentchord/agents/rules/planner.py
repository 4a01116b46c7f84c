"""A small STRIPS planner: ground operators, A* over sets of facts, then a two-arm schedule.

The offline composer's plans are short (under twenty operators) over a few dozen
ground operators, so a best-first search of our own is faster and clearer than a
round trip through PDDL files; see docs/design-choices.md. Facts are tuples of
strings (``("holding", "right", "bottle")``). An operator's ``delete`` may hold
patterns with ``"*"`` that match any value in that place.

A plan is a total order; :func:`schedule` turns it into rounds of at most one operator
per arm, so that independent operators of the two arms run at once (a two-arm step).
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from agentchord.agents.exceptions import PlanningError

Fact = tuple[str, ...]
State = frozenset[Fact]


@dataclass(frozen=True)
class Operator:
    """A ground operator: preconditions, effects, cost, and the edge steps that realise it.

    Attributes:
        name: Readable name with its arguments (``grasp(right, bottle)``).
        arms: Arms the operator moves.
        objects: Objects it touches (for the schedule's dependencies).
        pre: Facts that must hold.
        pre_not: Facts that must not hold.
        add: Facts it makes true.
        delete: Facts (or patterns with ``*``) it makes false.
        cost: Expected control ticks.
        steps: The edge's steps, each ``{arm: {"fn": ..., "args": {...}}}``.
        semantic: What holds afterwards, in words.
        skill: The skill it instantiates (``grasp``, ``pour``, ...).
        spot: The table point (m) a place sets its object down on, where known. Two operators whose
            spots are closer than ``PARALLEL_CLEARANCE`` never share a round.
    """

    name: str
    arms: tuple[str, ...]
    objects: tuple[str, ...]
    pre: frozenset[Fact]
    add: frozenset[Fact]
    delete: frozenset[Fact] = frozenset()
    pre_not: frozenset[Fact] = frozenset()
    cost: float = 100.0
    steps: tuple = ()
    semantic: str = ""
    skill: str = ""
    spot: tuple[float, float] | None = None

    def applicable(self, state: State) -> bool:
        """Whether the preconditions hold in ``state``."""
        return self.pre <= state and not (self.pre_not & state)

    def apply(self, state: State) -> State:
        """The state after the operator."""
        kept = frozenset(f for f in state if not any(_matches(pattern, f) for pattern in self.delete))
        return kept | self.add


def _matches(pattern: Fact, fact: Fact) -> bool:
    return len(pattern) == len(fact) and all(p == "*" or p == v for p, v in zip(pattern, fact, strict=True))


@dataclass
class Plan:
    """A plan and the states along it.

    Attributes:
        operators: In order.
        states: ``states[0]`` is the initial state, ``states[i + 1]`` the state after ``operators[i]``.
        expanded: States the search expanded (for the benchmark).
    """

    operators: list[Operator]
    states: list[State]
    expanded: int = 0

    @property
    def cost(self) -> float:
        """Sum of the operators' costs."""
        return sum(op.cost for op in self.operators)


def plan(initial: Iterable[Fact], goal: Iterable[Fact], operators: Sequence[Operator], max_expanded: int = 50_000) -> Plan:
    """The cheapest plan from ``initial`` to a state that contains every ``goal`` fact.

    A* with the number of unmet goal facts times the cheapest operator as the heuristic
    (admissible: one operator adds at least one of them). Ties break by insertion order,
    so the same problem always gives the same plan.

    Raises:
        PlanningError: No plan within ``max_expanded`` states; names the unmet goal facts.
    """
    start: State = frozenset(initial)
    goal = frozenset(goal)
    if not operators:
        cheapest = 1.0
    else:
        cheapest = max(1.0, min(op.cost for op in operators))

    def h(state: State) -> float:
        return cheapest * len(goal - state)

    counter = itertools.count()
    frontier: list[tuple[float, int, float, State]] = [(h(start), next(counter), 0.0, start)]
    came_from: dict[State, tuple[State, Operator] | None] = {start: None}
    best: dict[State, float] = {start: 0.0}
    expanded = 0
    while frontier:
        _, _, g, state = heapq.heappop(frontier)
        if g > best.get(state, float("inf")):
            continue
        if goal <= state:
            return _unwind(came_from, state, expanded)
        expanded += 1
        if expanded > max_expanded:
            break
        for op in operators:
            if not op.applicable(state):
                continue
            nxt = op.apply(state)
            cost = g + op.cost
            if cost < best.get(nxt, float("inf")):
                best[nxt] = cost
                came_from[nxt] = (state, op)
                heapq.heappush(frontier, (cost + h(nxt), next(counter), cost, nxt))
    unmet = sorted(" ".join(f) for f in goal - start)
    raise PlanningError(f"no sequence of skills reaches {', '.join(unmet) or 'the goal'} ({expanded} states searched)")


def _unwind(came_from: dict[State, tuple[State, Operator] | None], state: State, expanded: int) -> Plan:
    ops: list[Operator] = []
    states = [state]
    link = came_from[state]
    while link is not None:
        previous, op = link
        ops.append(op)
        states.append(previous)
        link = came_from[previous]
    return Plan(list(reversed(ops)), list(reversed(states)), expanded)


@dataclass
class Round:
    """Operators that run at once: at most one per arm.

    Attributes:
        operators: The operators, merged into one edge.
    """

    operators: list[Operator] = field(default_factory=list)

    @property
    def arms(self) -> set[str]:
        """Arms the round moves."""
        return {arm for op in self.operators for arm in op.arms}

    @property
    def steps(self) -> list[dict]:
        """The merged steps: step k of every operator runs together."""
        merged: list[dict] = []
        for op in self.operators:
            for k, step in enumerate(op.steps):
                if k == len(merged):
                    merged.append({})
                merged[k].update(step)
        return merged


def schedule(plan_: Plan, initial: State) -> tuple[list[Round], list[State]]:
    """Rounds of independent operators of different arms, and the state after each round.

    Operator ``j`` depends on an earlier ``i`` when they share an arm or a moved object,
    ``i`` adds a fact ``j`` needs or deletes one that must not hold for ``j``, or either
    deletes a fact the other needs. Each operator goes to the round after its latest
    dependency (as soon as possible); two operators share a round only when they have the
    same number of steps, so that their steps pair up. The rounds' order applied to the
    initial state is checked against the operators' preconditions.
    """
    level: list[int] = []
    for j, op in enumerate(plan_.operators):
        deps = [
            level[i]
            for i, other in enumerate(plan_.operators[:j])
            if set(op.arms) & set(other.arms) or set(op.objects) & set(other.objects) or other.add & op.pre or _interfere(other, op)
            or _unblocks(other, op)
        ]
        level.append(max(deps) + 1 if deps else 0)
    rounds: list[Round] = []
    for lvl in range(max(level, default=-1) + 1):
        members = [op for op, lv in zip(plan_.operators, level, strict=True) if lv == lvl]
        group: list[Round] = []
        for op in members:
            fit = next((r for r in group if not (r.arms & set(op.arms))
                        and all(len(o.steps) == len(op.steps) and _apart(o, op) for o in r.operators)), None)
            if fit is None:
                group.append(Round([op]))
            else:
                fit.operators.append(op)
        rounds += group
    states = [initial]
    for rnd in rounds:
        state = states[-1]
        for op in rnd.operators:
            if not op.applicable(state):
                # A parallel round that breaks a precondition: fall back to the plan's order.
                return [Round([o]) for o in plan_.operators], plan_.states
        for op in rnd.operators:
            state = op.apply(state)
        states.append(state)
    return rounds, states


#: Distance (m) two places' table points must keep to be made at once: a wrist and its open fingers
#: are about 8 cm across, so two hands closer would meet (two grasps go down on objects already apart).
PARALLEL_CLEARANCE = 0.12


def _apart(a: Operator, b: Operator) -> bool:
    """Whether two operators set their objects down far enough apart to run at once (unknown spots are apart)."""
    if a.spot is None or b.spot is None:
        return True
    return ((a.spot[0] - b.spot[0]) ** 2 + (a.spot[1] - b.spot[1]) ** 2) ** 0.5 >= PARALLEL_CLEARANCE


def _unblocks(a: Operator, b: Operator) -> bool:
    """Whether ``a`` deletes a fact that must not hold for ``b`` (the bottle untilted before the cup under it moves)."""
    return any(_matches(p, f) for p in a.delete for f in b.pre_not)


def _interfere(a: Operator, b: Operator) -> bool:
    """Whether one operator deletes a precondition of the other."""
    return any(_matches(p, f) for p in a.delete for f in b.pre) or any(_matches(p, f) for p in b.delete for f in a.pre)
