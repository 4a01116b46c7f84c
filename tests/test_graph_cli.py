"""Tests of agentchord.graph.cli through the ``agentchord`` command."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

from agentchord.actions.catalog import ACTIONS
from agentchord.cli import main
from agentchord.graph import load_graph

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner()


def _write(tmp_path: Path, data: dict, name: str = "g.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _regressive(tmp_path: Path) -> Path:
    # The re-grasped bottle goes home first: D(r) = 100 + D(v0) = 730 > D(v1) = 440.
    data = yaml.safe_load(POUR.read_text())
    exit_edge = next(e for e in data["edges"] if e["id"] == "r_bottle_regrasped_to_v2")
    exit_edge.update(target="v0", cost=100)
    return _write(tmp_path, data)


def test_schema_prints_json_schema(runner: CliRunner) -> None:
    result = runner.invoke(main, ["schema"])
    assert result.exit_code == 0
    schema = json.loads(result.output)
    assert schema["title"] == "TaskGraph" and "FailureMode" in schema["$defs"]
    assert result.output.startswith('{\n  "$defs"')


def test_check_valid_graph(runner: CliRunner) -> None:
    result = runner.invoke(main, ["graph", "check", str(POUR)])
    assert result.exit_code == 0
    assert result.output == f"{POUR}: ok (7 nodes, 9 edges, 3 failure modes)\n"


def test_check_reports_every_problem_and_exits_2(runner: CliRunner, tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    data["edges"][0]["actions"]["right"]["fn"] = "grab"
    data["edges"][4]["actions"]["right"]["args"]["obj"] = "mug"
    bad = _write(tmp_path, data)
    result = runner.invoke(main, ["graph", "check", str(POUR), str(bad)])
    assert result.exit_code == 2
    assert result.output.splitlines() == [
        f"{POUR}: ok (7 nodes, 9 edges, 3 failure modes)",
        f"{bad}: edges[0].actions.right.fn: unknown action 'grab' (did you mean 'grasp'?); actions are "
        f"{', '.join(sorted(ACTIONS))}",
        f"{bad}: edges[4].actions.right.args.obj: unknown object 'mug'; graph objects: bottle, cup",
    ]


def test_check_reports_load_errors(runner: CliRunner, tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    data["edges"][1]["failures"][0]["window"] = 0
    bad = _write(tmp_path, data)
    result = runner.invoke(main, ["graph", "check", str(bad)])
    assert result.exit_code == 2
    assert result.output == f"{bad}: edges[1].failures[0].window: Input should be greater than or equal to 1\n"


def test_check_regressive_branch(runner: CliRunner, tmp_path: Path) -> None:
    path = _regressive(tmp_path)
    result = runner.invoke(main, ["graph", "check", str(path)])
    assert result.exit_code == 2
    assert result.output == (
        f"{path}: edges[1].failures[0].recovery: regressive recovery branch (forward-moving principle): "
        "D(r_bottle_regrasped, goal)=730  >  D(v1, goal)=440\n"
    )


@pytest.mark.parametrize("suffix", [".dot", ".mmd", ".svg"])
def test_render(runner: CliRunner, tmp_path: Path, suffix: str) -> None:
    out = tmp_path / f"pour{suffix}"
    result = runner.invoke(main, ["graph", "render", str(POUR), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output == f"wrote {out}\n"
    assert "#e377c2" in out.read_text()


def test_render_unknown_format_fails_cleanly(runner: CliRunner, tmp_path: Path) -> None:
    result = runner.invoke(main, ["graph", "render", str(POUR), "-o", str(tmp_path / "g.xyz")])
    assert result.exit_code == 2
    assert "unsupported file type '.xyz'" in result.output


def test_render_of_unloadable_file(runner: CliRunner, tmp_path: Path) -> None:
    bad = tmp_path / "g.yaml"
    bad.write_text("task: [\n")
    result = runner.invoke(main, ["graph", "render", str(bad), "-o", str(tmp_path / "g.dot")])
    assert result.exit_code == 2
    assert result.output.startswith(f"{bad}: line 2, column 1: invalid YAML:")


def test_filter_refuses_to_overwrite_its_own_input(runner: CliRunner, tmp_path: Path) -> None:
    path = _regressive(tmp_path)
    before = path.read_text()
    result = runner.invoke(main, ["graph", "filter", str(path), "-o", str(path)])
    assert result.exit_code == 2, result.output
    assert "FILE" in result.output and path.read_text() == before  # its comments and the branch kept


def test_filter_says_what_it_removes_and_why(runner: CliRunner, tmp_path: Path) -> None:
    path = _regressive(tmp_path)
    out = tmp_path / "filtered.yaml"
    result = runner.invoke(main, ["graph", "filter", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.splitlines() == [
        f"{path}: remove bottle_dropped on e2 -> e2_r_bottle_dropped (r = r_bottle_regrasped, v_i = v1): "
        "D(r_bottle_regrasped, goal)=730  >  D(v1, goal)=440",
        f"{path}: unreachable after removal: edges e2_r_bottle_dropped, r_bottle_regrasped_to_v2; "
        "nodes r_bottle_regrasped",
        f"wrote {out}",
    ]
    filtered = load_graph(out)
    assert filtered.edge("e2").failures == []
    assert runner.invoke(main, ["graph", "check", str(out)]).exit_code == 0


def test_filter_with_nothing_to_remove(runner: CliRunner) -> None:
    result = runner.invoke(main, ["graph", "filter", str(POUR)])
    assert result.exit_code == 0
    assert result.output == f"{POUR}: nothing to remove (3 recovery branches, all forward-moving)\n"


def test_filter_of_graph_with_dangling_reference(runner: CliRunner, tmp_path: Path) -> None:
    data = yaml.safe_load(POUR.read_text())
    data["edges"][1]["failures"][0]["recovery"] = "missing"
    path = _write(tmp_path, data)
    result = runner.invoke(main, ["graph", "filter", str(path)])
    assert result.exit_code == 2
    assert "unknown edge 'missing'" in result.output and f"agentchord graph check {path}" in result.output


def test_render_style_full_keeps_every_detail_on_the_arcs(runner: CliRunner, tmp_path: Path) -> None:
    readable, full = tmp_path / "r.dot", tmp_path / "f.dot"
    assert runner.invoke(main, ["graph", "render", str(POUR), "-o", str(readable)]).exit_code == 0
    result = runner.invoke(main, ["graph", "render", str(POUR), "-o", str(full), "--style", "full"])
    assert result.exit_code == 0, result.output
    assert "rankdir=TB" in readable.read_text() and "rankdir=LR" in full.read_text()
    assert "when bottle_dropped on e2" in full.read_text()


def _with_goal(tmp_path: Path, goals: list[dict]) -> Path:
    from agentchord.library import library_path

    data = yaml.safe_load(Path(library_path("single_arm_pour_water")).read_text())
    data["success"] = {"judge": "goal", "goal_spec": {"goals": goals}}
    return _write(tmp_path, data)


def test_check_refuses_a_goal_spec_run_would_refuse(runner: CliRunner, tmp_path: Path) -> None:
    """``graph check`` validates the goal the graph is judged by, as ``run`` does (it said ok, run said no)."""
    path = _with_goal(tmp_path, [{"kind": "stacked", "obj": "cup"}])
    result = runner.invoke(main, ["graph", "check", str(path)])
    assert result.exit_code == 2 and "success.goal_spec.goals[0]: Input tag 'stacked'" in result.output
    run = runner.invoke(main, ["run", "single_arm_pour_water", "--graph", str(path)])
    assert run.exit_code == 2 and "success.goal_spec.goals[0]: Input tag 'stacked'" in run.output


def test_a_goal_naming_an_object_the_scene_lacks_is_refused_before_the_robot_moves(runner: CliRunner, tmp_path: Path) -> None:
    """It ran the whole episode and ended on an internal error (``KeyError: 'mug'``) when judged."""
    path = _with_goal(tmp_path, [{"kind": "inside", "obj": "bottle", "container": "mug"}])
    result = runner.invoke(main, ["graph", "check", str(path), "--task", "single_arm_pour_water"])
    assert result.exit_code == 2 and "goals[0].container: the single_arm_pour_water scene has no object 'mug'" in result.output
    run = runner.invoke(main, ["run", "single_arm_pour_water", "--graph", str(path)])
    assert run.exit_code == 2 and "has no object 'mug'" in run.output
