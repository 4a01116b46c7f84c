"""Tests of the reasoner interface: scene and request models, reply checks, call records."""

from __future__ import annotations

import json

import pytest
from pydantic import ValidationError

from agentchord.agents import (
    AGENTS,
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    Reasoner,
    ReasonerAttempt,
    ReasonerCall,
    Scene,
    SceneObject,
    UnanticipatedFailure,
    check_reply,
    total_usage,
)
from agentchord.agents.prompts import nominal_part
from agentchord.execution.trace import Trace
from agentchord.features.frame import make_static_frame
from agentchord.graph.models import ActionCall, Node, TaskGraph
from agentchord.library import load_task_graph


@pytest.fixture(scope="module")
def augmented() -> TaskGraph:
    return load_task_graph("single_arm_pour_water")


@pytest.fixture(scope="module")
def nominal(augmented: TaskGraph) -> TaskGraph:
    return nominal_part(augmented)


@pytest.fixture(scope="module")
def scene() -> Scene:
    return Scene(
        objects=[
            SceneObject(name="bottle", description="plastic bottle", pos=(0.10, 0.42, 0.09), extent=(0.05, 0.05, 0.18)),
            SceneObject(name="cup", pos=(0.0, 0.50, 0.05), extent=(0.08, 0.08, 0.10)),
        ]
    )


def messages(problems) -> str:
    return "\n".join(str(p) for p in problems)


# --- scene and requests ------------------------------------------------------------------


def test_scene_from_frame_rounds_poses_and_reads_the_grasp():
    frame = make_static_frame(
        {"bottle": {"pos": (0.123456, 0.4, 0.09)}, "cup": {}},
        {"right": {"ee": (0.1, 0.4, 0.2), "width": 0.031, "closed": 1.0}},
        holding={("right", "bottle")},
    )
    scene = Scene.from_frame(frame, descriptions={"cup": "red mug"}, notes="table top at z = 0")
    assert scene.object_names == ["bottle", "cup"]
    assert scene.objects[0].pos == (0.1235, 0.4, 0.09)
    assert scene.objects[1].description == "red mug"
    right = next(arm for arm in scene.arms if arm.name == "right")
    assert (right.closed, right.holding, right.width) == (True, "bottle", 0.031)
    assert next(arm for arm in scene.arms if arm.name == "left").holding is None
    assert json.loads(scene.model_dump_json())["notes"] == "table top at z = 0"


def test_requests_name_their_agent_and_forbid_unknown_fields(scene, nominal):
    assert (ComposeRequest.agent, ArrangeRequest.agent, ConductRequest.agent) == AGENTS
    with pytest.raises(ValidationError, match="instructions"):
        ComposeRequest(instructions="pour", scene=scene)
    request = ArrangeRequest(graph=nominal, scene=scene, failure=UnanticipatedFailure(edge="e2", context="v1"))
    assert ArrangeRequest.model_validate_json(request.model_dump_json()) == request


# --- check_reply -------------------------------------------------------------------------


def test_composer_accepts_a_nominal_graph(scene, nominal):
    request = ComposeRequest(instruction=nominal.instruction, scene=scene)
    assert check_reply(request, nominal) == []


def test_composer_refuses_failure_modes_and_recovery_branches(scene, augmented):
    problems = check_reply(ComposeRequest(instruction="pour", scene=scene), augmented)
    text = messages(problems)
    assert "composer writes the nominal graph only" in text
    assert any(p.path == "edges[0].failures" for p in problems)
    assert any(p.path.endswith(".kind") and p.path.startswith("nodes[") for p in problems)


def test_composer_refuses_objects_the_scene_lacks(nominal):
    scene = Scene(objects=[SceneObject(name="bottle", pos=(0, 0, 0), extent=(0.05, 0.05, 0.2))])
    problems = check_reply(ComposeRequest(instruction="pour", scene=scene), nominal)
    assert [p.path for p in problems] == ["objects[1]"]
    assert "'cup' is not a scene object; the scene has bottle" in problems[0].message


def test_composer_reports_graph_check_problems(scene, nominal):
    broken = nominal.model_copy(deep=True)
    broken.edges[0].target = "v9"
    problems = check_reply(ComposeRequest(instruction="pour", scene=scene), broken)
    assert any(p.path == "edges[0].target" and "unknown node 'v9'" in p.message for p in problems)


def test_arranger_accepts_the_library_augmentation(scene, nominal, augmented):
    assert check_reply(ArrangeRequest(graph=nominal, scene=scene), augmented) == []


