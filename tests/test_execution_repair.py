"""Online repair of unanticipated failures: the proposal check, the test double, the executor's use of both."""

from __future__ import annotations

import pytest

from agentchord.agents.reasoner import UnanticipatedFailure
from agentchord.execution.edge_program import EdgeProgram
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.executor import Executor, ExecutorConfig
from agentchord.execution.repair import RepairRejectedError, ScriptedRepairer, validate_repair
from agentchord.execution.strategies import make_strategy
from agentchord.features.frame import FeatureFrame
from agentchord.graph.models import FailureMode, TaskGraph
from agentchord.library import load_task_graph
from agentchord.sim.disturbances import ScriptedDrop
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

TASK = "single_arm_pour_water"
FAILURE = UnanticipatedFailure(edge="e2", context="v1", observation="at v2: tilt(bottle) - 15 = 4.33")
# Scene seed and drop moment (ticks into the first move_to_obj) where the forced-open gripper closes
# again on a bottle that slipped and tilted in the hand: e2 ends with v2's "tilt(bottle) - 15" violated.
SEED, AFTER = 2, 20
# The scripted repairer does not look at the frame.
FRAME = FeatureFrame(objects={}, arms={})


def unanticipated_graph() -> TaskGraph:
    """The library graph without e2's bottle_dropped and bottle_slipped modes: no monitor anticipates
    the drop on e2, nor the tilted hold it leaves."""
    graph = load_task_graph(TASK)
    e2 = graph.edge("e2")
    e2.failures = [f for f in e2.failures if f.name not in ("bottle_dropped", "bottle_slipped")]
    graph.edges = [e for e in graph.edges if e.id != "e2_r_bottle_slipped"]
    for edge in graph.edges:  # the re-approach that redoes e2's carry watched the same slip
        edge.failures = [f for f in edge.failures if f.recovery != "e2_r_bottle_slipped"]
    return graph


def scripted_repairer() -> ScriptedRepairer:
    # The bottle is still in the hand but tilted: set it down upright, side-grasp it again and
    # bring it back over the cup (the library's regrasp then move, with a place first).
    return ScriptedRepairer(
        name="bottle_slipped",
        monitor="tilt(bottle) - 15",
        intent="regrasp",
        steps=[
            {"right": {"fn": "place", "args": {"obj": "bottle", "target": [0.10, 0.42]}}},
            {"right": {"fn": "grasp", "args": {"obj": "bottle"}}},
            {"right": {"fn": "move_to_obj", "args": {"obj": "cup", "offset": [0.0, -0.09, 0.08], "yaw": 180}}},
        ],
    )


def episode(repairer=None, config: ExecutorConfig | None = None):
    drop = ScriptedDrop(action="move_to_obj", nth=0, after=AFTER)
    return run_episode(EpisodeSpec(TASK, seed=SEED, graph=unanticipated_graph(), disturbance=drop,
                                   repairer=repairer, config=config))


# --------------------------------------------------------------- the test double and the check
def test_scripted_repairer_adds_one_mode_and_its_entry_edge_merging_at_the_target():
    graph = unanticipated_graph()
    repaired = scripted_repairer()(graph, FAILURE, FRAME)
    assert repaired is not None and graph.edge("e2").failures == unanticipated_graph().edge("e2").failures
    mode = repaired.edge("e2").failures[-1]
    assert (mode.name, mode.monitor, mode.intent, mode.recovery) == ("bottle_slipped", "tilt(bottle) - 15", "regrasp", "e2_r_bottle_slipped")
    entry = repaired.edge("e2_r_bottle_slipped")
    assert (entry.kind, entry.source, entry.target, len(entry.steps)) == ("recovery", "v1", "v2", 3)


def test_scripted_repairer_declines_when_its_names_are_taken():
    repairer = scripted_repairer()
    once = repairer(unanticipated_graph(), FAILURE, FRAME)
    assert repairer(once, FAILURE, FRAME) is None
    assert repairer.calls == [FAILURE, FAILURE]


def test_valid_repair_is_accepted_and_filtered():
    graph = unanticipated_graph()
    repair = validate_repair(graph, scripted_repairer()(graph, FAILURE, FRAME), FAILURE)
    assert repair.failure.name == "bottle_slipped" and repair.recovery.id == "e2_r_bottle_slipped"
    assert ("e2", "bottle_slipped") in repair.filtered.graph.failure_entries()


def _propose(mutate) -> TaskGraph:
    proposal = scripted_repairer()(unanticipated_graph(), FAILURE, FRAME)
    mutate(proposal)
    return proposal


@pytest.mark.parametrize("mutate,message", [
    (lambda g: g.edges.remove(g.edge("e6")), "dropped e6"),
    (lambda g: g.edge("e2").failures.pop(), "expected one new failure mode on 'e2', got 0"),
    (lambda g: g.edge("e2").failures.append(FailureMode(name="x", monitor="tilt(cup) - 30", intent="i",
                                                        recovery="e2_r_bottle_slipped")), "got 2"),
    (lambda g: setattr(g.edge("e2").failures[-1], "monitor", "tilt(glass) - 15"), "graph check failed"),
    # Back to the start node: D(v0, goal) > D(v1, goal).
    (lambda g: setattr(g.edge("e2_r_bottle_slipped"), "target", "v0"), "regressive recovery branch"),
])
def test_invalid_proposals_are_rejected_with_a_reason(mutate, message):
    with pytest.raises(RepairRejectedError, match=message):
        validate_repair(unanticipated_graph(), _propose(mutate), FAILURE)


