"""The schema of a sweep record: what the bench writes passes, what it cannot have written does not."""

import pytest

from agentchord.bench.record import check_record
from agentchord.bench.sweep import Condition, EpisodeKey, SweepConfig, error_record, run_record

KEY = EpisodeKey("single_arm_pour_water", "agentchord", Condition(protocol="real"), 0)


@pytest.fixture(scope="module")
def written() -> dict:
    return run_record(KEY, SweepConfig())


def test_a_record_the_bench_writes_is_valid(written):
    assert written["success"] and check_record(written) == []


def test_an_error_record_is_valid_without_metrics():
    record = error_record(KEY, KeyError("x"), 0.5)
    assert check_record(record) == []
    assert check_record({**record, "traceback": None}) == ["traceback: Input should be a valid string (got None)"]


@pytest.mark.parametrize(("change", "problem"), [
    ({"p": 0.1}, "either p (a drop sweep) or protocol"),
    ({"protocol": "stress"}, "condition 'protocol=real' does not match p/protocol ('protocol=stress')"),
    ({"reaction_latency_s": [float("inf")]}, "reaction_latency_s.0: Input should be a finite number"),
    ({"reasoning_calls": {"plan": -1}}, "reasoning_calls.plan: Input should be greater than or equal to 0"),
    ({"version": 2}, "version: Input should be less than or equal to 1"),
])
def test_a_value_the_bench_cannot_have_written_is_named(written, change, problem):
    problems = check_record({**written, **change})
    assert any(problem in line for line in problems), problems


def test_a_line_that_is_not_an_object_is_refused():
    assert check_record([1, 2]) == ["expected a record object, found list"]
