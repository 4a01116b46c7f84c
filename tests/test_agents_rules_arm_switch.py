"""Arm-switching alternatives: generated for single-arm regrasps of rigid objects, validated, idempotent."""

import numpy as np
import pytest

from agentchord.agents.rules.arm_switch import add_arm_switch_alternatives, arm_switch_alternative
from agentchord.graph.models import Edge
from agentchord.graph.progress import forward_filter
from agentchord.graph.validation import check_graph
from agentchord.library import load_task_graph
from agentchord.sim.tasks import SIM_TASKS

LIBRARY = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "setup_coffee_tray", "fold_towel")


def _rigid(task: str) -> list[str]:
    return [o.name for o in SIM_TASKS[task].sample_scene(np.random.default_rng(0)).objects]


def test_the_other_arm_takes_the_object_sets_it_down_within_reach_then_the_entry_runs():
    entry = Edge.model_validate({
        "id": "e2_r", "source": "v1", "target": "v2", "kind": "recovery",
        "actions": [{"right": {"fn": "grasp", "args": {"obj": "bottle", "yaw": 90}}},
                    {"right": {"fn": "move_to_obj", "args": {"obj": "cup"}}}],
    })
    alt = arm_switch_alternative(entry, ["bottle", "cup"])
    assert alt is not None and alt.alternative_to == "e2_r" and (alt.source, alt.target) == ("v1", "v2")
    # The first arm opens, then goes home out of the way while the other arm takes the bottle.
    first = {arm: call.fn for arm, call in alt.steps[0].items() if call is not None}
    assert first == {"right": "open_gripper"}
    second = {arm: (call.fn, call.args) for arm, call in alt.steps[1].items() if call is not None}
    assert second == {"left": ("grasp", {"obj": "bottle"}), "right": ("back", {})}  # the first arm's yaw is not the other arm's
    calls = [(arm, call.fn, call.args) for arm, call in alt.calls]
    assert ("left", "place", {"obj": "bottle", "within_reach": "right"}) in calls
    assert [c[1] for c in calls[-3:]] == ["back", "grasp", "move_to_obj"]


def test_a_busy_other_arm_sets_its_object_down_hands_over_and_takes_its_object_again():
    entry = Edge.model_validate({
        "id": "e3_r", "source": "v2", "target": "v2", "kind": "recovery",
        "actions": [{"left": {"fn": "move_to_target", "args": {"pos": [-0.12, 0.72, 0.22]}},
                     "right": {"fn": "grasp", "args": {"obj": "bottle", "reseat": True}}}],
        "failures": [{"name": "bottle_dropped", "monitor": "right.closed * (0.5 - holding(right, bottle))", "intent": "regrasp", "recovery": "e3_r"},
                     {"name": "cup_dropped", "monitor": "left.closed * (0.5 - holding(left, cup))", "intent": "regrasp", "recovery": "e3_c"}],
    })
    alt = arm_switch_alternative(entry, ["bottle", "cup"], {("left", "cup"): {"height": 0.4}})
    assert alt is not None and alt.id == "e3_r_via_left"
    steps = [{arm: (call.fn, call.args) for arm, call in step.items() if call is not None} for step in alt.steps]
    assert steps[0] == {"right": ("open_gripper", {}), "left": ("place", {"obj": "cup", "free_hand": True})}
    assert steps[1] == {"left": ("grasp", {"obj": "bottle"}), "right": ("back", {})}
    assert steps[2] == {"left": ("place", {"obj": "bottle", "within_reach": "right"})}
    assert steps[3] == {"left": ("grasp", {"obj": "cup", "height": 0.4})}
    assert steps[4]["left"][0] == "move_to_target" and steps[4]["right"][0] == "grasp"  # then the entry as written
    # The left arm's own monitor would fire as it sets the cup down on purpose: not copied.
    assert [f.name for f in alt.failures] == ["bottle_dropped"]
    # Two objects in the other hand, or one it cannot set down: no alternative.
    assert arm_switch_alternative(entry, ["bottle"]) is None


def test_no_alternative_for_a_cloth_point_or_a_two_arm_grasp():
    cloth = Edge.model_validate({"id": "r", "source": "a", "target": "b", "kind": "recovery",
                                 "actions": {"left": {"fn": "grasp", "args": {"obj": "towel_bl"}}}})
    assert arm_switch_alternative(cloth, ["tray"]) is None
    both = Edge.model_validate({"id": "r", "source": "a", "target": "b", "kind": "recovery",
                                "actions": {"left": {"fn": "grasp", "args": {"obj": "tray"}}, "right": {"fn": "grasp", "args": {"obj": "tray"}}}})
    assert arm_switch_alternative(both, ["tray"]) is None


@pytest.mark.parametrize("task", LIBRARY)
def test_library_graphs_carry_their_alternatives_and_stay_valid(task):
    graph = load_task_graph(task)
    # Up to date: the rule adds nothing the file does not already have, and rebuilt from the graph
    # without them it writes them as the file has them.
    assert add_arm_switch_alternatives(graph, _rigid(task)) == graph
    bare = graph.model_copy(update={"edges": [e for e in graph.edges if e.alternative_to is None]})
    assert add_arm_switch_alternatives(bare, _rigid(task)).edges == graph.edges
    assert check_graph(graph) == []
    alternatives = [e for e in graph.edges if e.alternative_to]
    kept = {e.id for e in forward_filter(graph).graph.edges}
    assert all(e.id in kept for e in alternatives)


def test_single_arm_pour_has_a_left_arm_alternative_for_every_bottle_regrasp():
    graph = load_task_graph("single_arm_pour_water")
    entries = {f.recovery for e in graph.nominal_edges() for f in e.failures if f.name == "bottle_dropped"}
    assert entries and all(graph.alternatives(entry) for entry in entries)


def test_validation_refuses_an_alternative_with_other_ends():
    graph = load_task_graph("single_arm_pour_water")
    bad = graph.model_copy(deep=True)
    alt = next(e for e in bad.edges if e.alternative_to)
    alt.target = bad.goal
    assert any("goes where its entry edge goes" in p.message for p in check_graph(bad))
    alt.target, alt.alternative_to = graph.edge(alt.id).target, "nowhere"
    assert any("unknown edge" in p.message for p in check_graph(bad))
