"""The ``agentchord run`` and ``agentchord demo`` commands: outputs and exit statuses."""

import json

import pytest
from click.testing import CliRunner

from agentchord.cli import main


def test_run_prints_the_path_writes_trace_and_summary_and_exits_0(tmp_path):
    trace, summary = tmp_path / "trace.jsonl", tmp_path / "episode.json"
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--seed", "1", "--trace", str(trace), "--json", str(summary)])
    assert result.exit_code == 0, result.output
    assert "path: v0 -> e1 -> v1" in result.output
    data = json.loads(summary.read_text())
    assert {"success", "steps", "time_s", "failures_detected", "recoveries", "path"} <= set(data)
    assert data["success"] is True and data["path"][-1] == "v6"
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    assert events[0]["event"] == "episode_start" and events[-1]["event"] == "episode_end"


def test_run_exits_1_when_the_task_fails(tmp_path):
    graph = tmp_path / "stop_early.yaml"
    # A graph whose goal is the grasp: the pour never happens, so the task check fails.
    graph.write_text(
        "task: single_arm_pour_water\nobjects: [bottle, cup]\nstart: v0\ngoal: v1\n"
        "nodes: [{id: v0, semantic: start}, {id: v1, semantic: held}]\n"
        "edges: [{id: e1, source: v0, target: v1, actions: {right: {fn: grasp, args: {obj: bottle}}}}]\n"
    )
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--graph", str(graph)])
    assert result.exit_code == 1, result.output
    assert "never reached a pouring orientation" in result.output


def test_run_exits_2_on_bad_input(tmp_path):
    runner = CliRunner()
    assert runner.invoke(main, ["run", "no_such_task"]).exit_code == 2
    assert runner.invoke(main, ["run", "single_arm_pour_water", "--p", "1.5"]).exit_code == 2
    bad = tmp_path / "bad.yaml"
    bad.write_text("task: t\nstart: v0\ngoal: v9\nnodes: [{id: v0, semantic: s}]\nedges: []\n")
    result = runner.invoke(main, ["run", "single_arm_pour_water", "--graph", str(bad)])
    assert result.exit_code == 2
    assert f"{bad}: goal: unknown node 'v9'" in result.output


def test_demo_writes_the_aggregates_of_each_strategy(tmp_path):
    out = tmp_path / "demo.json"
    result = CliRunner().invoke(main, ["demo", "--trials", "1", "--p", "0", "--workers", "1", "--json", str(out)])
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    assert data["p"] == 0 and data["trials"] == 1
    for name in ("agentchord", "agentchord-bt"):
        stats = data["strategies"][name]
        assert stats["success_rate"] == 1.0
        assert {"mean_steps", "mean_time_s", "drops_injected", "drops_recovered", "reaction_latency_ticks_max"} <= set(stats)


def test_demo_refuses_an_unknown_strategy():
    result = CliRunner().invoke(main, ["demo", "--strategies", "magic"])
    assert result.exit_code == 2
    assert "unknown strategy" in result.output


def test_plan_writes_a_valid_augmented_graph_and_renders_it(tmp_path):
    from agentchord.graph.loader import load_graph
    from agentchord.graph.validation import check_graph

    out, figure = tmp_path / "g.yaml", tmp_path / "g.mmd"
    result = CliRunner().invoke(main, ["plan", "put the red block into the cup", "--task", "blocks_and_cup", "-o", str(out), "--render", str(figure)])
    assert result.exit_code == 0, result.output
    graph = load_graph(out)
    assert check_graph(graph) == [] and graph.recovery_edges()
    assert figure.read_text().startswith("flowchart")


def test_plan_from_a_goal_spec_file(tmp_path):
    goal = tmp_path / "goal.yaml"
    goal.write_text("goals:\n  - {kind: on_top_of, obj: red_block, support: blue_block}\n")
    result = CliRunner().invoke(main, ["plan", "--goal", str(goal), "--task", "blocks_and_cup", "-o", str(tmp_path / "g.yaml")])
    assert result.exit_code == 0, result.output


