"""An episode's result: execution time, the unrecoverable outcome, the JSON summary."""

from agentchord.execution.result import UNRECOVERABLE, EpisodeResult
from agentchord.execution.trace import Trace


def _result(reason="poured", **extra):
    fields = dict(success=False, reason=reason, steps=500, time_s=10.0, wall_s=1.23456, path=["v0", "e1"],
                  failures_detected=1, recoveries=1, repairs=0, drops_injected=1, drops_detected=1, drops_recovered=0,
                  reaction_latency_ticks=[3], disturbances={"drop": [1, 1, 0]}, trace=Trace())
    return EpisodeResult(**{**fields, **extra})


def test_execution_time_is_robot_time_plus_compute_plus_reasoning():
    assert _result(compute_s=0.5, reasoning_s=21.0).exec_time_s == 31.5


def test_unrecoverable_is_read_from_the_reason():
    assert _result(reason=f"{UNRECOVERABLE}: no arm can take cup").unrecoverable
    assert not _result(reason="tick limit 4000 reached").unrecoverable


def test_summary_rounds_times_and_keeps_the_counts():
    summary = _result(reaction_latency_s=[0.061234]).summary()
    assert summary["wall_s"] == 1.235 and summary["reaction_latency_s"] == [0.061]
    assert summary["robot_time_s"] == summary["time_s"] == 10.0
    assert summary["disturbances"] == {"drop": [1, 1, 0]} and summary["unrecoverable"] is False
