"""Arm-switching alternatives: a recovery the busy arm cannot reach is one the other arm can.

For every recovery entry edge that starts by one arm grasping a rigid object again
(``regrasp``, ``re-approach`` of a grasp), the rule adds an alternative edge
(``Edge.alternative_to``) with the same ends: the first arm opens and goes home out of
the way while the *other* arm takes the object wherever it lies, sets it down where both
arms reach (``place`` with ``within_reach``; the spot is chosen when it runs) and goes home;
then the entry edge's own steps run unchanged, so the recovery merges where it always did.
An other arm that holds an object of its own (the cup in a two-arm pour) sets it down where
it is first and takes it again after the hand-off. Still one pre-compiled branch per failure
mode, still forward-moving (the alternative has the entry edge's ends, so Eq. 8 judges both
alike): no re-planning at run time. Which one runs is decided when the recovery starts, once
the object is at rest, by a reach and IK check (``execution.feasibility``).

Works on any graph, the composer's or a hand-written one; the library graphs carry the
alternatives it writes (``tests/test_agents_rules_arm_switch.py`` checks they are up to date).
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from agentchord.graph.models import ActionCall, Edge, Step, TaskGraph
from agentchord.robot.aloha import other_arm

#: Suffix of an alternative's id: ``<entry id>_via_<arm>``.
VIA = "_via_"
#: Grasp arguments the other arm keeps (the rest are the first arm's geometry: yaw, offsets).
PORTABLE_GRASP_ARGS = ("obj", "mode", "height")


def _single_arm_grasp(step: Step) -> tuple[str, ActionCall] | None:
    """``(arm, grasp)`` when the step has exactly one grasp (the other arm may do something else)."""
    grasps = [(arm, call) for arm, call in step.items() if call is not None and call.fn == "grasp"]
    return grasps[0] if len(grasps) == 1 else None


def _held_by(entry: Edge, arm: str) -> set[str]:
    """The objects the entry's monitors watch ``arm`` holding (its hand is busy with them)."""
    return {match.group(1) for failure in entry.failures
            for match in re.finditer(rf"holding\(\s*{arm}\s*,\s*(\w+)\s*\)", failure.monitor)}


def arm_switch_alternative(entry: Edge, rigid: Iterable[str], regrasp: dict[tuple[str, str], dict] | None = None) -> Edge | None:
    """The other arm's way along a recovery entry edge, or None when the rule does not apply.

    It applies when the entry starts with one arm grasping a rigid object. The other arm either
    has a free hand (it is idle or going home in that step), or holds one rigid object that the
    entry's monitors watch (the cup in a two-arm pour): then it first sets that object down where
    it is, and takes it again once it has handed the first object over.

    Args:
        entry: A recovery entry edge.
        rigid: Objects that can be picked up and set down (not a cloth's corner).
        regrasp: Grasp arguments per ``(arm, object)`` for taking a set-down object again (the
            graph's own grasp of it); default: a plain grasp.
    """
    first = _single_arm_grasp(entry.steps[0]) if entry.steps else None
    if first is None:
        return None
    arm, grasp = first
    obj = grasp.args.get("obj")
    rigid = set(rigid)
    if obj not in rigid:
        return None
    other = other_arm(arm)
    busy = _held_by(entry, other) - {obj}
    other_first = entry.steps[0].get(other)
    args = {key: grasp.args[key] for key in PORTABLE_GRASP_ARGS if key in grasp.args}
    if not busy:
        if other_first is not None and other_first.fn != "back":
            return None  # the other arm has its own work in this step
        # The other arm already went home in the hand-off: drop its "back" from the entry's first step.
        rest = [{a: c for a, c in entry.steps[0].items() if a != other}, *entry.steps[1:]]
        hand_off: list[Step] = [
            # The arm that lost the object opens: its grasp-done signal resets, so its drop monitors wait for its own grasp.
            {arm: ActionCall(fn="open_gripper")},
            # ...and goes home while the other arm reaches: it may stand where it just tried to grasp.
            {other: ActionCall(fn="grasp", args=args), arm: ActionCall(fn="back")},
            {other: ActionCall(fn="place", args={"obj": obj, "within_reach": arm})},
            {other: ActionCall(fn="back")},
        ]
    else:
        if len(busy) > 1 or not busy <= rigid:
            return None
        held = next(iter(busy))
        again = {"obj": held, **(regrasp or {}).get((other, held), {})}
        rest = list(entry.steps)  # the other arm holds its object again: the entry runs as written
        hand_off = [
            # The busy arm sets its object down where it is, to have a free hand (if that object
            # fell too, the hand is already free).
            {arm: ActionCall(fn="open_gripper"), other: ActionCall(fn="place", args={"obj": held, "free_hand": True})},
            {other: ActionCall(fn="grasp", args=args), arm: ActionCall(fn="back")},
            {other: ActionCall(fn="place", args={"obj": obj, "within_reach": arm})},
            {other: ActionCall(fn="grasp", args=again)},
        ]
    return Edge(
        id=f"{entry.id}{VIA}{other}",
        source=entry.source,
        target=entry.target,
        kind="recovery",
        alternative_to=entry.id,
        actions=[*hand_off, *rest],
        # Only monitors gated by the first arm's grasp-done signal: they wait for its own grasp. An
        # ungated one (the object drifting) would fire while the other arm carries the object, and
        # the other arm's own (its object set down on purpose) would fire at once.
        failures=[failure.model_copy(deep=True) for failure in entry.failures if f"{arm}.closed *" in failure.monitor],
    )


def _regrasp_args(graph: TaskGraph) -> dict[tuple[str, str], dict]:
    """The graph's first grasp of each object by each arm: how a set-down object is taken again.

    The object may have fallen instead of being set down (both were dropped): where the graph
    re-seats the object after any grasp of it by that arm (a pour needs the nominal hold), so does
    the taking-again.
    """
    found: dict[tuple[str, str], dict] = {}
    reseated: set[tuple[str, str]] = set()
    for edge in graph.edges:
        for arm, call in edge.calls:
            if call.fn == "grasp" and "obj" in call.args:
                key = (arm, call.args["obj"])
                found.setdefault(key, {k: v for k, v in call.args.items() if k not in ("obj", "reseat")})
                if call.args.get("reseat"):
                    reseated.add(key)
    return {key: {**args, "reseat": True} if key in reseated else args for key, args in found.items()}


def add_arm_switch_alternatives(graph: TaskGraph, rigid: Iterable[str]) -> TaskGraph:
    """A copy of ``graph`` where every eligible recovery entry edge has its other-arm alternative.

    Entries that already have an alternative are left as they are, so the rule can be
    applied again without change.

    Args:
        graph: Any recovery-augmented graph.
        rigid: Objects that can be picked up and set down.
    """
    rigid = set(rigid)
    out = graph.model_copy(deep=True)
    regrasp = _regrasp_args(out)
    entries = list(dict.fromkeys(failure.recovery for _, failure in out.failures()))
    have = {edge.alternative_to for edge in out.edges if edge.alternative_to is not None}
    ids = {edge.id for edge in out.edges}
    for entry_id in entries:
        if entry_id in have or entry_id not in ids:
            continue
        alternative = arm_switch_alternative(out.edge(entry_id), rigid, regrasp)
        if alternative is not None and alternative.id not in ids:
            out.edges.append(alternative)
            ids.add(alternative.id)
    return out