def test_plan_refuses_what_it_cannot_ground_with_exit_2():
    result = CliRunner().invoke(main, ["plan", "juggle the cup", "--task", "blocks_and_cup", "-o", "/tmp/never.yaml"])
    assert result.exit_code == 2
    assert "no rule reads the clause 'juggle the cup'" in result.output and "--reasoner llm" in result.output


def test_schema_goal_prints_the_goal_spec_schema():
    import json

    result = CliRunner().invoke(main, ["schema", "goal"])
    assert result.exit_code == 0 and "goals" in json.loads(result.output)["properties"]


def test_plan_with_the_llm_reasoner_against_a_replay_server(tmp_path, monkeypatch):
    # The replies an LLM would give (here: what the rules answer), served by a local replay server.
    import numpy as np
    from replay_server import Completion, ReplayServer

    from agentchord.agents.observe import observe, task_regions
    from agentchord.agents.pipeline import plan_task
    from agentchord.agents.rules import RulesReasoner
    from agentchord.graph.loader import load_graph
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.world import SimWorld

    sim = SIM_TASKS["blocks_and_cup"]
    scene = observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))
    rules = RulesReasoner()
    plan_task("put the red block into the cup", scene, rules, "blocks_and_cup")
    with ReplayServer() as server:
        for call in rules.calls:
            server.push(Completion(json.dumps(call.reply)))
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "replay-model")
        monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "test-key")
        out = tmp_path / "g.yaml"
        result = CliRunner().invoke(main, ["plan", "put the red block into the cup", "--task", "blocks_and_cup",
                                           "--reasoner", "llm", "-o", str(out)])
        assert result.exit_code == 0, result.output
        assert len(server.requests) == 3
    assert load_graph(out).recovery_edges()


def test_run_prints_which_arm_a_recovery_was_bound_to_under_the_real_protocol():
    from click.testing import CliRunner

    from agentchord.cli import main

    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--protocol", "real", "--seed", "16"])
    assert result.exit_code in (0, 1), result.output
    assert "disturbance" in result.output and "recovery bound to" in result.output


@pytest.mark.parametrize("seed,line", [
    (9, "sub-goal met: v5 already holds"),  # pulled out of the hand while being put down, set down upright
    (5, "merged ahead: at v2, v3 reached before the failure and v4 holds: e3, e4 skipped"),  # taken mid-pour
])
def test_run_prints_a_recovery_that_had_nothing_left_to_do(seed, line):
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--protocol", "real", "--seed", str(seed)])
    assert result.exit_code == 0, result.output
    assert line in " ".join(result.output.split())  # the console wraps long lines


class _FakeVideo:
    """What ``_write_video`` asks of a recorder: ``path`` set, then ``write``."""

    path = None

    def write(self):
        self.path.write_bytes(b"mp4")
        return self.path


def test_a_video_output_that_is_a_symlink_is_written_through_to_its_target(tmp_path):
    from agentchord.cli.episode import _write_video

    target, link = tmp_path / "real.mp4", tmp_path / "link.mp4"
    target.write_bytes(b"old")
    link.symlink_to(target)
    _write_video(_FakeVideo(), link)
    assert link.is_symlink() and target.read_bytes() == b"mp4"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.mp4", "real.mp4"]


# ---------------------------------------------------------------------------- a graph judged by its own goal (issue 43)
HANDOVER = "hand the bottle to the left arm, then put it down"


def test_plan_writes_what_success_means_for_the_graph(tmp_path):
    import yaml

    from agentchord.library import load_task_graph

    own, other = tmp_path / "own.yaml", tmp_path / "other.yaml"
    runner = CliRunner()
    result = runner.invoke(main, ["plan", HANDOVER, "--task", "single_arm_pour_water", "-o", str(other)])
    assert result.exit_code == 0, result.output
    assert "success: judged by this graph's own goal (v5)" in " ".join(result.output.split())
    success = yaml.safe_load(other.read_text())["success"]
    assert success["judge"] == "goal"
    assert [g["kind"] for g in success["goal_spec"]["goals"]] == ["handed_over", "placed"]
    instruction = load_task_graph("single_arm_pour_water").instruction
    result = runner.invoke(main, ["plan", instruction, "--task", "single_arm_pour_water", "-o", str(own)])
    assert result.exit_code == 0, result.output
    assert "success" not in yaml.safe_load(own.read_text())  # the task's own check: the default, not written


