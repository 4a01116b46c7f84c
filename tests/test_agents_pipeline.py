"""Composer -> arranger -> conductor end to end, planned episodes, and online repair through the arranger."""

from __future__ import annotations

import pytest

from agentchord.agents.pipeline import ReasonerRepairer, make_reasoner, plan_task
from agentchord.agents.exceptions import ReasonerConfigError
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.graph.validation import check_graph
from agentchord.library import load_task_graph
from test_agents_rules_composer import scene_of


def test_plan_task_writes_a_valid_augmented_graph_and_records_three_calls():
    scene = scene_of("single_arm_pour_water")
    reasoner = make_reasoner("rules")
    result = plan_task(load_task_graph("single_arm_pour_water").instruction, scene, reasoner, "single_arm_pour_water")
    assert check_graph(result.graph) == []
    assert [c.agent for c in result.calls] == ["composer", "arranger", "conductor"] and all(c.ok for c in result.calls)
    assert result.filtered.removed == []
    assert result.graph.recovery_edges() and set(result.seconds) == {"composer", "arranger", "conductor"}


def test_unknown_reasoner_is_a_config_error():
    with pytest.raises(ReasonerConfigError, match="unknown reasoner"):
        make_reasoner("oracle")


def test_a_planned_episode_runs_the_planned_graph_and_traces_the_calls():
    spec = EpisodeSpec(task="single_arm_pour_water", seed=3, instruction=load_task_graph("single_arm_pour_water").instruction)
    result = run_episode(spec)
    assert result.success, result.reason
    calls = result.trace.of("reasoner_call")
    assert [c["agent"] for c in calls] == ["composer", "arranger", "conductor"]
    assert result.trace.events[0]["event"] == "reasoner_call"


def test_an_unseen_instruction_is_planned_and_executed_offline():
    result = run_episode(EpisodeSpec(task="blocks_and_cup", seed=0, instruction="put the red block into the cup"))
    assert result.success, result.reason


def test_the_repairer_adds_one_branch_through_the_arranger():
    from agentchord.agents.reasoner import UnanticipatedFailure
    from agentchord.features.frame import make_static_frame

    graph = load_task_graph("single_arm_pour_water").model_copy(deep=True)
    graph.edge("e2").failures = [f for f in graph.edge("e2").failures if f.name != "bottle_dropped"]
    frame = make_static_frame(objects={"bottle": {"pos": (0.1, 0.5, 0.09)}, "cup": {"pos": (-0.1, 0.6, 0.05)}})
    repaired = ReasonerRepairer(make_reasoner("rules"))(graph, UnanticipatedFailure(edge="e2", context="v1", observation="bottle not held"), frame)
    assert repaired is not None
    assert len(repaired.edge("e2").failures) == len(graph.edge("e2").failures) + 1
