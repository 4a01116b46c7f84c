"""Arm accounts: the symbolic effects of atomic actions along a nominal path."""

from agentchord.agents.rules.accounts import ARMS, ArmAccount, apply_step, calls_of, cancel_undone, holders_of, side_by_side
from agentchord.graph.models import ActionCall, Edge


def _call(fn, **args):
    return ActionCall(fn=fn, args=args)


def _empty():
    return {arm: ArmAccount() for arm in ARMS}


def test_a_grasp_then_relative_motions_are_remembered_until_the_place():
    account = apply_step(_empty(), {"right": _call("grasp", obj="bottle")})
    account = apply_step(account, {"right": _call("move_to_obj", obj="cup")})
    account = apply_step(account, {"right": _call("rotate_eef", angle=-95)})
    right = account["right"]
    assert right.holding == "bottle" and right.grasp.args["obj"] == "bottle" and right.relative_to == "cup"
    assert [c.fn for c in right.since_grasp] == ["move_to_obj", "rotate_eef"]
    assert holders_of(account, "bottle") == ["right"]
    placed = apply_step(account, {"right": _call("place", obj="bottle")})
    assert placed["right"] == ArmAccount() and holders_of(placed, "bottle") == []
    assert account["right"].holding == "bottle"  # the step returns a new account


def test_an_object_taken_from_the_other_arm_has_no_grasp_of_its_own_to_replay():
    account = apply_step(_empty(), {"left": _call("grasp", obj="block")})
    account = apply_step(account, {"right": _call("grasp", obj="block")})
    assert account["right"].holding == "block" and account["right"].grasp is None
    # Two arms closing on a tray in the same step each took it themselves.
    both = apply_step(_empty(), {"left": _call("grasp", obj="tray"), "right": _call("grasp", obj="tray")})
    assert both["left"].grasp is not None and both["right"].grasp is not None


def test_a_tilt_undone_by_the_next_tilt_cancels():
    tilt, back = _call("rotate_eef", angle=-95), _call("rotate_eef", angle=95)
    lift = _call("move_by_offset", offset=[0.0, 0.0, 0.05])
    assert cancel_undone([lift, tilt, back]) == [lift]
    assert cancel_undone([tilt, lift, back]) == [tilt, lift, back]


def test_calls_run_side_by_side_and_are_read_per_arm():
    steps = side_by_side({"left": [_call("back")], "right": [_call("grasp", obj="cup"), _call("place", obj="cup")]})
    assert [sorted(step) for step in steps] == [["left", "right"], ["right"]]
    edge = Edge(id="e1", source="v0", target="v1", actions=steps)
    assert [c.fn for c in calls_of(edge, "right")] == ["grasp", "place"] and [c.fn for c in calls_of(edge, "left")] == ["back"]
