"""Arm-switching alternatives: a recovery the busy arm cannot reach is one the other arm can.

For every recovery entry edge that starts by one arm grasping a rigid object again
(``regrasp``, ``re-approach`` of a grasp), the rule adds an alternative edge
(``Edge.alternative_to``) with the same ends: the first arm opens and goes home out of
the way while the *other* arm takes the object wherever it lies, sets it down where both
arms reach (``place`` with ``within_reach``; the spot is chosen when it runs), goes home, and then the entry edge's own steps run
unchanged, so the recovery merges where it always did. Still one pre-compiled branch
per failure mode, still forward-moving (the alternative has the entry edge's ends, so
Eq. 8 judges both alike): no re-planning at run time. Which of the two runs is decided
when the recovery starts, once the object is at rest, by a reach and IK check
(``execution.feasibility``).

Works on any graph, the composer's or a hand-written one; the library graphs carry the
alternatives it writes (``tests/test_tasks_library.py`` checks they are up to date).
"""

from __future__ import annotations

from collections.abc import Iterable

from agentchord.graph.models import ActionCall, Edge, Step, TaskGraph

ARMS = ("left", "right")
#: Suffix of an alternative's id: ``<entry id>_via_<arm>``.
VIA = "_via_"
#: Grasp arguments the other arm keeps (the rest are the first arm's geometry: yaw, offsets).
PORTABLE_GRASP_ARGS = ("obj", "mode", "height")


def _other(arm: str) -> str:
    return "right" if arm == "left" else "left"


def _single_arm_grasp(step: Step) -> tuple[str, ActionCall] | None:
    """``(arm, grasp)`` when the step is one arm's grasp (the other idle or going home)."""
    grasps = [(arm, call) for arm, call in step.items() if call is not None and call.fn == "grasp"]
    others = [call for arm, call in step.items() if call is not None and call.fn != "grasp"]
    if len(grasps) != 1 or any(call.fn != "back" for call in others):
        return None
    return grasps[0]


def arm_switch_alternative(entry: Edge, rigid: Iterable[str]) -> Edge | None:
    """The other arm's way along a recovery entry edge, or None when the rule does not apply.

    It applies when the entry starts with one arm grasping a rigid object and the other arm's
    hand is free during the entry (none of its monitors watches what the other arm holds).

    Args:
        entry: A recovery entry edge.
        rigid: Objects that can be picked up and set down (not a cloth's corner).
    """
    first = _single_arm_grasp(entry.steps[0]) if entry.steps else None
    if first is None:
        return None
    arm, grasp = first
    obj = grasp.args.get("obj")
    if obj not in set(rigid):
        return None
    other = _other(arm)
    if any(f"holding({other}," in failure.monitor for failure in entry.failures):
        return None  # the entry watches what the other arm holds: that hand is not free
    args = {key: grasp.args[key] for key in PORTABLE_GRASP_ARGS if key in grasp.args}
    # The other arm already went home in the hand-off: drop its "back" from the entry's first step.
    rest_first = {a: c for a, c in entry.steps[0].items() if a != other}
    hand_off: list[Step] = [
        # The arm that lost the object opens: its grasp-done signal resets, so its drop monitors wait for its own grasp.
        {arm: ActionCall(fn="open_gripper")},
        # ...and goes home while the other arm reaches: it may stand where it just tried to grasp.
        {other: ActionCall(fn="grasp", args=args), arm: ActionCall(fn="back")},
        {other: ActionCall(fn="place", args={"obj": obj, "within_reach": arm})},
        {other: ActionCall(fn="back")},
    ]
    return Edge(
        id=f"{entry.id}{VIA}{other}",
        source=entry.source,
        target=entry.target,
        kind="recovery",
        alternative_to=entry.id,
        actions=[*hand_off, rest_first, *entry.steps[1:]],
        # Only monitors gated by the first arm's grasp-done signal: they wait for its own grasp. An
        # ungated one (the object drifting) would fire while the other arm carries the object.
        failures=[failure.model_copy(deep=True) for failure in entry.failures if f"{arm}.closed *" in failure.monitor],
    )


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
    entries = list(dict.fromkeys(failure.recovery for _, failure in out.failures()))
    have = {edge.alternative_to for edge in out.edges if edge.alternative_to is not None}
    ids = {edge.id for edge in out.edges}
    for entry_id in entries:
        if entry_id in have or entry_id not in ids:
            continue
        alternative = arm_switch_alternative(out.edge(entry_id), rigid)
        if alternative is not None and alternative.id not in ids:
            out.edges.append(alternative)
            ids.add(alternative.id)
    return out
