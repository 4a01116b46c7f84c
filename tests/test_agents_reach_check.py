"""The reach check of a plan: a grasp or place beyond its arm's reach is refused before the robot moves."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from replay_server import Completion, ReplayServer

from agentchord.agents import ComposeRequest
from agentchord.agents.llm import LlmConfig, LlmReasoner
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.prompts import nominal_part
from agentchord.agents.reach_check import reach_problems
from agentchord.agents.scene import Scene, arms_reaching
from agentchord.cli import main
from agentchord.graph.loader import dump_graph
from agentchord.graph.models import Success, TaskGraph
from agentchord.library import library_tasks, load_task_graph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world
from agentchord.solvers.reach import BASE, SIDE_REACH, TOP_REACH


def _scene(task: str, seed: int = 0) -> Scene:
    return observe(open_world(task, seed), task_regions(SIM_TASKS[task]))


def _capsule_by_the_right_arm() -> TaskGraph:
    """The coffee tray's library graph with the capsule taken by the right arm, which stands 78 cm from it."""
    graph = load_task_graph("setup_coffee_tray").model_copy(deep=True)
    for edge in graph.nominal_edges():
        for step in edge.actions:
            call = step.get("left")
            if call is not None and call.args.get("obj") == "capsule":
                step["right"] = step.pop("left")
    return graph


@pytest.fixture(scope="module")
def tray_scene() -> Scene:
    return _scene("setup_coffee_tray")


def test_the_scene_states_each_arms_reach_and_who_reaches_what(tray_scene):
    arms = {arm.name: arm for arm in tray_scene.arms}
    assert arms["left"].base == BASE["left"] and arms["right"].base == BASE["right"]
    assert (arms["left"].reach_top, arms["left"].reach_side) == (TOP_REACH, SIDE_REACH)
    objects = {obj.name: obj for obj in tray_scene.objects}
    assert objects["capsule"].reachable_by == ["left"]  # on the left, 78 cm from the right arm
    assert objects["tray"].reachable_by == ["left", "right"]
    # A tall object is taken from the side, which reaches farther than a top grasp.
    assert arms_reaching((-0.2, 0.5, 0.1), (0.04, 0.04, 0.2)) == ["left", "right"]
    assert arms_reaching((-0.2, 0.5, 0.02), (0.03, 0.03, 0.03)) == ["left"]


@pytest.mark.parametrize("task", sorted(library_tasks()))
def test_every_library_graph_is_within_reach(task):
    for seed in (0, 1):
        assert reach_problems(load_task_graph(task), _scene(task, seed)) == []


def test_an_unreachable_grasp_names_the_edge_the_arm_the_distance_and_what_would_do(tray_scene):
    (problem,) = reach_problems(_capsule_by_the_right_arm(), tray_scene)
    assert problem.path == "edges[0].actions"
    message = problem.message
    assert message.startswith("edge 'e1': the right arm's grasp of capsule where it lies at (-0.30, 0.45)")
    assert "0.78 m from its base" in message and "0.20 m beyond its reach from above (0.58 m)" in message
    assert "use the left arm (it reaches it" in message and "a hand-over" in message


def test_a_place_beyond_reach_is_refused_and_a_hand_off_mid_table_is_not(tray_scene):
    graph = load_task_graph("setup_coffee_tray").model_copy(deep=True)
    first = graph.nominal_edges()[0]
    assert reach_problems(graph, tray_scene) == []
    # The capsule set down on the far right by the left arm: 0.71 m from its base.
    place = next(e for e in graph.nominal_edges() for s in e.actions if s.get("left") and s["left"].fn == "place")
    for step in place.actions:
        if step.get("left") is not None and step["left"].fn == "place":
            step["left"].args = {"obj": "capsule", "target": [0.25, 0.45]}
    problems = reach_problems(graph, tray_scene)
    assert [p.message.split(":")[0] for p in problems] == [f"edge {place.id!r}"]
    assert "the left arm's place of capsule at (0.25, 0.45)" in problems[0].message
    assert first.id != place.id


def test_the_llm_composer_is_asked_to_repair_an_unreachable_grasp(tray_scene):
    bad = nominal_part(_capsule_by_the_right_arm())
    goal = {"goals": [{"kind": "inside", "obj": "capsule", "container": "tray"},
                      {"kind": "placed", "obj": "tray", "region": "forward"}], "home": True}
    bad = bad.model_copy(update={"success": Success(judge="goal", goal_spec=goal)})
    good = nominal_part(load_task_graph("setup_coffee_tray")).model_copy(update={"success": bad.success})
    with ReplayServer() as server:
        server.push(*(Completion(json.dumps(g.model_dump(mode="json", exclude_defaults=True))) for g in (bad, good)))
        config = LlmConfig(base_url=server.base_url, model="replay-model", api_key="k", timeout_s=10.0, backoff_base_s=0.01)
        llm = LlmReasoner(config)
        graph = llm.compose(ComposeRequest(instruction=good.instruction, scene=tray_scene, task=good.task))
        repair = server.bodies()[1]["messages"][-1]["content"]
    assert graph == good
    assert "- edges[0].actions: edge 'e1': the right arm's grasp of capsule" in repair
    assert llm.last_goal is not None and [g.kind for g in llm.last_goal.goals] == ["inside", "placed"]


def test_graph_check_with_a_task_refuses_an_unreachable_grasp(tmp_path):
    path = tmp_path / "g.yaml"
    dump_graph(_capsule_by_the_right_arm(), path)
    result = CliRunner().invoke(main, ["graph", "check", str(path), "--task", "setup_coffee_tray"])
    assert result.exit_code == 2, result.output
    assert f"{path}: edges[0].actions: edge 'e1': the right arm's grasp of capsule" in result.output
    assert "use the left arm" in result.output
    plain = CliRunner().invoke(main, ["graph", "check", str(path)])  # no scene, no reach to check
    assert plain.exit_code == 0, plain.output
