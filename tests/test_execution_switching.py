"""Recovery switching: which failure mode a merge found violated is taken as."""

from types import SimpleNamespace

import pytest

from agentchord.execution.switching import RecoverySwitching
from agentchord.execution.trace import Trace
from agentchord.expr.compiler import compile_expr
from agentchord.expr.vocabulary import Vocabulary
from agentchord.features.frame import make_static_frame
from agentchord.library import load_task_graph
from agentchord.monitor import EdgeMonitors

TOWEL = load_task_graph("fold_towel")
TOP = {"towel_tl": (0.0, 0.6, 0.0), "towel_tr": (0.3, 0.6, 0.0)}


def _merged_at_v4(bl: tuple[float, float, float], br: tuple[float, float, float]) -> SimpleNamespace:
    """What ``_watched_violation`` reads of an executor whose recovery merged at the towel's v4."""
    vocabulary = Vocabulary(frozenset(TOWEL.objects))
    corner = {"extent": (0.005, 0.005, 0.005)}
    positions = {**TOP, "towel_bl": bl, "towel_br": br}
    frame = make_static_frame(objects={name: {**corner, "pos": pos} for name, pos in positions.items()})
    return SimpleNamespace(
        graph=TOWEL,
        frame=frame,
        world=SimpleNamespace(tick=100),
        trace=Trace(),
        constraints={"v4": [compile_expr(c, vocabulary) for c in TOWEL.node("v4").constraints]},
        monitors={"e5": EdgeMonitors.compile(TOWEL.edge("e5"), vocabulary)},
        modes_unknown=lambda edge_id: False,
    )


@pytest.mark.parametrize(
    ("bl", "br", "taken"),
    [
        # Both corners 6 cm short of their top corners: the mode listed first for that state re-places both,
        # though its monitor (the smaller of the two distances) spells neither constraint as the node does.
        ((0.0, 0.54, 0.0), (0.3, 0.54, 0.0), "both_misplaced"),
        # One corner off: its own mode, as before.
        ((0.0, 0.54, 0.0), (0.3, 0.59, 0.0), "bl_misplaced"),
        ((0.0, 0.59, 0.0), (0.3, 0.54, 0.0), "br_misplaced"),
    ],
)
def test_a_merge_takes_the_first_violated_mode_of_the_next_edge_that_reads_what_broke(bl, br, taken):
    executor = _merged_at_v4(bl, br)
    detection = RecoverySwitching._watched_violation(executor, "v4", "e5")
    assert detection is not None and detection.failure.name == taken
    assert executor.trace.of("violation_at_merge") == [
        {"tick": 100, "event": "violation_at_merge", "node": "v4", "edge": "e5", "failure": taken}
    ]


def test_a_merge_whose_constraints_hold_fires_nothing():
    executor = _merged_at_v4((0.0, 0.59, 0.0), (0.3, 0.59, 0.0))
    assert RecoverySwitching._watched_violation(executor, "v4", "e5") is None
    assert executor.trace.of("violation_at_merge") == []
