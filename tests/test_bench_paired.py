"""Paired comparisons of one method against the others on the same episodes."""

import csv
import io

import pytest

from agentchord.bench.paired import common_steps, paired_csv, paired_markdown, paired_rows


def _record(method, seed, success, exec_time, steps, disturbed=1, compute=0.0, task="single_arm_pour_water"):
    return {"task": task, "method": method, "condition": "protocol=real", "seed": seed, "success": success,
            "exec_time_s": exec_time, "robot_time_s": exec_time - 21.0 - compute, "compute_s": compute,
            "steps": steps, "disturbances_injected": disturbed}


def _records():
    # AgentChord: 800 steps where disturbed, 30 s. ReKep fails seed 0 (the hard one) and takes
    # 700 steps where it completes: on its own successes it looks cheaper than on the pairs.
    out = []
    for seed in range(4):
        out.append(_record("agentchord", seed, True, 30.0 + seed, 1400 if seed == 0 else 800, disturbed=int(seed != 3)))
        out.append(_record("rekep", seed, seed != 0, 20.0 + seed, 700 + 100 * seed, disturbed=int(seed != 3)))
    return out


def test_pairs_are_the_episodes_both_complete_and_steps_those_disturbed():
    (row,) = paired_rows(_records())
    assert row.method == "rekep" and row.both_complete == 3  # seeds 1-3
    assert row.exec_time_s.n == 3
    assert row.exec_time_s.reference == pytest.approx(32.0) and row.exec_time_s.other == pytest.approx(22.0)
    assert row.exec_time_s.mean == pytest.approx(10.0)
    assert row.exec_time_s.low == pytest.approx(10.0) and row.exec_time_s.high == pytest.approx(10.0)  # no spread
    assert row.exec_time_s.reference_better == 0
    # Steps: seeds 1 and 2 (seed 3 saw no disturbance): 800/800 against 800/900.
    assert row.steps.n == 2
    assert (row.steps.reference, row.steps.other) == (pytest.approx(800.0), pytest.approx(850.0))
    assert row.steps.reference_better == 1  # seed 2 strictly; seed 1 a tie
    assert row.steps.low < row.steps.mean < row.steps.high


def test_robot_and_compute_leave_out_the_reasoning_latency():
    records = [_record("agentchord", 0, True, 40.0, 900, compute=1.5), _record("doremi", 0, True, 60.0, 900)]
    (row,) = paired_rows(records)
    assert row.robot_and_compute_s.reference == pytest.approx(19.0)  # 40 - 21
    assert row.robot_and_compute_s.other == pytest.approx(39.0)


def test_a_method_with_no_common_success_has_empty_differences():
    records = [_record("agentchord", 0, True, 30.0, 800), _record("rekep", 0, False, 10.0, 300)]
    (row,) = paired_rows(records)
    assert row.both_complete == 0 and row.exec_time_s is None and row.steps is None
    assert "| ReKep | 0 | - |" in paired_markdown(records)


def test_common_steps_are_over_the_disturbed_episodes_every_method_completed():
    n, steps = common_steps(_records())
    assert n == 2  # seeds 1 and 2: seed 0 ReKep failed, seed 3 undisturbed
    assert steps == {"rekep": pytest.approx(850.0), "agentchord": pytest.approx(800.0)}
    assert "Steps over the 2 disturbed episodes every method completed: ReKep 850, AgentChord 800." in paired_markdown(_records())


def test_paired_csv_has_a_row_per_other_method_with_every_number():
    rows = list(csv.DictReader(io.StringIO(paired_csv(_records()))))
    assert len(rows) == 1 and rows[0]["method"] == "rekep" and rows[0]["both_complete"] == "3"
    assert float(rows[0]["exec_time_s_mean"]) == pytest.approx(10.0)
    assert rows[0]["steps_n"] == "2"


def test_a_reference_without_records_is_refused():
    with pytest.raises(ValueError, match="no records of 'agentchord'"):
        paired_rows([_record("rekep", 0, True, 20.0, 700)])


def test_one_pair_is_shown_without_a_degenerate_interval():
    """Issue 61: the paired table printed "+165 [+165, +165]" for a difference of one pair."""
    from agentchord.bench.paired import Difference, _cells

    one = Difference(n=1, reference=1000.0, other=1165.0, low=-165.0, high=-165.0, reference_better=1)
    assert _cells(one, 0)[1] == "-165 (no interval: 1 pair)"
    many = Difference(n=3, reference=1000.0, other=1165.0, low=-200.0, high=-130.0, reference_better=3)
    assert _cells(many, 0)[1] == "-165 [-200, -130]"