def test_a_graph_whose_goal_spec_is_invalid_is_refused(tmp_path):
    import yaml

    from agentchord.library import library_path

    data = yaml.safe_load(library_path("single_arm_pour_water").read_text())
    data["success"] = {"judge": "goal", "goal_spec": {"goals": [{"kind": "levitated", "obj": "bottle"}]}}
    graph = tmp_path / "g.yaml"
    graph.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--graph", str(graph)])
    assert result.exit_code == 2, result.output
    assert f"{graph}: success.goal_spec.goals[0]" in result.output
    data["success"] = {"judge": "maybe"}
    graph.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--graph", str(graph)])
    assert result.exit_code == 2 and "success.judge" in result.output, result.output


def test_run_judges_a_planned_graph_by_its_own_goal(tmp_path):
    graph = tmp_path / "handover.yaml"
    assert CliRunner().invoke(main, ["plan", HANDOVER, "--task", "single_arm_pour_water", "-o", str(graph)]).exit_code == 0
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--graph", str(graph)])
    assert result.exit_code == 0, result.output
    assert "SUCCESS: every goal predicate holds at the end" in result.output


def test_run_and_demo_accept_every_method_bench_compares():
    from agentchord.cli.episode import METHOD_NAMES
    from agentchord.execution.methods import METHODS

    assert set(METHOD_NAMES) == set(METHODS)


@pytest.mark.parametrize("args", [
    ["run", "blocks_and_cup"],
    ["demo", "--task", "blocks_and_cup", "--trials", "1"],
    ["bench", "--tasks", "blocks_and_cup", "--trials", "1"],
])
def test_a_task_without_a_library_graph_is_refused_up_front_not_run(args, tmp_path, monkeypatch):
    """blocks_and_cup has no fixed goal: without --instruction or --goal there is nothing to run (issue 58)."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, args + (["--out", str(tmp_path / "b")] if args[0] == "bench" else []))
    assert result.exit_code == 2, result.output
    assert "blocks_and_cup" in result.output and "library graph" in result.output


def test_run_prints_names_from_a_graph_file_as_written(tmp_path):
    """Rich markup in a node id or a failure name is printed as text, never interpreted (issue 58)."""
    import yaml

    from agentchord.library import library_path

    data = yaml.safe_load(library_path("single_arm_pour_water").read_text())
    data["start"] = "[link=file:///etc/passwd]v0"
    for node in data["nodes"]:
        if node["id"] == "v0":
            node["id"] = data["start"]
    for edge in data["edges"]:
        for end in ("source", "target"):
            if edge[end] == "v0":
                edge[end] = data["start"]
    path = tmp_path / "g.yaml"
    path.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--graph", str(path), "--seed", "1"])
    assert "[link=file:///etc/passwd]v0" in result.output, result.output


def test_demo_json_has_no_p_under_a_protocol_and_names_each_failed_seed(tmp_path):
    """Issue 61: `demo --protocol real --json` recorded "p": 0.1, which a protocol ignores."""
    import json

    out = tmp_path / "demo.json"
    result = CliRunner().invoke(main, ["demo", "--task", "single_arm_pour_water", "--trials", "1", "--protocol", "real",
                                       "--strategies", "agentchord", "--json", str(out)])
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    assert data["p"] is None and data["protocol"] == "real"
    assert all(f.startswith("seed ") for f in data["strategies"]["agentchord"]["failures"])


def test_a_plan_the_reasoner_refuses_is_not_preceded_by_a_usage_banner():
    """Issue 61: a refused instruction (exit 2) was printed after click's "Usage: ... Try --help" lines, as if the
    command line were wrong."""
    result = CliRunner().invoke(main, ["plan", "fold the towel side to side", "--task", "fold_towel", "-o", "/tmp/unused.yaml"])
    assert result.exit_code == 2 and "cannot ground the instruction" in result.output
    assert "Usage:" not in result.output and "--help" not in result.output


def test_run_says_what_each_node_means():
    """Issue 61: `run` printed node ids (`v3`) without their meaning."""
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--seed", "0"], terminal_width=200)
    assert result.exit_code == 0, result.output
    assert "node v1 (Right gripper holds the bottle)" in result.output
