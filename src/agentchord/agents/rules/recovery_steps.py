"""Recovery steps built from an arm account: regrasps, replays of the motions since a grasp, skips.

The arranger's branches (:mod:`.arranger`, :mod:`.in_hand`) end the same ways: take the object
again with its nominal hold, bring it back where the failed edge expects it, run the edge again
with its grasps and places made idempotent (an interrupted two-arm step).
"""

from __future__ import annotations

from collections.abc import Iterable

from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.accounts import RELATIVE, Account, calls_of, cancel_undone, side_by_side
from agentchord.graph.models import ActionCall, Edge, Step

#: Calls that bring the arm to a pose of their own, whatever it held before.
POSING = frozenset({"move_to_target", "move_to_obj", "place", "back"})


def with_skips(call: ActionCall) -> ActionCall:
    """A recovery's copy of a call: its grasp skips an object still held, its place one already placed."""
    if call.fn == "grasp":
        return ActionCall(fn="grasp", args={**call.args, "skip_if_held": True})
    if call.fn == "place":
        return ActionCall(fn="place", args={**call.args, "skip_if_placed": True})
    return call


def places_at_target(edge: Edge, arm: str, obj: str) -> bool:
    """Whether ``edge`` has ``arm`` put ``obj`` down at a target (a drop there may finish the place)."""
    return any(c.fn == "place" and c.args.get("obj") == obj and c.args.get("target") is not None for c in calls_of(edge, arm))


def regrasp(account: Account, arm: str, obj: str, tall: bool = False, skip_if_held: bool = True,
            skip_if_placed: bool = False) -> ActionCall:
    """``arm`` takes ``obj`` again with the hold of its nominal grasp (from ``account``)."""
    grasp = account[arm].grasp
    args = dict(grasp.args) if grasp is not None and grasp.args.get("obj") == obj else {"obj": obj}
    if tall and args.get("mode", "auto") != "top":
        # A tall object that fell is taken again from its side once upright: the nominal hold,
        # not the off-centre fallen-object hold (a pour or an upright place needs it).
        args["reseat"] = True
    if skip_if_placed:  # fallen where the edge was putting it: only let go (the replayed place does)
        args["skip_if_placed"] = True
    return ActionCall(fn="grasp", args={**args, "skip_if_held": skip_if_held})


def _poses_itself(call: ActionCall) -> bool:
    """Whether ``call`` brings the arm to a pose of its own, whatever came before.

    A cloth corner's place does not: its straight way from where the corner was taken again drags
    the cloth across the table (a corner laid so ended 5-7 cm off its top corner, four times over).
    It is brought over its spot the nominal way first.
    """
    return call.fn in POSING and not (call.fn == "place" and kb.is_cloth_corner(str(call.args.get("obj", ""))))


def replay_then_edge(account: Account, edge: Edge, arms: Iterable[str], regrasped: bool = False) -> list[Step]:
    """Restore each arm's motions since its grasp where ``edge`` relies on them, then ``edge`` again.

    An edge that continues them (its first call for the arm is relative) relies on them. So does,
    after a regrasp, one that does not move the arm to a pose of its own first: the object is then
    held where it was taken again, not where the edge expects it (a hand-over whose giving arm only
    opens, a cup held still while the other arm pours into it, a cloth corner to be laid on another).
    """
    prefix: dict[str, list[ActionCall]] = {}
    stripped: set[str] = set()
    for arm in arms:
        mine = calls_of(edge, arm)
        history = account[arm].since_grasp
        continues = bool(mine) and mine[0].fn in RELATIVE
        relies = continues or (regrasped and not (mine and _poses_itself(mine[0])))
        if not relies or not history:
            continue
        remaining = cancel_undone([*history, *mine])
        if len(remaining) < len(history):  # the edge undoes earlier motions: replay what is left, skip the edge's part
            prefix[arm], _ = remaining, stripped.add(arm)
        else:
            prefix[arm] = history
    steps = side_by_side(prefix)
    for step in edge.steps:
        kept = {a: with_skips(c) for a, c in step.items() if c is not None and a not in stripped}
        if kept:
            steps.append(kept)
    return steps


def after_park(account: Account, edge: Edge, busy: set[str]) -> list[Step]:
    """After parking the busy arms (an absolute move): their whole pose since the grasp, then the edge."""
    history = {a: account[a].since_grasp for a in busy if account[a].since_grasp}
    steps = side_by_side(history)
    for step in edge.steps:
        kept = {a: with_skips(c) for a, c in step.items() if c is not None}
        if kept:
            steps.append(kept)
    return steps
