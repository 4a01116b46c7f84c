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
