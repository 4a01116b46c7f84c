"""Execution times re-priced at other reasoning latencies: exact lines, their crossings, the table."""

import pytest

from agentchord.bench.latency import TimeLine, crossing, crossings_text, latency_csv, latency_rows, time_lines
from agentchord.bench.tables import table_layout


def _record(method, task, seed, robot, reasoning, success=True, compute=0.0):
    return {"task": task, "condition": "p=0.05", "p": 0.05, "protocol": None, "method": method, "seed": seed,
            "success": success, "robot_time_s": robot, "compute_s": compute, "reasoning_s": reasoning,
            "exec_time_s": round(robot + compute + reasoning, 2), "steps": 500, "disturbances_injected": 0,
            "reasoning_calls": {"plan": 1}, "replans": 0}


def _records():
    return [
        # AgentChord: three upfront calls (21 s), the robot a little faster.
        _record("agentchord", "single_arm_pour_water", 0, 14.0, 21.0, compute=0.5),
        _record("agentchord", "single_arm_pour_water", 1, 16.0, 21.0, compute=0.5),
        _record("agentchord", "rearrange_table", 0, 10.0, 21.0),
        # ReKep: one call (7 s); its failure is left out of the mean, as in the tables.
        _record("rekep", "single_arm_pour_water", 0, 17.0, 7.0),
        _record("rekep", "single_arm_pour_water", 1, 99.0, 7.0, success=False),
        _record("rekep", "rearrange_table", 0, 12.0, 7.0),
        # A re-planner: calls all along.
        _record("code-as-monitor", "single_arm_pour_water", 0, 16.0, 40.0),
        _record("code-as-monitor", "rearrange_table", 0, 11.0, 30.0),
    ]


def test_at_the_stated_latency_each_line_is_the_tables_average_row():
    records = _records()
    lines = time_lines(records)
    header, rows = table_layout(records, with_steps=False)
    average = dict(zip(header, rows[-1]))
    for method, short in (("agentchord", "AgentChord"), ("rekep", "ReKep"), ("code-as-monitor", "CaM")):
        assert f"{lines[method].at(1.0):.1f}" == average[f"Exec. time s {short}"]
    # Robot time + compute averaged per row, then over rows: (15.5 + 10) / 2 for AgentChord.
    assert lines["agentchord"] == TimeLine(base=12.75, reasoning=21.0, rows=2)
    assert lines["rekep"].base == pytest.approx(14.5)  # the failed episode is not in it


def test_two_lines_cross_once_and_the_side_is_named():
    agentchord, rekep = TimeLine(12.75, 21.0, 2), TimeLine(14.5, 7.0, 2)
    found = crossing(agentchord, rekep, "rekep")
    assert found.scale == pytest.approx(1.75 / 14.0) and found.faster_below
    assert agentchord.at(found.scale) == pytest.approx(rekep.at(found.scale))
    # Faster with no reasoning and with less of it: at every latency; slower in both: at none.
    assert crossing(agentchord, TimeLine(13.0, 35.0, 2), "cam").scale is None
    assert crossing(agentchord, TimeLine(13.0, 35.0, 2), "cam").faster_below
    assert not crossing(agentchord, TimeLine(12.0, 20.0, 2), "x").faster_below
    # Parallel lines never meet.
    assert crossing(agentchord, TimeLine(13.0, 21.0, 2), "y") == type(found)("y", None, True)


def test_the_table_names_the_fastest_at_each_scale_and_the_crossings_in_words():
    records = _records()
    header, rows = latency_rows(records, plan_s=7.0, scales=(0.0, 1.0))
    assert header[-1] == "Fastest" and header[2:5] == ["ReKep", "CaM", "AgentChord"]
    none, stated = rows
    assert none[:2] == ["0", "0"] and none[-1] == "AgentChord"
    assert stated[:2] == ["1", "7"] and stated[-1] == "ReKep"
    text = crossings_text(records, plan_s=7.0)
    assert "AgentChord is faster than ReKep below x0.12 the stated latencies (a planning call of 0.88 s)." in text
    assert "AgentChord is faster than CaM at every latency." in text
    assert "robot_and_compute_s" in latency_csv(records, 7.0)
