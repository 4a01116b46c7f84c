"""Ground truth of what a task has achieved so far: the event goals (a pour, a handover).

A re-planning LLM reads what already happened from its history (Inner Monologue's
scripted "scene description" in simulation). Events cannot be seen in a later
observation, so they are watched every tick on the feature frame, with the composer's
own tolerances; state goals (an object placed, a corner folded) the planner reads from the
observation when it re-plans.
"""

from __future__ import annotations

from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.goals import GoalSpec, HandedOver, Poured
from agentchord.expr import CompiledExpr, Vocabulary, compile_expr
from agentchord.features.frame import FeatureFrame


class GoalEvents:
    """Which event goals of a goal spec have happened.

    Args:
        goal: The task's goal spec.
        objects: The scene's object names.

    Attributes:
        achieved: Indices (into ``goal.goals``) of the event goals that happened.
    """

    def __init__(self, goal: GoalSpec, objects: list[str]) -> None:
        vocabulary = Vocabulary(frozenset(objects))
        self.achieved: set[int] = set()
        # Per event goal: alternatives, each a list of expressions that all hold (<= 0) when it happens.
        self._tests: dict[int, list[list[CompiledExpr]]] = {}
        # A handover needs its giver to have held the object first.
        self._given: dict[int, CompiledExpr] = {}
        self._held_by_giver: set[int] = set()
        for index, g in enumerate(goal.goals):
            if isinstance(g, Poured):
                s, c = g.source, g.target
                arms = [g.arm] if g.arm else ["left", "right"]
                self._tests[index] = [
                    [compile_expr(e, vocabulary) for e in (f"0.5 - holding({arm}, {s})", f"{kb.POUR_MIN_TILT:g} - tilt({s})",
                                                             f"norm(xy({s}.top - {c}.top)) - 0.5 * {c}.extent[0] - 0.01")]
                    for arm in arms
                ]
            elif isinstance(g, HandedOver):
                o = g.obj
                self._given[index] = compile_expr(f"0.5 - holding({g.giver}, {o})", vocabulary)
                self._tests[index] = [[compile_expr(e, vocabulary) for e in (f"0.5 - holding({g.receiver}, {o})", f"holding({g.giver}, {o}) - 0.5")]]

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick."""
        for index, alternatives in self._tests.items():
            if index in self.achieved:
                continue
            if index in self._given:
                if self._given[index].scalar(frame) <= 0.0:
                    self._held_by_giver.add(index)
                if index not in self._held_by_giver:
                    continue
            if any(all(e.scalar(frame) <= 0.0 for e in tests) for tests in alternatives):
                self.achieved.add(index)
