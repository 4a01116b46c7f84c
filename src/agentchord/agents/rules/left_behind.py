"""Objects put down earlier and left behind while the arms go home: knocked over or pushed off their spot.

The last edges of a task send the arms home with the work done; a person can still knock over a
bottle that was stood on the table or push a tray off the spot it was carried to, and the goal
then fails with nothing left to run. For a retreat edge (every call a ``back``) whose target
node constrains such an object, the arranger adds:

- ``<obj>_knocked`` (a tall object the target wants upright): ``tipped(obj, X + 2)`` past the
  target's ``tilt(obj) - X``, knocked flat or left leaning;
- ``<obj>_moved`` (an object put down at a spot of the table, not relative to another one: those
  are the arranger's ``_misplaced`` relations): the target's constraint on its position.

Both share one recovery: the arm (or both arms) that put it down take it again with the nominal
grasp, repeat the relative motions since (a two-arm lift), put it down as before, and merge back
at the retreat edge's source, whose edge runs again under the same monitors. A drop while doing
so starts that recovery again.
"""

from __future__ import annotations

from dataclasses import dataclass

from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.accounts import ARMS, RELATIVE, Account, ArmAccount, apply_step, side_by_side
from agentchord.agents.rules.constraints import upright_bound
from agentchord.agents.scene import SceneObject
from agentchord.graph.models import ActionCall, Edge, FailureMode, Step, TaskGraph
from agentchord.graph.progress import nominal_path

#: How far (deg) past the target's upright bound an object left behind leans before it is set upright.
LEAN_MARGIN_DEG = 2.0


@dataclass
class PutDown:
    """How one arm put an object down: its grasp, the relative motions since, and the place."""

    grasp: ActionCall
    carry: list[ActionCall]
    place: ActionCall


def is_retreat(edge: Edge) -> bool:
    """Whether every call of ``edge`` sends an arm home."""
    calls = [c for step in edge.steps for c in step.values() if c is not None]
    return bool(calls) and all(c.fn == "back" for c in calls)


def put_down_before(graph: TaskGraph, edge: Edge) -> dict[str, dict[str, PutDown]]:
    """Objects put down on the nominal path before ``edge`` and not taken again since: obj -> arm -> how.

    Two arms that put one object down in the same step (a tray carried by its handles) both appear.
    """
    out: dict[str, dict[str, PutDown]] = {}
    account: Account = {arm: ArmAccount() for arm in ARMS}
    for edge_id in nominal_path(graph):
        if edge_id == edge.id:
            break
        for step in graph.edge(edge_id).steps:
            placed_now: dict[str, dict[str, PutDown]] = {}
            for arm, call in step.items():
                if call is None:
                    continue
                if call.fn == "place" and account[arm].holding == call.args["obj"]:
                    # Taken from the other arm (a handover), it has no grasp of its own: a plain one.
                    grasp = account[arm].grasp or ActionCall(fn="grasp", args={"obj": call.args["obj"]})
                    # The place aims at its spot itself; only relative motions (a two-arm lift) are replayed.
                    carry = [c for c in account[arm].since_grasp if c.fn in RELATIVE]
                    placed_now.setdefault(call.args["obj"], {})[arm] = PutDown(grasp, carry, call)
                elif call.fn == "grasp":
                    out.pop(call.args["obj"], None)
            out.update(placed_now)
            account = apply_step(account, step)
    return out


def left_behind_branches(graph: TaskGraph, edge: Edge, objects: dict[str, SceneObject]) -> list[tuple[FailureMode, Edge | None]]:
    """Knocked-over and moved-off-its-spot branches of a retreat edge (none for any other edge)."""
    if not is_retreat(edge):
        return []
    target = graph.node(edge.target).constraints
    upright_bounds = dict(b for b in map(upright_bound, target) if b is not None)
    out: list[tuple[FailureMode, Edge | None]] = []
    for obj, by_arm in put_down_before(graph, edge).items():
        info = objects.get(obj)
        if info is None or any(p.place.args.get("relative_to") for p in by_arm.values()):
            continue
        modes: list[FailureMode] = []
        recovery = f"{edge.id}_r_{obj}_put_back"
        bound = upright_bounds.get(obj)
        if kb.is_tall(info) and bound is not None:
            # Past the target's own bound, not only knocked flat: a bottle pushed against the cup as the
            # arm left leaned 17 deg there, and the goal failed with nothing left to run. 2 deg over
            # it: a released bottle settles.
            modes.append(FailureMode(name=f"{obj}_knocked", monitor=f"tipped({obj}, {bound + LEAN_MARGIN_DEG:g})", window=kb.WINDOW,
                                     intent="set upright", recovery=recovery))
        at_spot = [c for c in target if f"{obj}.pos" in c and not _names_another(c, obj, objects)]
        if at_spot and all(p.place.args.get("target") is not None for p in by_arm.values()):
            modes.append(FailureMode(name=f"{obj}_moved", monitor=at_spot[0], window=kb.WINDOW, intent="re-place",
                                     recovery=recovery))
        if not modes:
            continue
        steps: list[Step] = [{arm: ActionCall(fn="grasp", args=dict(p.grasp.args)) for arm, p in by_arm.items()}]
        steps += side_by_side({arm: p.carry for arm, p in by_arm.items()})
        steps.append({arm: p.place for arm, p in by_arm.items()})
        terms = [f"{arm}.closed * (0.5 - holding({arm}, {obj}))" for arm in by_arm]
        drop = FailureMode(name=f"{obj}_dropped", monitor=terms[0] if len(terms) == 1 else f"max({', '.join(terms)})",
                           window=kb.WINDOW, intent="regrasp", recovery=recovery)
        put_back = Edge(id=recovery, source=edge.source, target=edge.source, kind="recovery", actions=steps, failures=[drop])
        # One recovery edge for both modes: the arranger adds an edge once, with the first mode.
        out += [(mode, put_back if k == 0 else None) for k, mode in enumerate(modes)]
    return out


def _names_another(constraint: str, obj: str, objects: dict[str, SceneObject]) -> bool:
    return any(f"{other}." in constraint or f"({other}" in constraint for other in objects if other != obj)
