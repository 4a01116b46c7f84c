"""Aggregates of episode summaries."""

import pytest

from agentchord.bench.report import aggregate, paired_steps, wilson_interval


def _summary(seed, success, steps, drops=0, latencies=()):
    return {"seed": seed, "success": success, "steps": steps, "time_s": steps / 50, "wall_s": 1.0, "reason": "" if success else "x",
            "drops_injected": drops, "drops_detected": drops, "drops_recovered": drops if success else 0,
            "reaction_latency_ticks": list(latencies)}


def test_aggregate_counts_rates_and_latencies():
    runs = [_summary(0, True, 700), _summary(1, True, 900, drops=1, latencies=[3]), _summary(2, False, 300, drops=1, latencies=[4])]
    stats = aggregate(runs)
    assert stats["success_rate"] == pytest.approx(2 / 3)
    assert stats["mean_steps"] == pytest.approx(633.3, abs=0.1)
    assert stats["mean_steps_with_drop"] == 600.0
    assert stats["mean_steps_success_with_drop"] == 900.0
    assert stats["drops_injected"] == 2 and stats["drops_recovered"] == 1
    assert stats["reaction_latency_ticks_max"] == 4
    assert stats["failures"] == ["seed 2: x"]  # which seed failed (issue 61)
    # As bench's tables: the failed episode, which ended early, does not flatter the mean time (issue 61).
    assert stats["mean_time_s"] == pytest.approx((700 + 900) / 2 / 50)


def test_the_strategies_are_printed_side_by_side():
    import io

    from rich.console import Console

    from agentchord.bench.report import print_tables

    out = io.StringIO()
    results = {"agentchord": aggregate([_summary(0, True, 700)]), "agentchord-bt": aggregate([_summary(0, False, 300)])}
    print_tables(results, Console(file=out, width=200))
    text = out.getvalue()
    header = next(line for line in text.splitlines() if "metric" in line)
    assert "agentchord" in header and "agentchord-bt" in header  # one table, a column per strategy
    assert "agentchord-bt failed seed 0: x" in text


def test_paired_steps_uses_seeds_every_strategy_completed_after_a_drop():
    by_strategy = {
        "a": [_summary(0, True, 700), _summary(1, True, 900, drops=1), _summary(2, True, 950, drops=1)],
        "b": [_summary(0, True, 700), _summary(1, True, 1000, drops=1), _summary(2, False, 300, drops=1)],
    }
    paired = paired_steps(by_strategy)
    assert paired == {"seeds": [1], "mean_steps": {"a": 900.0, "b": 1000.0}}


def test_wilson_interval_brackets_the_rate():
    low, high = wilson_interval(19, 20)
    assert low < 0.95 < high <= 1.0
    assert wilson_interval(0, 0) == (0.0, 0.0)
