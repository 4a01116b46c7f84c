"""Recovery steps (agentchord.agents.rules.recovery_steps): a regrasp brings the object back where the edge expects it."""

from __future__ import annotations

import pytest

from agentchord.agents.rules.accounts import ArmAccount
from agentchord.agents.rules.arranger import Arranger
from agentchord.agents.rules.recovery_steps import replay_then_edge
from agentchord.graph.models import ActionCall, Edge
from test_agents_rules_arranger import nominal_only
from test_agents_rules_composer import scene_of


def _handover_edge() -> tuple[dict, Edge]:
    carry = ActionCall(fn="move_to_target", args={"pos": [0.0, 0.5, 0.25], "yaw": 0.0})
    account = {"left": ArmAccount(holding="block", grasp=ActionCall(fn="grasp", args={"obj": "block"}), since_grasp=[carry]),
               "right": ArmAccount()}
    edge = Edge(id="e3", source="v2", target="v3", actions=[
        {"right": {"fn": "grasp", "args": {"obj": "block", "height": 0.2}}},
        {"left": {"fn": "open_gripper"}},
    ])
    return account, edge


def test_after_a_regrasp_the_motions_since_the_grasp_are_replayed_unless_the_edge_poses_the_arm():
    account, edge = _handover_edge()
    steps = replay_then_edge(account, edge, ["left"], regrasped=True)
    assert [(arm, call.fn) for step in steps for arm, call in step.items()] == [
        ("left", "move_to_target"), ("right", "grasp"), ("left", "open_gripper")]
    assert steps[1]["right"].args["skip_if_held"] is True
    # Not regrasped (the object is still where the edge left it): the edge alone.
    assert [call.fn for step in replay_then_edge(account, edge, ["left"]) for call in step.values()] == ["grasp", "open_gripper"]
    # An edge that first poses the arm itself needs no replay.
    placing = Edge(id="e4", source="v3", target="v4", actions=[{"left": {"fn": "place", "args": {"obj": "block"}}}])
    assert [call.fn for step in replay_then_edge(account, placing, ["left"], regrasped=True) for call in step.values()] == ["place"]


def test_a_regrasp_brings_the_object_back_where_the_edge_expects_it():
    out = Arranger(scene_of("handover_block")).arrange(nominal_only("handover_block"))
    # Dropped in the hand-over, whose giving arm only opens: taken again where it fell, the block
    # goes back up to the hand-over pose before the right arm takes it (planned handover, real seed 10).
    handover = out.edge(next(f.recovery for f in out.edge("e3").failures if f.name == "block_dropped"))
    calls = [(arm, call.fn) for arm, call in handover.calls]
    assert calls.index(("left", "move_to_target")) < calls.index(("right", "grasp"))
    carry = next(c for _, c in out.edge("e2").calls if c.fn == "move_to_target")
    assert next(c for a, c in handover.calls if c.fn == "move_to_target").args["pos"] == carry.args["pos"]


def test_a_regrasp_of_an_object_held_still_restores_its_pose_before_the_other_arm_goes_on():
    graph = nominal_only("dual_arm_pour_water")
    arranger = Arranger(scene_of("dual_arm_pour_water"))
    out = arranger.arrange(graph)
    for edge in graph.edges:
        left = arranger.accounts(graph)[edge.id]["left"]
        if left.holding != "cup" or any(a == "left" for a, _ in edge.calls) or not left.since_grasp:
            continue
        regrasp = out.edge(next(f.recovery for f in out.edge(edge.id).failures if f.name == "cup_dropped"))
        assert [(a, c) for a, c in regrasp.calls][1] == ("left", left.since_grasp[0]), edge.id
        break
    else:
        pytest.fail("no dual-arm pour edge holds the cup still in the left hand")


def test_a_cloth_corner_taken_again_is_brought_over_its_spot_before_it_is_laid_there():
    over = ActionCall(fn="move_to_obj", args={"obj": "towel_tl", "offset": [0.0, -0.02, 0.1]})
    account = {"left": ArmAccount(holding="towel_bl", grasp=ActionCall(fn="grasp", args={"obj": "towel_bl"}), since_grasp=[over]),
               "right": ArmAccount()}
    lay = Edge(id="e4", source="v3", target="v4",
               actions=[{"left": {"fn": "place", "args": {"obj": "towel_bl", "target": [0.0, -0.04], "relative_to": "towel_tl"}}}])
    steps = replay_then_edge(account, lay, ["left"], regrasped=True)
    # Its straight way from where it was taken again would drag the cloth (planned fold, real seed 15).
    assert [step["left"] for step in steps][0] == over and steps[1]["left"].fn == "place"
