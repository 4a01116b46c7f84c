"""Seeded disturbance schedules: drawn from the seed, identical across strategies."""

import pytest

from agentchord.execution.episode import EpisodeSpec, run_episode
from agentchord.worlds.sim.disturbances import RandomDrop


def _draws(schedule, n=50):
    due = []
    for k in range(n):
        schedule.action_started("right", "move_to_obj", 100, tick=1000 * k)
        due.append(schedule._pending.get("right"))
    return due


def test_same_seed_same_schedule_other_seed_other_schedule():
    assert _draws(RandomDrop(0.3, seed=4)) == _draws(RandomDrop(0.3, seed=4))
    assert _draws(RandomDrop(0.3, seed=4)) != _draws(RandomDrop(0.3, seed=5))


def test_probability_zero_never_drops_and_bad_probability_is_refused():
    assert all(d is None for d in _draws(RandomDrop(0.0, seed=1)))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        RandomDrop(1.5, seed=1)


def test_both_strategies_see_the_same_first_disturbance_for_a_seed():
    firsts = []
    for strategy in ("agentchord", "agentchord-bt"):
        result = run_episode(EpisodeSpec("single_arm_pour_water", strategy=strategy, p=0.3, seed=5))
        firsts.append(result.trace.of("disturbance")[0])
    assert firsts[0] == firsts[1]