def test_arranger_must_keep_the_nominal_graph(scene, nominal, augmented):
    changed = augmented.model_copy(deep=True)
    changed.edges[1].actions = [{"right": ActionCall(fn="back")}]
    changed.edges = [e for e in changed.edges if e.id != "e6"]
    changed.nodes.append(Node(id="v7", semantic="an extra nominal node"))
    text = messages(check_reply(ArrangeRequest(graph=nominal, scene=scene), changed))
    assert "nominal edge 'e2' must keep its actions" in text
    assert "nominal edge 'e6' of the input is missing" in text
    assert "node 'v7' is new: nodes the arranger adds are kind: recovery" in text


def test_arranger_must_keep_start_and_goal(scene, nominal, augmented):
    moved = augmented.model_copy(update={"goal": "v5"})
    problems = check_reply(ArrangeRequest(graph=nominal, scene=scene), moved)
    assert any(p.path == "goal" and "must stay 'v6'" in p.message for p in problems)


def test_conductor_accepts_tuned_parameters(scene, augmented):
    tuned = augmented.model_copy(deep=True)
    tuned.edges[1].actions[0]["right"].args["offset"] = [0.0, -0.1, 0.09]
    tuned.edges[1].failures[2].monitor = "drift(cup, 0.015)"
    tuned.edges[1].failures[2].window = 5
    assert check_reply(ConductRequest(graph=augmented, scene=scene), tuned) == []


def test_conductor_must_keep_the_structure(scene, augmented):
    changed = augmented.model_copy(deep=True)
    changed.edges[1].failures.pop()  # e2 loses cup_shifted
    changed.edges[2].target = "v4"
    changed.nodes[-1].kind = "nominal"
    text = messages(check_reply(ConductRequest(graph=augmented, scene=scene), changed))
    assert "edge 'e2' must keep its failure modes" in text
    assert "edge 'e3' must keep 'v2' -> 'v3' (nominal), got 'v2' -> 'v4' (nominal)" in text
    assert "kind changed: r_bottle_regrasped" in text


# --- records -----------------------------------------------------------------------------


def make_call(ok: bool = True) -> ReasonerCall:
    call = ReasonerCall(
        agent="composer",
        reasoner="llm",
        model="m",
        request={"instruction": "pour"},
        messages=[{"role": "user", "content": "pour"}],
        attempts=[
            ReasonerAttempt(reply="nope", tokens_in=10, tokens_out=5, problems=["the reply is not valid JSON"]),
            ReasonerAttempt(reply="{}", tokens_in=12, tokens_out=None, transport_errors=["HTTP 500: boom; retry 1/4"]),
        ],
        reply={"task": "t"} if ok else None,
        error=None if ok else "no valid task graph",
        latency_s=1.5,
        started_at=1_700_000_000.0,
    )
    call.add_usage()
    return call


def test_call_accounting_and_errors():
    call = make_call()
    assert (call.tokens_in, call.tokens_out, call.repairs, call.ok) == (22, 5, 1, True)
    assert call.errors == ["attempt 1: the reply is not valid JSON", "attempt 2: HTTP 500: boom; retry 1/4"]
    failed = make_call(ok=False)
    assert not failed.ok and failed.errors[-1] == "no valid task graph"
    assert total_usage([call, failed]) == {
        "calls": 2, "failed": 1, "attempts": 4, "tokens_in": 44, "tokens_out": 10, "latency_s": 3.0
    }


def test_call_round_trips_through_the_episode_trace(tmp_path):
    call = make_call()
    trace = Trace()
    trace.add(0, "reasoner_call", **call.to_trace_event())
    back = Trace.read(trace.write(tmp_path / "trace.jsonl")).of("reasoner_call")[0]
    assert back["ok"] is True and back["errors"] == call.errors
    restored = ReasonerCall.model_validate({k: v for k, v in back.items() if k not in ("tick", "event")})
    assert restored.model_dump() == call.model_dump()
    assert "messages" not in call.to_trace_event(messages=False)


def test_a_class_with_the_three_methods_is_a_reasoner(nominal):
    class Fixed:
        name = "fixed"

        def __init__(self) -> None:
            self.calls: list[ReasonerCall] = []

        def compose(self, request: ComposeRequest) -> TaskGraph:
            return nominal

        def arrange(self, request: ArrangeRequest) -> TaskGraph:
            return nominal

        def conduct(self, request: ConductRequest) -> TaskGraph:
            return nominal

    assert isinstance(Fixed(), Reasoner)
    assert not isinstance(object(), Reasoner)
