"""Arm accounts: what each arm holds, and how it got there, along a nominal path.

The arranger and the conductor walk the nominal path keeping this symbolic account of the
atomic actions' effects (who holds what, which relative motions since the last grasp, what
each arm's last absolute motion aimed at); recovery steps are built from it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

from agentchord.graph.models import ActionCall, Edge, Step
from agentchord.robot.aloha import ARMS

#: Motions relative to the arm's current pose (replayed after a regrasp; the others aim at a pose or an object).
RELATIVE = frozenset({"rotate_eef", "move_by_offset"})


@dataclass
class ArmAccount:
    """What one arm is doing at a node of the nominal path.

    Attributes:
        holding: Object held, if any.
        grasp: The call that took it (``None`` when it was taken from the other arm).
        since_grasp: Motions since the grasp that set the held object's pose (to replay).
        relative_to: Object the arm's last absolute motion aimed at.
    """

    holding: str | None = None
    grasp: ActionCall | None = None
    since_grasp: list[ActionCall] = field(default_factory=list)
    relative_to: str | None = None


Account = dict[str, ArmAccount]


def apply_step(account: Account, step: Step) -> Account:
    """The account after one step (both arms' calls of the step)."""
    after = copy.deepcopy(account)
    for arm, call in step.items():
        if call is None:
            continue
        me = after[arm]
        args = call.args
        if call.fn == "grasp":
            # Taken from the other arm (a handover) only if it held it before this step: a two-arm grasp is not.
            taken = any(account[a].holding == args["obj"] for a in ARMS if a != arm)
            me.holding, me.grasp, me.since_grasp, me.relative_to = args["obj"], (None if taken else call), [], None
        elif call.fn == "place" or call.fn == "open_gripper":
            me.holding, me.grasp, me.since_grasp, me.relative_to = None, None, [], None
        elif call.fn == "back":
            me.since_grasp, me.relative_to = [], None
        elif call.fn in ("move_to_obj", "move_to_target"):
            me.since_grasp = [call] if me.holding else []
            me.relative_to = args.get("obj")
        elif call.fn in RELATIVE and me.holding:
            me.since_grasp = cancel_undone([*me.since_grasp, call])
    return after


def cancel_undone(calls: list[ActionCall]) -> list[ActionCall]:
    """Drop a rotation undone by the next one (tilt, then tilt back)."""
    out: list[ActionCall] = []
    for call in calls:
        if out and call.fn == "rotate_eef" and out[-1].fn == "rotate_eef" and abs(out[-1].args["angle"] + call.args["angle"]) < 1e-6:
            out.pop()
        else:
            out.append(call)
    return out


def holders_of(account: Account, obj: str) -> list[str]:
    """The arms holding ``obj``."""
    return [a for a in ARMS if account[a].holding == obj]


def calls_of(edge: Edge, arm: str) -> list[ActionCall]:
    """``arm``'s calls in ``edge``, in order."""
    return [step[arm] for step in edge.steps if step.get(arm) is not None]


def side_by_side(per_arm: dict[str, list[ActionCall]]) -> list[Step]:
    """Steps that run each arm's calls in order, the arms side by side."""
    longest = max((len(c) for c in per_arm.values()), default=0)
    return [{arm: calls[k] for arm, calls in per_arm.items() if k < len(calls)} for k in range(longest)]
