"""The disturbance ledger: a detection books the open disturbance once; a merge recovers what is under way."""

from dataclasses import dataclass

import pytest

from agentchord.execution.ledger import DisturbanceLedger


@dataclass
class _Event:
    tick: int
    kind: str
    obj: str = "bottle"
    arm: str = "right"
    action: str = "move_to_obj"


def test_a_detection_books_the_open_disturbance_with_its_latencies():
    ledger = DisturbanceLedger()
    drop = _Event(100, "drop")
    ledger.injected(drop, reasoning_s=21.0)
    assert ledger.detection(104) is drop
    ledger.switched(drop, 110, reasoning_s=24.5)  # a re-planner was charged 3.5 s meanwhile
    assert ledger.latency_ticks == [4]
    assert ledger.latency_s == [pytest.approx(10 / 50 + 3.5)]
    # The next detection is not this disturbance's: it was booked already.
    assert ledger.detection(120) is None
    assert ledger.latency_ticks == [4]


def test_recovered_only_once_the_recovery_merges_and_both_of_two_nested_ones():
    ledger = DisturbanceLedger()
    first, second = _Event(100, "drop"), _Event(150, "pull")
    ledger.injected(first, 0.0)
    ledger.detection(103)
    ledger.injected(second, 0.0)  # interrupts the first one's recovery
    ledger.detection(153)
    assert ledger.recovered == []
    ledger.merged()
    assert ledger.recovered == [first, second] and ledger.unmerged == []
    injected = [first, second, _Event(300, "drop")]  # a third, never detected
    assert ledger.by_kind(injected) == {"drop": [2, 1, 1], "pull": [1, 1, 1]}
    assert ledger.drops(injected) == (2, 1, 1)


def test_a_detection_reported_late_books_the_disturbance_before_it_not_one_during_the_wait():
    # A failure fired at 279 and waited for its branch; a second disturbance came at 367, during the wait.
    ledger = DisturbanceLedger()
    pull, second = _Event(276, "pull", obj="fork"), _Event(367, "pull", obj="spoon")
    ledger.injected(pull, 0.0)
    ledger.injected(second, 0.0)
    assert ledger.detection(279) is pull
    assert ledger.latency_ticks == [3]
    # The second one stays open for its own detection.
    assert ledger.detection(930) is second
    assert ledger.latency_ticks == [3, 563]


def test_a_disturbance_not_detected_before_the_next_one_is_not_counted():
    ledger = DisturbanceLedger()
    missed, caught = _Event(100, "perturb"), _Event(200, "drop")
    ledger.injected(missed, 0.0)
    ledger.injected(caught, 0.0)
    assert ledger.detection(203) is caught and ledger.detected == [caught]
    assert ledger.detection(300) is None
