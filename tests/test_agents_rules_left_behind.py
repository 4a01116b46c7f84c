"""Put-back branches of the retreat edges: objects knocked over or pushed off their spot as the arms go home."""

from __future__ import annotations

import pytest

from agentchord.agents.rules.arranger import Arranger
from agentchord.agents.rules.left_behind import is_retreat, put_down_before
from agentchord.graph.progress import forward_filter
from test_agents_rules_arranger import nominal_only
from test_agents_rules_composer import scene_of

TASKS = ["single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "setup_coffee_tray", "fold_towel"]


def _arranged(task: str):
    return Arranger(scene_of(task)).arrange(nominal_only(task))


def _modes(graph, edge_id: str) -> dict[str, tuple[str, str]]:
    return {f.name: (f.monitor, f.recovery) for f in graph.edge(edge_id).failures}


def test_a_bottle_stood_on_the_table_is_watched_for_a_knock_as_the_arm_goes_home():
    out = _arranged("single_arm_pour_water")
    last = out.edge("e6")
    assert is_retreat(last)
    # Past the goal's own bound (tilt(bottle) - 10), not only knocked flat: left leaning 17 deg against
    # the cup, the goal failed with nothing left to run (planned single-arm pour, stress seed 7).
    assert "tilt(bottle) - 10" in out.node(last.target).constraints
    assert _modes(out, "e6")["bottle_knocked"] == ("tipped(bottle, 12)", "e6_r_bottle_put_back")
    put_back = out.edge("e6_r_bottle_put_back")
    # Taken again with the nominal grasp, put down as the nominal place did; then home again from v5.
    assert (put_back.source, put_back.target) == ("v5", "v5")
    assert [{a: c.fn for a, c in step.items() if c is not None} for step in put_back.steps] == [{"right": "grasp"}, {"right": "place"}]
    assert put_back.steps[1]["right"] == nominal_only("single_arm_pour_water").edge("e5").steps[0]["right"]
    assert [f.name for f in put_back.failures] == ["bottle_dropped"]


def test_a_tray_carried_by_both_arms_is_watched_on_its_spot_and_carried_back_by_both():
    out = _arranged("setup_coffee_tray")
    spot = "norm(xy(tray.pos) - [0.0, 0.67, 0.0]) - 0.03"
    assert _modes(out, "e5")["tray_moved"] == (spot, "e5_r_tray_put_back")
    put_back = out.edge("e5_r_tray_put_back")
    assert [sorted(a for a, c in step.items() if c is not None) for step in put_back.steps] == [["left", "right"]] * 3
    assert [step["left"].fn for step in put_back.steps] == ["grasp", "move_by_offset", "place"]
    assert put_back.steps[0]["left"].args["offset"] == [-0.145, 0.0, 0.0]  # the nominal handle grasp
    assert "max(left.closed" in put_back.failures[0].monitor


def test_a_block_taken_from_the_other_arm_is_taken_again_with_a_plain_grasp():
    out = _arranged("handover_block")
    modes = _modes(out, "e5")
    assert modes["block_knocked"][1] == modes["block_moved"][1] == "e5_r_block_put_back"
    put_back = out.edge("e5_r_block_put_back")
    assert put_back.steps[0]["right"].args == {"obj": "block"}
    assert put_back.steps[-1]["right"].args["target"] == [0.12, 0.45]


def test_cutlery_placed_beside_the_plate_keeps_its_relation_branches_only():
    out = _arranged("rearrange_table")
    assert not [name for name in _modes(out, "e4") if name.endswith(("_knocked", "_moved"))]
    assert {"fork_misplaced", "spoon_misplaced"} <= set(_modes(out, "e4"))


@pytest.mark.parametrize("task", TASKS)
def test_only_retreat_edges_get_put_back_branches_and_nothing_regresses(task):
    out = _arranged(task)
    for edge in out.nominal_edges():
        put_backs = [f for f in edge.failures if f.recovery.endswith("_put_back")]
        assert not put_backs or is_retreat(edge), f"{task}: {edge.id}"
    assert forward_filter(out).removed == []


def test_what_was_put_down_is_known_only_after_its_place():
    graph = nominal_only("single_arm_pour_water")
    assert put_down_before(graph, graph.edge("e5")) == {}  # e5 is the place itself
    assert set(put_down_before(graph, graph.edge("e6"))) == {"bottle"}
    assert set(put_down_before(graph, graph.edge("e6"))["bottle"]) == {"right"}
