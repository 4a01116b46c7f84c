"""Compiled monitors of an edge and the recovery map (Eq. 11-13)."""

import pytest

from agentchord.expr import Vocabulary
from agentchord.features.frame import make_static_frame
from agentchord.graph.models import Edge, FailureMode
from agentchord.monitor import EdgeMonitors, RecoveryMap
from agentchord.library import load_task_graph

VOCAB = Vocabulary(frozenset({"bottle", "cup"}))


def _frame(holding: bool, closed: float = 1.0):
    return make_static_frame(
        objects={"bottle": {"pos": (0.1, 0.5, 0.2)}, "cup": {"pos": (-0.1, 0.6, 0.05)}},
        arms={"right": {"closed": closed}},
        holding={("right", "bottle")} if holding else set(),
    )


def test_drop_monitor_fires_after_its_window_and_names_the_failure():
    graph = load_task_graph("single_arm_pour_water")
    monitors = EdgeMonitors.compile(graph.edge("e2"), VOCAB)
    held, dropped = _frame(True), _frame(False)
    assert monitors.evaluate(held) is None
    detections = []
    for tick in range(3):
        dropped.tick = 10 + tick
        detections.append(monitors.evaluate(dropped))
    assert detections[:2] == [None, None]
    assert detections[2].failure.name == "bottle_dropped"
    assert detections[2].onset_tick == 10


def test_gated_drop_monitor_is_quiet_while_the_gripper_is_open():
    graph = load_task_graph("single_arm_pour_water")
    monitors = EdgeMonitors.compile(graph.edge("e1"), VOCAB)
    open_gripper = _frame(False, closed=0.0)
    assert all(monitors.evaluate(open_gripper) is None for _ in range(10))


def test_recovery_map_returns_the_entry_edge_and_orders_exits_by_cost_to_go():
    graph = load_task_graph("single_arm_pour_water")
    recovery = RecoveryMap(graph)
    assert recovery.entry("e2", "bottle_dropped").id == "e2_r_bottle_dropped"
    assert recovery.entry("e2", "no_such_failure") is None
    exits = recovery.exit_edges("r_bottle_regrasped")
    assert [e.target for e in exits] == ["v2"]


def test_violated_now_reports_a_violation_on_one_frame_without_waiting_for_persistence():
    edge = Edge(id="e9", source="a", target="b", actions={"right": {"fn": "back"}},
                failures=[FailureMode(name="cup_tipped", monitor="tipped(cup, 30)", window=5, intent="set upright", recovery="r")])
    monitors = EdgeMonitors.compile(edge, VOCAB)
    upright = make_static_frame({"cup": {"axis": (0.0, 0.0, 1.0)}})
    lying = make_static_frame({"cup": {"axis": (1.0, 0.0, 0.0)}})
    assert monitors.violated_now(upright) is None
    detection = monitors.violated_now(lying)
    assert detection is not None and detection.failure.name == "cup_tipped" and detection.value == pytest.approx(60.0)
    assert monitors.evaluate(lying) is None  # the persistence window still counts one tick


def test_violated_now_scene_only_skips_monitors_that_read_an_arm():
    edge = Edge(id="e9", source="a", target="b", actions={"right": {"fn": "back"}},
                failures=[FailureMode(name="bottle_dropped", monitor="right.closed * (0.5 - holding(right, bottle))",
                                      window=3, intent="regrasp", recovery="r"),
                          FailureMode(name="cup_tipped", monitor="tipped(cup, 30)", window=3, intent="set upright", recovery="r")])
    monitors = EdgeMonitors.compile(edge, VOCAB)
    closed_on_nothing = _frame(False)  # the gripper closed, the bottle not held; the cup upright
    assert monitors.violated_now(closed_on_nothing).failure.name == "bottle_dropped"
    assert monitors.violated_now(closed_on_nothing, scene_only=True) is None


def test_watching_names_the_monitors_of_one_arms_hold_of_one_object():
    graph = load_task_graph("dual_arm_pour_water")
    monitors = EdgeMonitors.compile(graph.edge("e1"), Vocabulary(frozenset(graph.objects)))
    assert [m.failure.name for m in monitors.watching("right", "bottle")] == ["bottle_dropped"]
    assert [m.failure.name for m in monitors.watching("left", "cup")] == ["cup_dropped"]
    assert monitors.watching("left", "bottle") == []