# ------------------------------------------------------------------------------- the executor
def test_repair_bounds_one_attempt_per_edge_and_target_and_max_repairs_per_episode(pour_scene):
    calls: list[UnanticipatedFailure] = []

    def decline(graph: TaskGraph, failure: UnanticipatedFailure, frame: FeatureFrame) -> None:
        calls.append(failure)

    executor = Executor(unanticipated_graph(), SimWorld(pour_scene), make_strategy("agentchord"),
                        SIM_TASKS[TASK].success_tracker(), config=ExecutorConfig(max_repairs=2), repairer=decline)
    # At home nothing is held: v2 and v3 (the bottle in hand) do not hold, so the programs "end" unmet.
    for edge in ("e2", "e2", "e3", "e4"):
        assert executor._repair(EdgeProgram.from_edge(executor.graph.edge(edge))) is None
    assert [(c.edge, c.context) for c in calls] == [("e2", "v1"), ("e3", "v2")]
    assert "holding(right, bottle) = " in calls[0].observation
    events = executor.trace.of("repair")
    assert [(e["edge"], e["accepted"], e["reason"]) for e in events] == [
        ("e2", False, "the repairer proposed no branch"), ("e3", False, "the repairer proposed no branch")]


def test_unanticipated_failure_without_a_repairer_goes_on_and_fails():
    result = episode()
    assert not result.success
    assert result.summary()["repairs"] == 0 and result.recoveries == 0
    v2 = next(e for e in result.trace.of("node_reached") if e["node"] == "v2")
    assert v2["violated"] == ["tilt(bottle) - 15"]


def test_scripted_repair_adds_a_branch_and_recovers_forward():
    repairer = scripted_repairer()
    result = episode(repairer)
    assert result.success, result.reason
    assert [(c.edge, c.context) for c in repairer.calls] == [("e2", "v1")]
    assert "tilt(bottle) - 15 = " in repairer.calls[0].observation
    (repair,) = result.trace.of("repair")
    assert (repair["edge"], repair["failure"], repair["recovery"], repair["accepted"]) == (
        "e2", "bottle_slipped", "e2_r_bottle_slipped", True)
    assert repair["latency_s"] >= 0.0
    assert result.summary()["repairs"] == 1
    # The new recovery edge starts at once, from where the robot is, and merges forward at v2.
    (switch,) = result.trace.of("recovery_switch")
    assert (switch["edge"], switch["to"], switch["tick"]) == ("e2", "e2_r_bottle_slipped", repair["tick"])
    assert result.path[result.path.index("e2"):][:3] == ["e2", "e2_r_bottle_slipped", "v2"]
    assert result.drops_detected == result.drops_recovered == 1


def test_max_repairs_zero_keeps_the_old_behaviour():
    repairer = scripted_repairer()
    result = episode(repairer, ExecutorConfig(max_repairs=0))
    assert not result.success
    assert repairer.calls == [] and result.trace.of("repair") == []
    assert result.summary()["repairs"] == 0


def test_the_rules_arranger_repairs_the_same_unforeseen_failure_online():
    # No scripted branch: the rules read the tilted bottle in the hand from the observation.
    drop = ScriptedDrop(action="move_to_obj", nth=0, after=AFTER)
    result = run_episode(EpisodeSpec(TASK, seed=SEED, graph=unanticipated_graph(), disturbance=drop, repair=True))
    repairs = [e for e in result.trace.of("repair") if e["accepted"]]
    assert result.success, result.reason
    assert result.repairs >= 1 and repairs[0]["failure"] == "bottle_slipped"


def test_after_an_outage_no_more_repairs_are_asked(pour_scene):
    """Issue 58: with the LLM server dead mid-episode, each later online repair retried it for about 15 s."""
    from agentchord.agents.exceptions import ReasonerTransportError

    calls: list[UnanticipatedFailure] = []

    def down(graph: TaskGraph, failure: UnanticipatedFailure, frame: FeatureFrame) -> None:
        calls.append(failure)
        raise ReasonerTransportError("the arranger's endpoint could not be reached after 3 tries", agent="arranger")

    executor = Executor(unanticipated_graph(), SimWorld(pour_scene), make_strategy("agentchord"),
                        SIM_TASKS[TASK].success_tracker(), config=ExecutorConfig(max_repairs=3), repairer=down)
    for edge in ("e2", "e3", "e4"):
        assert executor._repair(EdgeProgram.from_edge(executor.graph.edge(edge))) is None
    assert len(calls) == 1 and executor.repairer is None
    (event,) = executor.trace.of("repair")
    assert "no more repairs are asked" in event["reason"]
