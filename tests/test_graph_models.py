"""Tests of agentchord.graph.models."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

from agentchord.graph import ActionCall, Edge, TaskGraph, UnknownEdgeError, UnknownNodeError

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"


@pytest.fixture
def pour() -> TaskGraph:
    return TaskGraph.model_validate(yaml.safe_load(POUR.read_text()))


def _edge(actions: object) -> Edge:
    return Edge.model_validate({"id": "e", "source": "a", "target": "b", "actions": actions})


def test_single_step_is_one_step_and_dumps_compact() -> None:
    edge = _edge({"left": None, "right": {"fn": "grasp", "args": {"obj": "bottle"}}})
    assert edge.steps == [{"left": None, "right": ActionCall(fn="grasp", args={"obj": "bottle"})}]
    assert edge.model_dump()["actions"] == {"left": None, "right": {"fn": "grasp", "args": {"obj": "bottle"}}}


def test_step_list_is_kept_as_a_list() -> None:
    edge = _edge([{"right": {"fn": "grasp", "args": {"obj": "bottle"}}}, {"right": {"fn": "back"}}])
    assert [step["right"].fn for step in edge.steps] == ["grasp", "back"]
    assert isinstance(edge.model_dump()["actions"], list)
    assert edge.calls == [("right", edge.steps[0]["right"]), ("right", edge.steps[1]["right"])]


def test_round_trip_through_dump_is_identity(pour: TaskGraph) -> None:
    again = TaskGraph.model_validate(pour.model_dump(mode="json", exclude_defaults=True))
    assert again == pour
    assert TaskGraph.model_validate(pour.model_dump()) == pour


def test_actions_of_wrong_type_are_refused() -> None:
    with pytest.raises(
        ValidationError, match=re.escape("expected a mapping arm -> {fn, args} or a list of such steps, got int")
    ):
        _edge(5)


@pytest.mark.parametrize(
    ("patch", "loc"),
    [
        ({"nodes": [{"id": "v0", "semantic": "s", "constrains": []}]}, ("nodes", 0, "constrains")),
        ({"start": "v0", "strat": "v0"}, ("strat",)),
    ],
)
def test_unknown_fields_are_errors(pour: TaskGraph, patch: dict, loc: tuple) -> None:
    data = pour.model_dump() | patch
    with pytest.raises(ValidationError) as info:
        TaskGraph.model_validate(data)
    assert [e["loc"] for e in info.value.errors()] == [loc]


def test_failure_window_must_be_positive_and_kind_literal(pour: TaskGraph) -> None:
    data = pour.model_dump()
    data["edges"][1]["failures"][0]["window"] = 0
    data["edges"][2]["kind"] = "recover"
    with pytest.raises(ValidationError) as info:
        TaskGraph.model_validate(data)
    assert {e["loc"] for e in info.value.errors()} == {("edges", 1, "failures", 0, "window"), ("edges", 2, "kind")}


def test_defaults(pour: TaskGraph) -> None:
    failure = pour.edge("e3").failures[0]
    assert (failure.margin, failure.window) == (0.0, 3)
    assert pour.edge("e4").failures == [] and pour.edge("e4").cost is None
    assert pour.node("v0").kind == "nominal" and pour.node("v0").constraints == []


def test_lookup_helpers(pour: TaskGraph) -> None:
    assert pour.node("r_bottle_regrasped").is_recovery
    assert pour.edge("e2").target == "v2"
    assert [e.id for e in pour.nominal_edges()] == ["e1", "e2", "e3", "e4", "e5"]
    assert [n.id for n in pour.recovery_nodes()] == ["r_bottle_regrasped"]
    assert [e.id for e in pour.out_edges("v2")] == ["e3", "e3_r_bottle_dropped"]
    assert [(e.id, f.name) for e, f in pour.failures()] == [
        ("e1", "grasp_missed"),
        ("e2", "bottle_dropped"),
        ("e3", "bottle_dropped"),
    ]
    assert pour.failure_entries()[("e2", "bottle_dropped")] == "e2_r_bottle_dropped"


def test_unknown_ids_raise_specific_key_errors(pour: TaskGraph) -> None:
    with pytest.raises(UnknownNodeError, match="unknown node 'v9'") as info:
        pour.node("v9")
    assert isinstance(info.value, KeyError)
    with pytest.raises(UnknownEdgeError, match="unknown edge 'e9'"):
        pour.edge("e9")


def test_json_schema_shows_both_action_forms() -> None:
    schema = TaskGraph.model_json_schema()
    assert set(schema["required"]) == {"task", "start", "goal", "nodes", "edges"}
    actions = schema["$defs"]["Edge"]["properties"]["actions"]
    assert {option["type"] for option in actions["anyOf"]} == {"object", "array"}
    assert schema["$defs"]["FailureMode"]["properties"]["window"]["minimum"] == 1


@pytest.mark.parametrize(("node_id", "message"), [("v\ud800", "a lone surrogate"), ("a\x00b", r"a control character \(U\+0000\)"),
                                                  ("a\nb", r"a control character \(U\+000A\)"), ("v" * 100_000, "more than 128")])
def test_an_id_is_one_short_line_of_text(node_id, message):
    """An adversarial pass (issue 58): `graph check` accepted these ids, which `graph render` then could not
    write (exit 3), wrote as DOT that Graphviz rejects, or broke a Mermaid label."""
    from agentchord.graph.models import Node

    with pytest.raises(ValueError, match=message):
        Node(id=node_id, semantic="s")


def test_a_semantic_keeps_its_lines_but_no_nul():
    from agentchord.graph.models import Node

    assert Node(id="v0", semantic="two\\nlines").semantic == "two\\nlines"
    with pytest.raises(ValueError, match="U\\+0000"):
        Node(id="v0", semantic="a\x00b")
