"""Where an AgentChord recovery stops short: what the failure did not undo.

Two checks, both made with the graph's own node constraints (the sub-goals' definitions):

- **Sub-goal met.** Once what fell is at rest and no arm holds it, a recovery whose merge node
  holds already has nothing left to do: a bottle pulled out of the hand while being put down,
  and set down upright by the person, already meets "standing upright on the table, released".
- **Passed before the failure.** A nominal node whose constraints held at some tick of the edge
  into it was *passed*, even if a failure cut that edge short afterwards. A recovery that merges
  just before a passed node goes on past it when the node after it holds: a bottle taken out of
  the hand after the pour reached the cup, once regrasped upright, is put down, not poured again.

- **Placed by the fall.** The same test per object: a recovery's place of an object gets the merge
  node's constraints that read that object (:func:`attach_subgoal_checks`). With ``skip_if_placed``,
  the regrasp of an object that fell and settled where they all hold is not made and its place only
  retreats: a towel corner pulled out of the pinch as it was being laid on its top corner, which
  fell onto it, while the other arm is still laying its own corner (so the node as a whole does not
  hold yet).

A re-planning baseline judges what is achieved itself; a backtrack returns regardless. Only the
strategies with ``merges_met_subgoals`` use this.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

from agentchord.actions.library import Place
from agentchord.execution.edge_program import EdgeProgram
from agentchord.expr.compiler import CompiledExpr
from agentchord.graph.models import TaskGraph

#: Whether a node's constraints all hold now (False for a node without constraints: nothing to judge by).
NodeHolds = Callable[[str], bool]


class Ahead(NamedTuple):
    """Where a merged recovery goes on from, and what it skips on the way."""

    node: str
    passed: list[str]
    skipped: list[str]


@dataclass
class Shortcuts:
    """The nodes passed so far in one episode, and the two checks.

    Attributes:
        passed: Nominal nodes whose constraints held at some tick of the edge into them.
    """

    passed: set[str] = field(default_factory=set)

    def observe(self, program: EdgeProgram | None, holds: NodeHolds) -> None:
        """One tick: a running nominal edge whose target holds now has passed it."""
        if program is not None and program.kind == "nominal" and program.target not in self.passed and holds(program.target):
            self.passed.add(program.target)

    @staticmethod
    def met_merge(graph: TaskGraph, recovery: EdgeProgram, objects: Iterable[str],
                  holding: Iterable[tuple[str, str]], holds: NodeHolds) -> str | None:
        """The recovery's merge node if it holds already, else None.

        Only while no arm holds what the recovery grasps (``objects``): a hold caught again lower in
        the hand, or askew, may meet a node's ``holding`` constraint and still not be the hold the
        next edges need; the binding judges those (:mod:`agentchord.execution.binding`).
        """
        if recovery.kind != "recovery":
            return None
        grasped = set(objects)
        if any(obj in grasped for _, obj in holding):
            return None
        node = graph.node(recovery.target)
        return node.id if node.kind == "nominal" and holds(node.id) else None

    def ahead(self, graph: TaskGraph, nominal_next: dict[str, str], node_id: str, holds: NodeHolds) -> Ahead | None:
        """Where a recovery merged at ``node_id`` goes on from, when what lies ahead was done already.

        Walking the nominal path: while the next node was passed and the node after it holds now,
        both edges are skipped. Never into the goal, whose criterion is the task's.
        """
        here, passed, skipped = node_id, [], []
        while True:
            into = nominal_next.get(here)
            middle = graph.edge(into).target if into is not None else None
            out = nominal_next.get(middle) if middle in self.passed else None
            after = graph.edge(out).target if out is not None else None
            if after is None or after == graph.goal or not holds(after):
                break
            here = after
            assert into is not None and middle is not None and out is not None  # after was found through them
            passed.append(middle)
            skipped.extend([into, out])
        return Ahead(here, passed, skipped) if here != node_id else None


def attach_subgoal_checks(program: EdgeProgram, constraints: Sequence[CompiledExpr]) -> None:
    """Give each place in ``program`` the test of what its merge node's ``constraints`` ask of its object.

    Only the constraints that read the placed object count (``dist(towel_bl.pos, towel_tl.pos) -
    0.045``, ``holding(left, towel_bl) - 0.5``); a place whose object no constraint reads gets no
    test (nothing to judge by). The place consults it only with ``skip_if_placed``, and only for an
    object no arm holds.
    """
    for step in program.steps:
        for action in step:
            if not isinstance(action, Place):
                continue
            reading = [c for c in constraints if action.args.obj in c.objects]
            if reading:
                action.meets_subgoal = lambda frame, reading=reading: all(c.scalar(frame) <= 0.0 for c in reading)
