"""The persistence trigger (paper Eq. 12)."""

import pytest

from agentchord.monitor import PersistenceTrigger


@pytest.mark.parametrize("window", [1, 3, 7])
def test_window_minus_one_violating_ticks_do_not_fire_window_ticks_do(window):
    trigger = PersistenceTrigger(margin=0.0, window=window)
    fired = [trigger.update(1.0, tick) for tick in range(window - 1)]
    assert not any(fired)
    assert trigger.update(1.0, window - 1)
    assert trigger.first_violation_tick == 0


def test_a_normal_tick_resets_the_streak():
    trigger = PersistenceTrigger(margin=0.0, window=3)
    assert not trigger.update(1.0, 0)
    assert not trigger.update(1.0, 1)
    assert not trigger.update(-0.1, 2)
    assert not trigger.update(1.0, 3)
    assert not trigger.update(1.0, 4)
    assert trigger.update(1.0, 5)
    assert trigger.first_violation_tick == 3


def test_values_within_the_margin_do_not_count():
    trigger = PersistenceTrigger(margin=0.5, window=2)
    assert not any(trigger.update(0.5, t) for t in range(10))
    assert not trigger.update(0.51, 10)
    assert trigger.update(0.51, 11)


def test_reset_forgets_history():
    trigger = PersistenceTrigger(window=2)
    trigger.update(1.0)
    trigger.reset()
    assert not trigger.update(1.0)


def test_window_must_be_positive():
    with pytest.raises(ValueError, match="window"):
        PersistenceTrigger(window=0)
