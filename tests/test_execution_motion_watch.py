"""The motion watch: which objects still move, measured over a few ticks of feature frames."""

import pytest

from agentchord.execution.motion_watch import REST_SPEED, MotionWatch
from agentchord.features.frame import make_static_frame
from agentchord.worlds.protocol import CONTROL_HZ


def _frame(bottle_x: float, cup_x: float = 0.3):
    return make_static_frame({"bottle": {"pos": (bottle_x, 0.5, 0.08)}, "cup": {"pos": (cup_x, 0.5, 0.05)}})


def test_an_object_faster_than_the_rest_speed_moves_and_one_at_rest_does_not():
    watch = MotionWatch(["bottle", "cup"])
    step = 2.0 * REST_SPEED / CONTROL_HZ  # twice the rest speed, per tick
    for tick in range(6):
        watch.observe(_frame(tick * step))
    assert watch.moving() == ["bottle"]


def test_a_slow_creep_is_rest():
    watch = MotionWatch(["bottle"])
    step = 0.5 * REST_SPEED / CONTROL_HZ
    for tick in range(6):
        watch.observe(_frame(tick * step))
    assert watch.moving() == []


@pytest.mark.parametrize("ticks_seen", [0, 1])
def test_nothing_moves_before_two_ticks_are_seen(ticks_seen):
    watch = MotionWatch(["bottle"])
    for tick in range(ticks_seen):
        watch.observe(_frame(0.1 * tick))
    assert watch.moving() == []


def test_frames_refreshed_every_five_ticks_still_show_motion():
    # RGB-D features refresh at 10 Hz: four ticks of a frozen frame, then a jump. Measured over one
    # tick the object would read as at rest most of the time.
    watch = MotionWatch(["bottle"])
    for tick in range(11):
        watch.observe(_frame(0.01 * (tick // 5)))  # 1 cm every 5 ticks: 10 cm/s
    assert watch.moving() == ["bottle"]


def test_objects_a_frame_lacks_are_skipped():
    watch = MotionWatch(["bottle", "towel_bl"])
    for tick in range(3):
        watch.observe(_frame(0.05 * tick))
    assert watch.moving() == ["bottle"]
