"""The paper's table layouts, confidence intervals, the ordering check and the figures."""

import pytest

from agentchord.bench.figures import steps_figure, stress_figure
from agentchord.bench.tables import cell, ordering, summary_csv, table_layout, table_markdown


def _record(method, seed, success, exec_time, steps, p=0.1, task="single_arm_pour_water", disturbed=1):
    return {"id": f"{task}|{method}|p={p}|{seed}", "task": task, "method": method, "condition": f"p={p:g}", "p": p,
            "protocol": None, "seed": seed, "success": success, "exec_time_s": exec_time, "robot_time_s": exec_time - 7,
            "reasoning_s": 7.0, "steps": steps, "disturbances_injected": disturbed, "reasoning_calls": {"plan": 1}, "replans": 0}


def _records():
    out = []
    for seed in range(4):
        out.append(_record("agentchord", seed, True, 30.0 + seed, 800, disturbed=seed % 2))
        out.append(_record("rekep", seed, seed != 0, 40.0 + seed, 1000))
    return out


def test_a_cell_counts_successes_and_averages_time_over_successes():
    c = cell([r for r in _records() if r["method"] == "rekep"])
    assert (c.n, c.successes) == (4, 3)
    assert c.time_s == pytest.approx(42.0)  # seeds 1-3: 41, 42, 43
    low, high = c.time_ci
    assert low < 42.0 < high
    assert c.success_ci[0] < 0.75 < c.success_ci[1]
    assert c.steps_disturbed == 1000


def test_table_one_layout_has_a_row_per_task_and_condition_and_an_average():
    header, rows = table_layout(_records())
    assert header[:4] == ["Task", "Condition", "Success % ReKep", "Success % AgentChord"]
    assert rows[0][:2] == ["Single-arm pour water", "p=0.1"]
    assert rows[0][2].startswith("75 [") and rows[0][3].startswith("100 [")
    assert rows[-1][0] == "Average"
    markdown = table_markdown(_records(), "Table I", "caption")
    assert markdown.startswith("### Table I") and "| Average |" in markdown and markdown.rstrip().endswith("caption")


def test_ordering_says_whether_agentchord_leads():
    lead = ordering(_records())
    assert lead["success"]["best"] and lead["exec_time_s"]["best"] and lead["steps_disturbed"]["best"]
    worse = [{**r, "exec_time_s": r["exec_time_s"] + (50 if r["method"] == "agentchord" else 0)} for r in _records()]
    assert not ordering(worse)["exec_time_s"]["best"]


def test_summary_csv_has_one_row_per_group():
    lines = summary_csv(_records()).strip().splitlines()
    assert lines[0].startswith("task,condition,method,episodes")
    assert len(lines) == 3


def test_figures_are_png():
    records = _records() + [_record("agentchord", s, True, 30.0, 800, p=0.3) for s in range(2)]
    assert stress_figure(records).startswith(b"\x89PNG")
    assert steps_figure(records).startswith(b"\x89PNG")
    assert stress_figure(_records()) is None  # one value of p: no curve


def test_every_table_of_a_full_sweep_fits_a_terminal_of_120_characters():
    """Issue 60: Tables I and II were Markdown of 37 columns. Now the paper's own columns (success with its
    interval, execution time) are the main table, a row per method, and the rest have tables of their own."""
    from agentchord.execution.methods import METHODS

    records = [{**_record(method, seed, seed != 1, 30.0 + seed, 900, p=p, task=task), "first_motion_s": 1.5,
                "critical_reasoning_s": 1.2}
               for task in ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block",
                            "setup_coffee_tray", "fold_towel")
               for method in METHODS for seed in range(3) for p in (0.05, 0.1)]
    markdown = table_markdown(records, "Table I: random drops", "caption")
    assert max(len(line) for line in markdown.splitlines()) <= 120
    assert "| Method | Success % [95% CI] | Exec. time s |" in markdown
    assert "time to the first motion" in markdown and "steps of the disturbed episodes" in markdown
