"""Two sweeps' records compared episode by episode, the clock left out."""

from agentchord.bench.compare import compare_records, comparison_markdown


def _record(key, method="agentchord", steps=900, wall=1.0, compute=0.05, reasoning=1.5, robot=18.0):
    return {"id": key, "method": method, "success": True, "steps": steps, "wall_s": wall, "compute_s": compute,
            "reasoning_s": reasoning, "exec_time_s": robot + compute + reasoning, "robot_time_s": robot}


def test_the_same_episodes_on_another_clock_are_identical():
    before = [_record("a"), _record("b", method="rekep")]
    after = [_record("a", wall=3.2, compute=0.09), _record("b", method="rekep", wall=0.4), _record("c")]
    comparison = compare_records(before, after)
    assert comparison.identical and comparison.compared == 2 and comparison.only_after == ["c"]
    assert comparison_markdown(comparison).startswith("2 episodes in both; 0 differ")


def test_a_changed_episode_is_named_with_its_fields_per_method():
    before = [_record("a"), _record("b", method="rekep")]
    after = [_record("a", steps=901, robot=18.02), _record("b", method="rekep", reasoning=1.6)]
    comparison = compare_records(before, after)
    assert not comparison.identical
    assert comparison.changed["a"] == ["robot_time_s", "steps", "exec_time_s - compute_s - reasoning_s"]
    assert comparison.changed["b"] == ["reasoning_s"]
    text = comparison_markdown(comparison)
    assert "| agentchord | steps | 1 |" in text and "| rekep | reasoning_s | 1 |" in text
