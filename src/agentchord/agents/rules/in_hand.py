"""Holds that go wrong in the hand: a tall object slipped askew, a hand-over's giver holding low.

Each is watched while the arm holds the object and recovered the same way (:func:`retaken`):
set it down, take it again with the nominal hold, bring it back, redo the edge.
"""

from __future__ import annotations

import re

from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.accounts import ARMS, Account, calls_of, holders_of
from agentchord.agents.rules.constraints import upright_bound
from agentchord.agents.rules.recovery_steps import regrasp, replay_then_edge
from agentchord.agents.scene import SceneObject
from agentchord.graph.models import ActionCall, Edge, FailureMode, Step, TaskGraph
from agentchord.graph.progress import nominal_path
from agentchord.robot.aloha import other_arm

#: A slipped-grasp monitor, ``holding(arm, obj) * tipped(obj, X)``, matched with its spaces removed.
_SLIP_MONITOR = re.compile(r"holding\((left|right),(\w+)\)\*tipped\(\2,(\d+(?:\.\d+)?)\)")


def redone_slips(graph: TaskGraph, recovery: Edge) -> list[FailureMode]:
    """The slipped-grasp modes of the nominal edge a recovery redoes the carry of.

    A recovery from the same source to the same target whose holding arm makes only that edge's own
    calls (a re-approach to a shifted host) carries the object the same way, under the same upright
    bound: a slip then is the same failure (a bottle turned 24 deg in the hand while it was brought
    to a moved cup again, and was poured from there).
    """
    out = []
    for nominal in graph.nominal_edges():
        if (nominal.source, nominal.target) != (recovery.source, recovery.target):
            continue
        for mode in nominal.failures:
            match = _SLIP_MONITOR.fullmatch("".join(mode.monitor.split()))
            if mode.intent != "reseat" or match is None:
                continue
            arm = match.group(1)
            redone = calls_of(recovery, arm)
            if redone and all(call in calls_of(nominal, arm) for call in redone):
                out.append(mode.model_copy())
    return out


def retaken(edge: Edge, before: Account, arm: str, obj: str, failure: str, monitor: str, intent: str) -> tuple[FailureMode, Edge]:
    """A hold that went wrong in the hand: set the object down, take it again with the nominal
    hold, bring it back and redo the edge."""
    steps: list[Step] = [{arm: ActionCall(fn="place", args={"obj": obj})}, {arm: regrasp(before, arm, obj)}]
    steps += replay_then_edge(before, edge, {arm}, regrasped=True)
    recovery = Edge(id=f"{edge.id}_r_{failure}", source=edge.source, target=edge.target, kind="recovery", actions=steps)
    return FailureMode(name=failure, monitor=monitor, window=kb.WINDOW, intent=intent, recovery=recovery.id), recovery

def slipped(edge: Edge, before: Account, arm: str, obj: str, limit_deg: float) -> tuple[FailureMode, Edge]:
    """A tall object tilted in the hand (pushed while it was taken, knocked in the hand): set it
    down, take it again with the nominal hold, redo the edge. A pour or an upright place from
    an askew hold fails however the rest of the task goes."""
    return retaken(edge, before, arm, obj, f"{obj}_slipped", f"holding({arm}, {obj}) * tipped({obj}, {limit_deg:g})", "reseat")

def gripped_low(graph: TaskGraph, edge: Edge, before: Account) -> list[tuple[FailureMode, Edge]]:
    """The giver of a hand-over holding the bar low (a fallen bar is taken by its middle): the
    receiver's fingers, taken low too, find no room beside it, and the bar drops in the hand-over.
    Set it down standing, take it high again."""
    path = nominal_path(graph)
    later = [graph.edge(e) for e in path[path.index(edge.id):]]
    out = []
    for arm in ARMS:
        obj, grasp = before[arm].holding, before[arm].grasp
        if obj is None or grasp is None or grasp.args.get("height") != kb.HANDOVER_GIVER_HEIGHT:
            continue
        if not any(c.fn == "grasp" and c.args.get("obj") == obj for e in later for c in calls_of(e, other_arm(arm))):
            continue  # not handed over from here on
        # Only while the bar stands: a bar lying in the hand has no high and low.
        monitor = (f"holding({arm}, {obj}) * clip({kb.HANDOVER_STANDING_DEG:g} - tilt({obj}), 0, 1) * "
                   f"({kb.HANDOVER_GRIP_LOW:g} * {obj}.extent[2] - ({arm}.ee[2] - {obj}.bottom[2]))")
        out.append(retaken(edge, before, arm, obj, f"{obj}_grip_low", monitor, "regrip high"))
    return out

def upright_in_hand(edge: Edge, before: Account, after: Account, objects: dict[str, SceneObject]) -> list[tuple[FailureMode, Edge]]:
    """Slipped-grasp branches for the tall objects an edge carries under an upright path constraint.

    The path constraint ``tilt(obj) - X`` says the object must stay within X degrees of upright
    while the edge runs; held throughout by one arm, leaving that bound means the hold slipped.
    """
    out = []
    for constraint in edge.path_constraints:
        bound = upright_bound(constraint)
        if bound is None:
            continue
        obj, limit = bound
        info = objects.get(obj)
        holders = holders_of(before, obj)
        if info is None or not kb.is_tall(info) or len(holders) != 1 or holders_of(after, obj) != holders:
            continue
        out.append(slipped(edge, before, holders[0], obj, limit))
    return out
