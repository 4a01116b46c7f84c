"""``agentchord bench``: bad input exits 2; a sweep killed midway resumes without losing or repeating an episode."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from agentchord.cli import main


def test_bad_options_exit_2(tmp_path):
    runner = CliRunner()
    out = str(tmp_path / "sweep")
    for args in (["--p", "0.1,1.5"], ["--p", "nan"], ["--p", "0.1", "--protocol", "real"], ["--methods", "magic"],
                 ["--tasks", "no_such_task"], ["--latency", "plan=-1"], ["--ray-address", "auto"]):
        result = runner.invoke(main, ["bench", *args, "--out", out])
        assert result.exit_code == 2, (args, result.output)
    blocked = tmp_path / "file"
    blocked.write_text("x")
    result = runner.invoke(main, ["bench", "--p", "0", "--out", str(blocked)])
    assert result.exit_code == 2


def _ids(directory: Path) -> list[str]:
    lines = (directory / "records.jsonl").read_bytes().split(b"\n")
    return [json.loads(line)["id"] for line in lines if line.strip()]


def test_a_sweep_killed_midway_loses_and_repeats_nothing(tmp_path):
    out = tmp_path / "sweep"
    args = [sys.executable, "-m", "agentchord.cli", "bench", "--tasks", "single_arm_pour_water", "--methods", "agentchord",
            "--p", "0", "--trials", "3", "--workers", "1", "--out", str(out)]
    process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 120
    while time.time() < deadline and not ((out / "records.jsonl").exists() and len(_ids(out)) >= 1):
        time.sleep(0.2)
    os.killpg(process.pid, signal.SIGKILL)  # kill -9, mid-sweep
    process.wait()
    before = _ids(out)
    assert 1 <= len(before) < 3
    result = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    after = _ids(out)
    assert after[: len(before)] == before  # nothing lost
    assert sorted(after) == sorted(set(after)) and len(after) == 3  # nothing repeated
    assert f"{len(before)} already in" in " ".join(result.stdout.split())
    assert (out / "tables" / "table1.md").exists()


def test_an_episode_that_raises_is_a_row_not_the_end_of_the_sweep(tmp_path, monkeypatch):
    import agentchord.bench.sweep as sweep

    real = sweep.run_episode

    def buggy(spec, *args, **kwargs):
        if spec.seed == 1:
            raise KeyError("a bug in one episode")
        return real(spec, *args, **kwargs)

    monkeypatch.setattr(sweep, "run_episode", buggy)
    out = tmp_path / "sweep"
    args = ["bench", "--tasks", "single_arm_pour_water", "--methods", "agentchord", "--p", "0", "--trials", "3",
            "--workers", "1", "--out", str(out)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 3, result.output
    assert "1 episode(s) stopped on an internal error" in " ".join(result.output.split())
    records = [json.loads(line) for line in (out / "records.jsonl").read_text().splitlines()]
    assert [r["seed"] for r in records if "error" in r] == [1]
    error = next(r for r in records if "error" in r)
    assert error["error"] == "KeyError: 'a bug in one episode'" and "buggy" in error["traceback"]
    # The tables count the two finished episodes only, and say why.
    summary = (out / "tables" / "summary.csv").read_text().splitlines()
    assert summary[1].split(",")[3:5] == ["2", "2"]  # episodes, successes
    assert "1 episode(s) that stopped on an internal error are left out" in (out / "tables" / "table1.md").read_text()
    # Fixed: a rerun runs only that episode again.
    monkeypatch.setattr(sweep, "run_episode", real)
    again = CliRunner().invoke(main, args)
    assert again.exit_code == 0, again.output
    assert "2 already in" in " ".join(again.output.split())
    assert _ids(out) == [r["id"] for r in records] + ["single_arm_pour_water|agentchord|p=0|1"]


def test_an_llm_sweep_needs_the_llm_settings_before_any_episode(tmp_path, monkeypatch):
    for name in [k for k in os.environ if k.startswith("AGENTCHORD_LLM_")]:
        monkeypatch.delenv(name)
    result = CliRunner().invoke(main, ["bench", "--reasoner", "llm", "--p", "0", "--out", str(tmp_path / "sweep")])
    assert result.exit_code == 2
    assert "AGENTCHORD_LLM_BASE_URL" in result.output and not (tmp_path / "sweep" / "records.jsonl").exists()


def test_an_llm_sweep_plans_every_episode_and_charges_what_the_calls_measured(tmp_path, monkeypatch):
    # The replies an LLM would give (what the rules answer for the same scene), from a local replay server.
    from replay_server import Completion, ReplayServer

    from agentchord.agents.observe import observe, task_regions
    from agentchord.agents.pipeline import plan_task
    from agentchord.agents.rules import RulesReasoner
    from agentchord.library import load_task_graph
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.trial import open_world

    task = "single_arm_pour_water"
    rules = RulesReasoner()
    plan_task(load_task_graph(task).instruction, observe(open_world(task, 0), task_regions(SIM_TASKS[task])), rules, task)
    out = tmp_path / "sweep"
    with ReplayServer() as server:
        for call in rules.calls:
            server.push(Completion(json.dumps(call.reply), delay_s=0.2))
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "replay-model")
        monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "test-key")
        result = CliRunner().invoke(main, ["bench", "--reasoner", "llm", "--tasks", task, "--methods", "agentchord",
                                           "--p", "0", "--trials", "1", "--workers", "1", "--out", str(out)])
        assert result.exit_code == 0, result.output
        assert len(server.requests) == 3  # composer, arranger, conductor
    (record,) = [json.loads(line) for line in (out / "records.jsonl").read_text().splitlines()]
    assert record["success"], record["reason"]
    # AgentChord's plan is pipelined: the robot waited for the composer's measured call (about 0.2 s), not for
    # modelled ones; the arranger and conductor answered while it moved.
    assert 0.15 <= record["reasoning_s"] < 2.0, record["reasoning_s"]
    assert record["first_motion_s"] == pytest.approx(record["reasoning_s"] + record["compute_s"], abs=1e-3)
    assert json.loads((out / "sweep.json").read_text())["reasoner"] == "llm"
    assert "planning calls measured" in " ".join(result.output.split())


def test_the_report_of_several_methods_has_the_paired_table(tmp_path):
    from agentchord.bench.sweep import SweepConfig
    from agentchord.cli.bench import write_report

    def record(method, seed, success, exec_time, steps):
        return {"id": f"single_arm_pour_water|{method}|protocol=real|{seed}", "task": "single_arm_pour_water",
                "method": method, "condition": "protocol=real", "p": None, "protocol": "real", "seed": seed,
                "success": success, "exec_time_s": exec_time, "robot_time_s": exec_time - 7.0, "compute_s": 0.0,
                "reasoning_s": 7.0, "steps": steps, "disturbances_injected": 1, "reasoning_calls": {"plan": 1}, "replans": 0}

    records = [record(m, seed, True, 30.0 + seed, 900 + seed) for m in ("rekep", "agentchord") for seed in range(3)]
    written = write_report(records, tmp_path, SweepConfig(), None, trials=3, first_seed=0)
    assert tmp_path / "tables" / "paired.md" in written and tmp_path / "tables" / "paired.csv" in written
    assert "| ReKep | 3 |" in (tmp_path / "tables" / "paired.md").read_text()
    # Modelled latencies: the same episodes priced at other latencies; measured LLM calls are not re-priced.
    assert tmp_path / "tables" / "latency.md" in written
    assert "AgentChord takes the same time as ReKep at every latency" in (tmp_path / "tables" / "latency.md").read_text()
    measured = write_report(records, tmp_path / "llm", SweepConfig(reasoner="llm"), None, trials=3, first_seed=0)
    assert not any(path.name.startswith("latency") for path in measured)


def _llm_env(monkeypatch, server, model="replay-model"):
    monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
    monkeypatch.setenv("AGENTCHORD_LLM_MODEL", model)
    monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "test-key")
    monkeypatch.setenv("AGENTCHORD_LLM_DEADLINE_S", "3")


def test_an_llm_outage_is_the_same_rerun_record_for_every_method(tmp_path, monkeypatch):
    """Issue 58: during an outage an AgentChord episode counted as a task failure, while the same outage for
    agentchord-sequential became an internal-error record (exit 3). Now both are outage records: left out
    of the tables, reported, run again on a rerun; exit 1 (the sweep is not complete)."""
    from replay_server import Completion, HttpError, ReplayServer

    from agentchord.agents.observe import observe, task_regions
    from agentchord.agents.pipeline import plan_task
    from agentchord.agents.rules import RulesReasoner
    from agentchord.library import load_task_graph
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.trial import open_world

    task = "single_arm_pour_water"
    rules = RulesReasoner()
    plan_task(load_task_graph(task).instruction, observe(open_world(task, 0), task_regions(SIM_TASKS[task])), rules, task)
    composed = json.dumps(rules.calls[0].reply)
    out = tmp_path / "sweep"
    # The pipelined method's composer answers, then the endpoint goes down; the sequential one meets it at once.
    answers = iter([Completion(composed)])
    with ReplayServer(lambda body: next(answers, HttpError(503, "down"))) as server:
        _llm_env(monkeypatch, server)
        result = CliRunner().invoke(main, ["bench", "--reasoner", "llm", "--tasks", task, "--methods",
                                           "agentchord,agentchord-sequential", "--p", "0", "--trials", "1", "--workers", "1",
                                           "--out", str(out)])
    assert result.exit_code == 1, result.output
    assert "2 episode(s) could not reach the LLM" in " ".join(result.output.split())
    records = [json.loads(line) for line in (out / "records.jsonl").read_text().splitlines()]
    assert sorted(r["method"] for r in records) == ["agentchord", "agentchord-sequential"]
    assert all(r["outage"] and r["reason"].startswith("LLM outage: ") and "traceback" not in r for r in records)


def test_an_llm_sweep_resumed_with_another_model_is_refused(tmp_path, monkeypatch):
    """Issue 58: a --reasoner llm sweep resumed with another model or endpoint was accepted silently."""
    from replay_server import ReplayServer

    from agentchord.bench.store import RecordStore
    from agentchord.bench.sweep import SweepConfig

    out = tmp_path / "sweep"
    RecordStore(out, SweepConfig(reasoner="llm", llm={"model": "model-a", "endpoint": "http://127.0.0.1:1/v1"})).close()
    with ReplayServer() as server:
        _llm_env(monkeypatch, server, model="model-b")
        result = CliRunner().invoke(main, ["bench", "--reasoner", "llm", "--tasks", "single_arm_pour_water", "--methods",
                                           "agentchord", "--p", "0", "--trials", "1", "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "another configuration (llm differ)" in " ".join(result.output.split())
    manifest = json.loads((out / "sweep.json").read_text())
    assert manifest["llm"] == {"model": "model-a", "endpoint": "http://127.0.0.1:1/v1"}
