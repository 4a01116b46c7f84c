"""Where each method's time goes, and the pipelined plan's early failures against the sequential plan."""

import pytest

from agentchord.bench.pipeline import decomposition, early_failures, early_failures_markdown, regressions
from agentchord.bench.tables import table_layout


def _record(method, seed, success=True, first=2.0, robot=20.0, reasoning=None, wait=0.0, early=(), task="single_arm_pour_water"):
    reasoning = first if reasoning is None else reasoning
    return {"task": task, "method": method, "condition": "protocol=real", "seed": seed, "success": success,
            "reason": "ok" if success else "dropped", "exec_time_s": robot + reasoning, "robot_time_s": robot,
            "compute_s": 0.0, "reasoning_s": reasoning, "first_motion_s": first, "plan_wait_s": wait,
            "critical_reasoning_s": reasoning + wait, "early_failures": list(early), "steps": int(robot * 50),
            "disturbances_injected": 1, "reasoning_calls": {"plan": 1}, "replans": 0}


def test_the_parts_add_up_to_the_tables_time():
    records = [_record("rekep", 0, first=2.5, robot=20.0), _record("rekep", 1, first=2.5, robot=22.0),
               _record("inner-monologue", 0, first=5.0, robot=20.0, reasoning=15.0),
               _record("agentchord", 0, first=1.5, robot=24.0, wait=3.0), _record("agentchord", 1, success=False)]
    parts = decomposition(records)
    assert parts["rekep"]["exec_s"] == pytest.approx(23.5) and parts["rekep"]["after_s"] == 0.0
    assert parts["inner-monologue"]["after_s"] == pytest.approx(10.0)  # the VQA and next-step calls after the first motion
    assert parts["agentchord"] == pytest.approx({"first_motion_s": 1.5, "robot_s": 24.0, "after_s": 0.0, "plan_wait_s": 3.0,
                                                 "exec_s": 25.5})
    header, rows = table_layout(records, with_steps=False, with_condition=False)
    average = dict(zip(header, rows[-1]))
    assert average["Exec. time s ReKep"] == "23.5" and average["First motion s AgentChord"] == "1.5"
    assert average["Critical reasoning s AgentChord"] == "4.5"


def test_each_early_failure_is_named_with_its_outcome_and_the_sequential_plans():
    early = {"edge": "e2", "failure": "bottle_dropped", "tick": 200, "waited_ticks": 150, "then": "recovery for bottle_dropped"}
    records = [_record("agentchord", 0, early=[early]), _record("agentchord-sequential", 0),
               _record("agentchord", 1, success=False, early=[early]), _record("agentchord-sequential", 1),
               _record("agentchord", 2, success=False, early=[early]), _record("agentchord-sequential", 2, success=False)]
    rows = early_failures(records)
    assert [(e["seed"], e["success"], e["sequential"], e["waited_s"]) for e in rows] == [
        (0, True, True, 3.0), (1, False, True, 3.0), (2, False, False, 3.0)]
    assert [e["seed"] for e in regressions(records)] == [1]  # lost where the sequential plan won
    text = early_failures_markdown(records)
    assert "3 in 3 of 3 pipelined episodes" in text and "1 in an episode that failed where the sequential plan" in text
