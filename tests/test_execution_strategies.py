"""Recovery strategies: a failed skill taken as an anticipated failure (the base rule AgentChord uses)."""

from types import SimpleNamespace

import pytest

from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.strategies import make_strategy
from agentchord.expr import Vocabulary
from agentchord.features.frame import make_static_frame
from agentchord.monitor import EdgeMonitors, RecoveryMap
from agentchord.library import load_task_graph


def _context(task: str, holding: set[tuple[str, str]] | None = None) -> SimpleNamespace:
    """What ``on_program_failure`` reads of the executor, for a library graph."""
    graph = load_task_graph(task)
    vocabulary = Vocabulary(frozenset(graph.objects))
    objects = {name: {"pos": (0.0, 0.6, 0.05)} for name in graph.objects}
    return SimpleNamespace(
        graph=graph,
        monitors={edge.id: EdgeMonitors.compile(edge, vocabulary) for edge in graph.edges},
        recovery_map=RecoveryMap(graph),
        frame=make_static_frame(objects, holding=holding or set()),
        world=SimpleNamespace(tick=42),
    )


def _failed(context: SimpleNamespace, edge_id: str, arm: str, kind: str | None = None) -> EdgeProgram:
    """``edge_id``'s program, ended by the failure of ``arm``'s first action."""
    program = EdgeProgram.from_edge(context.graph.edge(edge_id))
    if kind is not None:
        program.kind = kind
    program.failed_action = next(a for step in program.steps for a in step if a.arm == arm)
    return program


@pytest.mark.parametrize("strategy", ["agentchord", "agentchord-bt"])
def test_a_failed_first_grasp_is_the_edges_anticipated_loss_of_that_hold(strategy):
    context = _context("handover_block")
    detection = make_strategy(strategy).on_program_failure(context, _failed(context, "e1", "left"))
    assert detection is not None
    assert (detection.edge_id, detection.failure.name, detection.tick) == ("e1", "block_dropped", 42)
    # The recovery the switch then offers: the same arm's regrasp, and the other arm's.
    assert [e.id for e in context.recovery_map.candidates("e1", "block_dropped")] == [
        "e1_r_block_dropped", "e1_r_block_dropped_via_right"]


def test_of_a_synchronous_grasp_the_failed_arms_hold_is_named():
    context = _context("dual_arm_pour_water")
    strategy = make_strategy("agentchord")
    assert strategy.on_program_failure(context, _failed(context, "e1", "right")).failure.name == "bottle_dropped"
    assert strategy.on_program_failure(context, _failed(context, "e1", "left")).failure.name == "cup_dropped"


def test_a_recoverys_own_failure_a_grasp_that_holds_or_another_skill_is_not_taken_so():
    context = _context("handover_block")
    strategy = make_strategy("agentchord")
    assert strategy.on_program_failure(context, _failed(context, "e1", "left", kind="recovery")) is None
    assert strategy.on_program_failure(context, EdgeProgram.from_edge(context.graph.edge("e1"))) is None  # no failed action
    held = _context("handover_block", holding={("left", "block")})
    assert strategy.on_program_failure(held, _failed(held, "e1", "left")) is None
    # e2 moves the held block: its failed move is no grasp.
    assert strategy.on_program_failure(context, _failed(context, "e2", "left")) is None
