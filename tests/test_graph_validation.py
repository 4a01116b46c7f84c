"""Tests of agentchord.graph.validation: one test per kind of problem."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from agentchord.actions.catalog import ACTIONS
import yaml

from agentchord.expr import ExprError, Vocabulary, compile_expr
from agentchord.graph import Problem, TaskGraph, check_file, check_graph

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"

Data = dict[str, Any]


def _pour() -> Data:
    return yaml.safe_load(POUR.read_text())


def _check(edit: Callable[[Data], None]) -> list[Problem]:
    data = _pour()
    edit(data)
    return check_graph(TaskGraph.model_validate(data))


def _expr_error(source: str, objects: list[str]) -> str:
    with pytest.raises(ExprError) as info:
        compile_expr(source, Vocabulary(frozenset(objects)))
    return str(info.value)


def _edge(data: Data, edge_id: str) -> Data:
    return next(e for e in data["edges"] if e["id"] == edge_id)


def test_pour_water_graph_is_valid() -> None:
    assert check_graph(TaskGraph.model_validate(_pour())) == []
    assert check_file(POUR) == []


def test_problem_prints_as_path_and_message() -> None:
    assert str(Problem("edges[1].id", "duplicate")) == "edges[1].id: duplicate"


def test_duplicate_node_id() -> None:
    problems = _check(lambda d: d["nodes"].append({"id": "v2", "semantic": "again"}))
    assert problems == [Problem("nodes[7].id", "duplicate node id 'v2' (first at nodes[2])")]


def test_duplicate_edge_id() -> None:
    problems = _check(lambda d: d["edges"].append(dict(_edge(d, "e4"), failures=[])))
    assert problems == [Problem("edges[9].id", "duplicate edge id 'e4' (first at edges[3])")]


def test_duplicate_object_and_failure_name() -> None:
    def edit(d: Data) -> None:
        d["objects"].append("cup")
        failures = _edge(d, "e2")["failures"]
        failures.append(dict(failures[0]))

    assert _check(edit) == [
        Problem("objects[2]", "duplicate object 'cup' (first at objects[1])"),
        Problem("edges[1].failures[1].name", "duplicate failure mode 'bottle_dropped' (first at edges[1].failures[0])"),
    ]


def test_edge_naming_unknown_nodes() -> None:
    def edit(d: Data) -> None:
        _edge(d, "e4")["source"] = "v33"
        _edge(d, "e4")["target"] = "nowhere"

    assert _check(edit) == [
        Problem("edges[3].source", "unknown node 'v33' (did you mean 'v3'?)"),
        Problem("edges[3].target", "unknown node 'nowhere'"),
    ]


@pytest.mark.parametrize("field", ["start", "goal"])
def test_start_or_goal_missing(field: str) -> None:
    problems = _check(lambda d: d.update({field: "v6"}))
    assert problems == [Problem(field, "unknown node 'v6'")]


def test_failure_recovery_naming_unknown_edge() -> None:
    problems = _check(lambda d: _edge(d, "e2")["failures"][0].update(recovery="e2_r_bottle_droped"))
    assert problems[0] == Problem(
        "edges[1].failures[0].recovery", "unknown edge 'e2_r_bottle_droped' (did you mean 'e2_r_bottle_dropped'?)"
    )


def test_goal_unreachable_over_nominal_edges() -> None:
    # A recovery edge does not count: the nominal plan itself must reach the goal.
    problems = _check(lambda d: _edge(d, "e4").update(kind="recovery"))
    assert Problem("goal", "'v5' is not reachable from start 'v0' over nominal edges") in problems


def test_recovery_entry_edge_must_be_a_recovery_edge() -> None:
    def edit(d: Data) -> None:
        _edge(d, "e1")["failures"][0]["recovery"] = "e2"  # also the wrong source

    assert _check(edit) == [
        Problem(
            "edges[0].failures[0].recovery",
            "entry edge 'e2' is a nominal edge; a recovery entry edge needs kind: recovery",
        ),
        Problem(
            "edges[0].failures[0].recovery",
            "entry edge 'e2' leaves 'v1', but the failure context is 'v0' (the source of edge 'e1')",
        ),
        Problem(
            "edges[5]",
            "recovery edge 'e1_r_grasp_missed' is on no recovery branch (no failure mode's recovery leads to it)",
        ),
    ]


def test_recovery_entry_edge_must_leave_the_failure_context() -> None:
    problems = _check(lambda d: _edge(d, "e2_r_bottle_dropped").update(source="v0"))
    assert problems[0] == Problem(
        "edges[1].failures[0].recovery",
        "entry edge 'e2_r_bottle_dropped' leaves 'v0', but the failure context is 'v1' (the source of edge 'e2')",
    )


def test_unknown_action() -> None:
    problems = _check(lambda d: _edge(d, "e1")["actions"]["right"].update(fn="grab"))
    assert problems == [
        Problem(
            "edges[0].actions.right.fn",
            f"unknown action 'grab' (did you mean 'grasp'?); actions are {', '.join(sorted(ACTIONS))}",
        )
    ]


def test_unknown_arm() -> None:
    problems = _check(lambda d: _edge(d, "e1")["actions"].update(rigth=_edge(d, "e1")["actions"].pop("right")))
    assert problems == [
        Problem("edges[0].actions.rigth", "unknown arm 'rigth' (did you mean 'right'?); arms are left, right")
    ]


def test_unknown_object() -> None:
    problems = _check(lambda d: _edge(d, "e5")["actions"]["right"]["args"].update(obj="botle"))
    assert problems == [
        Problem(
            "edges[4].actions.right.args.obj",
            "unknown object 'botle' (did you mean 'bottle'?); graph objects: bottle, cup",
        )
    ]


def test_objects_not_listed() -> None:
    problems = _check(lambda d: d.pop("objects"))
    assert (
        Problem(
            "edges[0].actions.right.args.obj", "unknown object 'bottle'; graph objects: none (list them under objects)"
        )
        in problems
    )


def test_action_args_failing_the_catalogue_model() -> None:
    def edit(d: Data) -> None:
        _edge(d, "e3")["actions"]["right"]["args"] = {"angle": 270}
        _edge(d, "e4")["actions"]["right"]["args"] = {}
        _edge(d, "e2")["actions"]["right"]["args"]["ofset"] = [0, 0, 0]
        _edge(d, "e3_r_bottle_dropped")["actions"][1]["right"]["args"]["offset"] = [0, 0, "up"]

    assert _check(edit) == [
        Problem("edges[1].actions.right.args.ofset", "Extra inputs are not permitted (did you mean 'offset'?)"),
        Problem("edges[2].actions.right.args.angle", "Input should be less than or equal to 180"),
        Problem("edges[3].actions.right.args.angle", "Field required"),
        Problem(
            "edges[8].actions[1].right.args.offset[2]",
            "Input should be a valid number, unable to parse string as a number",
        ),
    ]


def test_a_grasp_skipping_as_placed_needs_a_later_place_at_a_target() -> None:
    def lone(d: Data) -> None:  # e1 grasps and nothing places the bottle after it
        _edge(d, "e1")["actions"]["right"]["args"]["skip_if_placed"] = True

    assert _check(lone) == [
        Problem(
            "edges[0].actions.right.args.skip_if_placed",
            "no later place of bottle by the right arm with a target in this edge to tell where it would lie placed",
        )
    ]

    def placed(d: Data) -> None:
        _edge(d, "e5")["actions"] = [
            {"right": {"fn": "grasp", "args": {"obj": "bottle", "skip_if_placed": True}}},
            {"right": {"fn": "place", "args": {"obj": "bottle", "target": [0.1, 0.42], "skip_if_placed": True}}},
        ]

    assert _check(placed) == []


def test_empty_steps() -> None:
    def edit(d: Data) -> None:
        _edge(d, "e4")["actions"] = []
        _edge(d, "e1")["actions"] = {"left": None, "right": None}

    problems = _check(edit)
    assert Problem("edges[3].actions", "no step; an edge needs at least one action") in problems
    assert Problem("edges[0].actions", "no arm acts in this step") in problems


@pytest.mark.parametrize(
    ("path", "edit"),
    [
        (
            "nodes[2].constraints[0]",
            lambda d: d["nodes"][2]["constraints"].__setitem__(0, "dist(mug.pos, cup.top) - 0.03"),
        ),
        ("edges[1].path_constraints[0]", lambda d: _edge(d, "e2")["path_constraints"].__setitem__(0, "tilt(mug) - 20")),
        (
            "edges[2].failures[0].monitor",
            lambda d: _edge(d, "e3")["failures"][0].update(monitor="0.5 - holding(right, mug)"),
        ),
    ],
)
def test_expression_that_does_not_compile(path: str, edit: Callable[[Data], None]) -> None:
    data = _pour()
    edit(data)
    graph = TaskGraph.model_validate(data)
    [problem] = check_graph(graph)
    assert problem.path == path
    source = {
        "nodes[2].constraints[0]": graph.nodes[2].constraints[0],
        "edges[1].path_constraints[0]": graph.edges[1].path_constraints[0],
        "edges[2].failures[0].monitor": graph.edges[2].failures[0].monitor,
    }[path]
    assert problem.message == _expr_error(source, graph.objects)
    assert "mug" in problem.message


def test_regressive_recovery_branch() -> None:
    # The re-grasped bottle goes home first: D(r) = 100 + D(v0) = 730 > D(v1) = 440.
    problems = _check(lambda d: _edge(d, "r_bottle_regrasped_to_v2").update(target="v0", cost=100))
    assert problems == [
        Problem(
            "edges[1].failures[0].recovery",
            "regressive recovery branch (forward-moving principle): "
            "D(r_bottle_regrasped, goal)=730  >  D(v1, goal)=440",
        )
    ]


def test_recovery_node_unreachable_from_any_entry() -> None:
    def edit(d: Data) -> None:
        d["nodes"].append({"id": "r_orphan", "kind": "recovery", "semantic": "never reached"})
        d["edges"].append(
            {
                "id": "r_orphan_to_v2",
                "kind": "recovery",
                "source": "r_orphan",
                "target": "v2",
                "actions": {"right": {"fn": "back"}},
            }
        )

    assert _check(edit) == [
        Problem("nodes[7]", "recovery node 'r_orphan' is not reachable from any recovery entry edge"),
        Problem(
            "edges[9]",
            "recovery edge 'r_orphan_to_v2' is on no recovery branch (no failure mode's recovery leads to it)",
        ),
    ]


def test_recovery_node_without_path_to_goal() -> None:
    def edit(d: Data) -> None:
        d["edges"] = [e for e in d["edges"] if e["id"] != "r_bottle_regrasped_to_v2"]

    assert _check(edit) == [
        Problem("nodes[6]", "recovery node 'r_bottle_regrasped' has no path to the goal 'v5'"),
        Problem(
            "edges[1].failures[0].recovery",
            "regressive recovery branch (forward-moving principle): "
            "D(r_bottle_regrasped, goal)=inf  >  D(v1, goal)=440",
        ),
    ]


def test_graph_checks_wait_for_sound_references() -> None:
    # With an unknown node, reachability and cost-to-go would be noise: only the cause is reported.
    problems = _check(lambda d: _edge(d, "e3").update(target="v9"))
    assert problems == [Problem("edges[2].target", "unknown node 'v9'")]


def test_check_file_lines(tmp_path: Path) -> None:
    data = _pour()
    _edge(data, "e5")["actions"]["right"]["args"]["obj"] = "mug"
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    assert check_file(path) == [
        f"{path}: edges[4].actions.right.args.obj: unknown object 'mug'; graph objects: bottle, cup"
    ]
    broken = tmp_path / "broken.yaml"
    broken.write_text("task: [\n")
    [line] = check_file(broken)
    assert line.startswith(f"{broken}: line 2, column 1: invalid YAML:")
