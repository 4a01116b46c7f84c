"""Sweep keys (``bench/sweep.py``): every condition named exactly, every task and method once."""

from __future__ import annotations

from agentchord.bench.sweep import Condition, sweep_keys


def test_two_different_probabilities_never_share_a_label():
    assert Condition(p=0.1234567).label != Condition(p=0.1234568).label
    assert Condition(p=0.1234567).label == "p=0.1234567"
    assert Condition(p=1e-7).label != Condition(p=1.1e-7).label
    for p in (0.1234567, 1e-7, 0.30000000000000004):
        assert Condition.from_label(Condition(p=p).label) == Condition(p=p)


def test_the_usual_labels_are_unchanged():
    assert [Condition(p=p).label for p in (0.0, 0.05, 0.1, 0.3, 1.0)] == ["p=0", "p=0.05", "p=0.1", "p=0.3", "p=1"]
    assert Condition(protocol="real").label == "protocol=real"


def test_an_odd_spelling_names_the_same_condition():
    assert Condition(p=-0.0) == Condition(p=0.0) and Condition(p=-0.0).label == "p=0"
    assert Condition(p=float("0.10")).label == Condition(p=0.1).label


def test_a_task_method_or_condition_named_twice_runs_once():
    keys = sweep_keys(["t", "t"], ["m", "n", "m"], [Condition(p=0.1), Condition(p=0.10), Condition(p=-0.0)], 2)
    ids = [k.id for k in keys]
    assert len(ids) == len(set(ids)) == 1 * 2 * 2 * 2


def test_bench_counts_a_task_or_method_named_twice_once(tmp_path):
    from click.testing import CliRunner

    from agentchord.cli import main

    task = "single_arm_pour_water"
    result = CliRunner().invoke(main, ["bench", "--out", str(tmp_path), "--tasks", f"{task},{task}", "--methods",
                                       "agentchord,agentchord", "--p", "0,-0", "--trials", "1", "--workers", "1"])
    assert result.exit_code == 0, result.output
    assert "1 task(s) x 1 method(s) x p=0 x 1 seeds = 1 episodes" in " ".join(result.output.split())
    assert len((tmp_path / "records.jsonl").read_text().splitlines()) == 1
