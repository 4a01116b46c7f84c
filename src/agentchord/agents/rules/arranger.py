"""The offline arranger: failure modes, monitors and forward-moving recovery branches (Sec. III-C).

Works on any nominal graph, the composer's or a hand-written one: it walks the nominal
path and keeps a symbolic account of the atomic actions' effects (:mod:`.accounts`: who holds
what, which motions since the last grasp, what each arm's pose is relative to). For each nominal edge
``e: s -> t`` it predicts, from what the edge does and that account:

- a held object can drop or slip (Eq. 16-17): ``regrasp`` where it fell, restore the arm's
  relative motions since the grasp, then finish ``e``;
- a tall object carried under an upright path constraint can tilt in the hand (taken askew),
  and a hand-over's giver can hold the bar low (:mod:`.in_hand`): ``reseat`` or ``regrip high``:
  set it down, take it again with the nominal hold, then ``e`` again;
- an object the edge aims at (or places relative to) can drift (Eq. 14): ``re-approach``,
  run ``e`` again on its new pose; if it must stand upright it can tip (Eq. 15): ``set upright``
  with a free arm while the busy arm parks, then ``e`` again;
- an object released inside or on another one can fall out when that one is carried (Eq. 19):
  ``re-place`` it and take the carried one again;
- an object put down earlier can be knocked over or pushed off its spot while the arms go home
  (:mod:`.left_behind`): ``put back``, then go home again;
- with RGB-D perception, a tracked object can be lost from view (Eq. 18): ``re-observe``;
- a regrasp the busy arm cannot reach gets the other arm's alternative (``arm_switch``).

Every recovery edge leaves the failure context ``s`` and merges at ``t`` (or, for a broken
relation, at ``s``): nothing regresses, and the forward-moving filter (Eq. 8) checks it.
Recovery edges carry drop monitors of their own, and a recovery that redoes an edge's carry the
slipped-grasp monitor of that edge; recovery grasps skip an object still held
and recovery places skip an object already placed (an interrupted two-arm step).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from agentchord.agents.reasoner import UnanticipatedFailure
from agentchord.agents.scene import Scene, SceneObject
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.accounts import ARMS, RELATIVE, Account, ArmAccount, apply_step, calls_of, holders_of, side_by_side
from agentchord.agents.rules.arm_switch import add_arm_switch_alternatives
from agentchord.agents.rules.constraints import over_footprint
from agentchord.agents.rules.in_hand import gripped_low, redone_slips, slipped, upright_in_hand
from agentchord.agents.rules.left_behind import left_behind_branches
from agentchord.agents.rules.recovery_steps import after_park, places_at_target, regrasp, replay_then_edge, with_skips
from agentchord.features.frame import tilt_deg
from agentchord.graph.models import ActionCall, Edge, FailureMode, Step, TaskGraph
from agentchord.graph.progress import forward_filter, nominal_path

#: Ticks a placed relation must stay broken before it counts (a released cloth settles).
MISPLACED_WINDOW = 10
#: Tilt (deg) of a placed upright object beyond which it leans (the placed constraints allow 10).
PLACED_TILT_DEG = 10.0


def _mentions(observation: str, name: str) -> bool:
    """Whether the violated constraints of an observation name an object (``bottle.top``, ``tilt(bottle)``)."""
    return re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", observation) is not None


@dataclass
class Arranger:
    """The rule set. Thresholds come from :mod:`~agentchord.agents.rules.knowledge` and the scene.

    Attributes:
        scene: The first observation (sizes for thresholds, categories).
        watch_visibility: Add lost-from-view monitors (RGB-D perception).
    """

    scene: Scene
    watch_visibility: bool = False

    def __post_init__(self) -> None:
        self.objects: dict[str, SceneObject] = {o.name: o for o in self.scene.objects}

    # --- the whole graph ---------------------------------------------------------------

    def arrange(self, graph: TaskGraph) -> TaskGraph:
        """The graph with recovery branches for every nominal edge, forward-filtered."""
        out = graph.model_copy(deep=True)
        accounts = self.accounts(graph)
        nominal = {e.id: e for e in out.edges}
        for edge_id, account in accounts.items():
            edge = nominal[edge_id]
            for mode, recovery in self.branches(graph, edge, account):
                if any(f.name == mode.name for f in edge.failures):
                    continue
                edge.failures.append(mode)
                if recovery is not None:
                    out.edges.append(recovery)
        self._monitor_recoveries(out)
        # A recovery the busy arm cannot reach is one the other arm can: its alternatives.
        rigid = [name for name in self.objects if not kb.is_cloth_corner(name)]
        return forward_filter(add_arm_switch_alternatives(out, rigid)).graph

    def accounts(self, graph: TaskGraph) -> dict[str, Account]:
        """The account at the source of every nominal edge, along the nominal path."""
        account: Account = {arm: ArmAccount() for arm in ARMS}
        for arm in self.scene.arms:
            if arm.holding:
                account[arm.name].holding = arm.holding
        out: dict[str, Account] = {}
        for edge_id in nominal_path(graph):
            edge = graph.edge(edge_id)
            out[edge_id] = account
            for step in edge.steps:
                account = apply_step(account, step)
        return out

    # --- one edge ----------------------------------------------------------------------

    def branches(self, graph: TaskGraph, edge: Edge, account: Account) -> list[tuple[FailureMode, Edge | None]]:
        """Failure modes of one nominal edge and their recovery entry edges."""
        after = account
        for step in edge.steps:
            after = apply_step(after, step)
        out = []
        held = [o for o in dict.fromkeys([a.holding for a in account.values()] + [a.holding for a in after.values()]) if o]
        for obj in held:
            out.append(self._drop(edge, account, after, obj))
        busy = {arm for step in edge.steps for arm, call in step.items() if call is not None}
        for obj in self._aimed_at(graph, edge, account, held):
            obj_info = self.objects.get(obj)
            if obj_info is None:
                continue
            replay = Edge(
                id=f"{edge.id}_r_{obj}_moved", source=edge.source, target=edge.target, kind="recovery",
                actions=replay_then_edge(account, edge, busy),
            )
            if kb.keeps_upright(obj_info):
                tipped = self._set_upright(edge, account, obj, busy)
                if tipped is not None:
                    out.append(tipped)
            shifted = FailureMode(name=f"{obj}_shifted", monitor=f"drift({obj}, {kb.drift_tolerance(obj_info):g})", window=kb.WINDOW,
                                  intent="re-approach", recovery=replay.id)
            out.append((shifted, replay))
            if self.watch_visibility:
                lost = FailureMode(name=f"{obj}_lost", monitor=f"lost_view({obj}, {kb.MIN_POINTS})", window=kb.WINDOW,
                                   intent="re-observe", recovery=replay.id)
                out.append((lost, None))
        out += upright_in_hand(edge, account, after, self.objects)
        out += gripped_low(graph, edge, account)
        out += self._relations(graph, edge, account, after)
        out += self._misplaced(graph, edge, account)
        out += left_behind_branches(graph, edge, self.objects)
        return out

    def _misplaced(self, graph: TaskGraph, edge: Edge, before: Account) -> list[tuple[FailureMode, Edge]]:
        """Objects released relative to another one earlier, left alone by this edge: the relation the
        target node states can break as they settle (Eq. 19). Re-place: take it again, bring it over the
        spot the way the nominal path's last motions did, put it on the anchor itself (a second place does not drag what it lies
        on), and merge back at the edge's source, whose edge runs again under the same monitors. Two
        broken at once are re-placed together."""
        placed = self._placements(graph, edge)
        target = graph.node(edge.target).constraints
        singles: list[tuple[FailureMode, Edge, str, list[Step]]] = []
        carried = {before[a].holding for a in ARMS if before[a].holding}
        for obj, (host, arm, grasp, place, carry) in placed.items():
            if any(before[a].holding == obj for a in ARMS) or any(c.args.get("obj") == obj for _, c in edge.calls):
                continue
            if host in carried or before[arm].holding is not None:
                continue  # travels with a carried host (see _relations), or the placing arm's hands are full
            relation = [c for c in target if obj in c and host in c]
            if not relation:
                continue
            again = ActionCall(fn="place", args={**place.args, "target": [0.0, 0.0]}) if "dist(" in relation[0] else place
            steps: list[Step] = [{arm: ActionCall(fn="grasp", args={**grasp.args})}, *({arm: c} for c in carry), {arm: again}]
            singles.append((FailureMode(name=f"{obj}_misplaced", monitor=relation[0], window=MISPLACED_WINDOW, intent="re-place",
                                        recovery=f"{edge.id}_r_{obj}_misplaced"), None, arm, steps))
        out: list[tuple[FailureMode, Edge]] = []
        if len(singles) == 2 and singles[0][2] != singles[1][2]:
            (m1, _, a1, s1), (m2, _, a2, s2) = singles
            both = side_by_side({a1: [c for st in s1 for c in st.values()], a2: [c for st in s2 for c in st.values()]})
            entry = f"{edge.id}_r_both_misplaced"
            monitor = f"min({m1.monitor}, {m2.monitor})"
            out.append((FailureMode(name="both_misplaced", monitor=monitor, window=MISPLACED_WINDOW, intent="re-place", recovery=entry),
                        Edge(id=entry, source=edge.source, target=edge.source, kind="recovery", actions=both)))
        for mode, _, _, steps in singles:
            out.append((mode, Edge(id=mode.recovery, source=edge.source, target=edge.source, kind="recovery", actions=steps)))
        return out

    def _placements(self, graph: TaskGraph, edge: Edge) -> dict[str, tuple[str, str, ActionCall, ActionCall, list[ActionCall]]]:
        """Objects placed relative to another before ``edge`` on the nominal path:
        obj -> (host, arm, grasp, place, the motions that brought it over the spot)."""
        placed: dict[str, tuple[str, str, ActionCall, ActionCall, list[ActionCall]]] = {}
        account: Account = {arm: ArmAccount() for arm in ARMS}
        for edge_id in nominal_path(graph):
            if edge_id == edge.id:
                break
            for step in graph.edge(edge_id).steps:
                for arm, call in step.items():
                    if call is not None and call.fn == "place" and call.args.get("relative_to") and account[arm].grasp is not None:
                        # The last carrying motion (and what followed it) brought it over the spot: replay those,
                        # not the whole carry (a cloth corner lifted from its start again would unfold it).
                        placed[call.args["obj"]] = (call.args["relative_to"], arm, account[arm].grasp, call, list(account[arm].since_grasp))
                    elif call is not None and call.fn == "grasp":
                        placed.pop(call.args["obj"], None)
                account = apply_step(account, step)
        return placed

    def _drop(self, edge: Edge, before: Account, after: Account, obj: str) -> tuple[FailureMode, Edge]:
        at_s, at_t = holders_of(before, obj), holders_of(after, obj)
        if at_s and at_t and at_s != at_t:  # passed between the arms: someone must hold it throughout
            monitor = f"0.5 - max(holding(left, {obj}), holding(right, {obj}))"
        else:
            arms = at_s or at_t
            deliberate = not at_s or not at_t  # grasped or released on purpose: trust the latched grasp-done signal
            terms = [f"{a}.closed * (0.5 - holding({a}, {obj}))" if deliberate else f"0.5 - holding({a}, {obj})" for a in arms]
            monitor = terms[0] if len(terms) == 1 else f"max({', '.join(terms)})"
        if not at_s:  # grasped during the edge: finish the grasp
            steps = [{a: with_skips(c) for a, c in step.items() if c is not None} for step in edge.steps]
        else:
            busy = {arm for step in edge.steps for arm, call in step.items() if call is not None}
            tall = obj in self.objects and kb.is_tall(self.objects[obj])
            # Carried by two arms and lost by one, it hangs from the other: both let go (a grasp opens
            # first), so it lands flat, and both take it again.
            retake: Step = {a: regrasp(before, a, obj, tall, skip_if_held=len(at_s) < 2,
                                       skip_if_placed=places_at_target(edge, a, obj)) for a in at_s}
            # An arm of this edge with empty hands gets out of the way while the object is taken again.
            retake.update({a: ActionCall(fn="back") for a in busy if a not in at_s and before[a].holding is None})
            steps = [retake, *replay_then_edge(before, edge, at_s or busy, regrasped=True)]
        recovery = Edge(id=f"{edge.id}_r_{obj}_dropped", source=edge.source, target=edge.target, kind="recovery", actions=steps)
        mode = FailureMode(name=f"{obj}_dropped", monitor=monitor, window=kb.WINDOW, intent="regrasp", recovery=recovery.id)
        return mode, recovery

    def _aimed_at(self, graph: TaskGraph, edge: Edge, account: Account, held: list[str]) -> list[str]:
        """Objects the edge aims at (or keeps a pose relative to) whose pose its target constrains."""
        names: list[str] = []
        for arm in ARMS:
            calls = calls_of(edge, arm)
            for call in calls:
                for key in ("obj", "relative_to"):
                    name = call.args.get(key)
                    if name and (call.fn != "grasp") and (call.fn != "place" or key == "relative_to"):
                        names.append(name)
            if calls and calls[0].fn in RELATIVE and account[arm].relative_to:
                names.append(account[arm].relative_to)
        target = graph.node(edge.target)
        text = " ".join(target.constraints)
        return [
            n for n in dict.fromkeys(names)
            if n not in held and not kb.is_cloth_corner(n) and (f"{n}." in text or f"({n}" in text or f" {n})" in text)
        ]

    def _set_upright(self, edge: Edge, account: Account, obj: str, busy: set[str]) -> tuple[FailureMode, Edge] | None:
        free = [a for a in ARMS if account[a].holding is None and a not in busy]
        if not free:
            return None
        helper = free[0]
        parked = {a: ActionCall(fn="move_to_target", args={"pos": list(kb.PARK_POSE[a][0]), "yaw": kb.PARK_POSE[a][1]}) for a in busy if account[a].holding}
        steps: list[Step] = [parked] if parked else []
        steps += [{helper: ActionCall(fn="grasp", args={"obj": obj})}, {helper: ActionCall(fn="place", args={"obj": obj})}, {helper: ActionCall(fn="back")}]
        steps += replay_then_edge(account, edge, busy) if not parked else after_park(account, edge, busy)
        recovery = Edge(id=f"{edge.id}_r_{obj}_tipped", source=edge.source, target=edge.target, kind="recovery", actions=steps)
        mode = FailureMode(name=f"{obj}_tipped", monitor=f"tipped({obj}, {kb.TIP_DEG:g})", window=kb.WINDOW, intent="set upright", recovery=recovery.id)
        return mode, recovery

    def _relations(self, graph: TaskGraph, edge: Edge, before: Account, after: Account) -> list[tuple[FailureMode, Edge]]:
        """Objects released in or on one that this edge carries (Eq. 19): put them back, take the carrier again."""
        out = []
        # Released inside or on top of the host (no lateral offset): it travels with the host.
        placed = {obj: p for obj, p in self._placements(graph, edge).items() if not any(abs(v) > 1e-9 for v in (p[3].args.get("target") or (0.0, 0.0)))}
        carried = {before[a].holding for a in ARMS if before[a].holding}  # held at the source: this edge moves it
        for obj, (host, arm, grasp, place, _) in placed.items():
            if host not in carried or host not in self.objects:
                continue
            holders = holders_of(before, host)
            steps: list[Step] = [{a: ActionCall(fn="place", args={"obj": host, "skip_if_placed": True}) for a in holders}]
            steps += [{arm: with_skips(grasp)}, {arm: place}]
            steps.append({a: regrasp(before, a, host) for a in holders})
            steps += side_by_side({a: before[a].since_grasp for a in holders if before[a].since_grasp})
            recovery = Edge(id=f"{edge.id}_r_{obj}_out", source=edge.source, target=edge.source, kind="recovery", actions=steps)
            mode = FailureMode(name=f"{obj}_out", monitor=over_footprint(obj, self.objects[host]), window=kb.WINDOW, intent="re-place", recovery=recovery.id)
            out.append((mode, recovery))
        return out

    def _monitor_recoveries(self, graph: TaskGraph) -> None:
        """Drop monitors on recovery edges: a second drop re-enters that object's recovery from the same context.
        A recovery that redoes a nominal edge's carry also watches that edge's slips (:func:`redone_slips`).

        Watched: what the arms hold at the recovery's source and what the recovery grasps. The
        grasp-done signal gates every such monitor: a recovery grasps and places on purpose.
        """
        entries = {(e.source, f.name): f.recovery for e in graph.nominal_edges() for f in e.failures if f.intent == "regrasp"}
        accounts = {graph.edge(edge_id).source: account for edge_id, account in self.accounts(graph).items()}
        for edge in graph.recovery_edges():
            if edge.failures:
                continue
            source = accounts.get(edge.source)
            held: dict[str, list[str]] = {}  # object -> arms
            for arm in ARMS:
                if source is not None and source[arm].holding:
                    held.setdefault(source[arm].holding, []).append(arm)
            for step in edge.steps:
                for arm, call in step.items():
                    if call is not None and call.fn == "grasp" and arm not in held.setdefault(call.args["obj"], []):
                        held[call.args["obj"]].append(arm)
            for obj, arms in held.items():
                name = f"{obj}_dropped"
                recovery = entries.get((edge.source, name))
                if recovery is None or not arms:
                    continue
                terms = [f"{arm}.closed * (0.5 - holding({arm}, {obj}))" for arm in arms]
                monitor = terms[0] if len(terms) == 1 else f"max({', '.join(terms)})"
                edge.failures.append(FailureMode(name=name, monitor=monitor, window=kb.WINDOW, intent="regrasp", recovery=recovery))
            edge.failures += redone_slips(graph, edge)

    # --- online repair -----------------------------------------------------------------

    def _replace_tilted(self, edge: Edge, before: Account, current: dict[str, SceneObject], holding: set) -> tuple[FailureMode, Edge] | None:
        """An upright object this edge put down leans (released on something, or held off-centre): place it again."""
        for arm in ARMS:
            for call in calls_of(edge, arm):
                obj = call.args.get("obj")
                info = self.objects.get(obj or "")
                # Held again (by either arm: a hand-off set down for the other arm to take), it is not put down.
                if call.fn != "place" or info is None or obj not in current or any(held == obj for _, held in holding):
                    continue
                if not kb.keeps_upright(info) or tilt_deg(current[obj].axis) <= PLACED_TILT_DEG:
                    continue
                steps: list[Step] = [{arm: regrasp(before, arm, obj, kb.is_tall(info))}, {arm: call}]
                recovery = Edge(id=f"{edge.id}_r_{obj}_leaning", source=edge.source, target=edge.target, kind="recovery", actions=steps)
                monitor = f"(1 - {arm}.closed) * tipped({obj}, {PLACED_TILT_DEG + 2:g})"
                mode = FailureMode(name=f"{obj}_leaning", monitor=monitor, window=kb.WINDOW, intent="re-place", recovery=recovery.id)
                return mode, recovery
        return None

    def repair(self, graph: TaskGraph, failure: UnanticipatedFailure, now: Scene) -> TaskGraph | None:
        """One new branch for an unanticipated failure at the end of a nominal edge, or ``None``.

        Reads the current observation ``now`` against the nominal account at the edge's source: a held
        object no longer held is a drop; a held object tilted in the hand, where a violated
        constraint names it, is a slipped grasp (set it down upright, take it again, redo the edge:
        a pour whose mouth ended off the cup is poured again; a bottle tilted by the pour while
        another arm's pose is what is violated is left alone); an upright object lying on its side
        is a tip.
        """
        accounts = self.accounts(graph)
        edge = graph.edge(failure.edge)
        # A recovery edge starts where a nominal edge does: the account there is the same.
        by_source = {graph.edge(e).source: a for e, a in accounts.items()}
        before = accounts.get(edge.id) or by_source.get(edge.source)
        if before is None:
            return None
        after = before
        for step in edge.steps:
            after = apply_step(after, step)
        current = {o.name: o for o in now.objects}
        holding = {(a.name, a.holding) for a in now.arms if a.holding}
        branch: tuple[FailureMode, Edge] | None = None
        # A recovery edge's own calls are all that is known of where it left things.
        touched = {c.args.get("obj") for _, c in edge.calls} if edge.is_recovery else None
        for arm in ARMS:
            obj = after[arm].holding
            if not obj or obj not in current or (touched is not None and obj not in touched):
                continue
            info = self.objects.get(obj)
            if (arm, obj) not in holding:
                mode, recovery = self._drop(edge, before, after, obj)
                entry = f"{edge.id}_r_{obj}_lost_unforeseen"
                branch = (mode.model_copy(update={"name": f"{obj}_lost_unforeseen", "recovery": entry}), recovery.model_copy(update={"id": entry}))
            elif (info is not None and kb.is_tall(info) and tilt_deg(current[obj].axis) > 15.0 and before[arm].holding == obj
                  and _mentions(failure.observation, obj)):
                branch = slipped(edge, before, arm, obj, 15.0)
            if branch:
                break
        if branch is None:
            branch = self._replace_tilted(edge, before, current, holding)
        if branch is None:
            for name, info in self.objects.items():
                if name in current and kb.keeps_upright(info) and not any((a, name) in holding for a in ARMS) and tilt_deg(current[name].axis) > kb.TIP_DEG:
                    busy = {a for step in edge.steps for a, c in step.items() if c is not None}
                    branch = self._set_upright(edge, before, name, busy)
                    if branch:
                        break
        if branch is None:
            return None
        mode, recovery = branch
        if any(f.name == mode.name for f in edge.failures) or any(e.id == recovery.id for e in graph.edges):
            return None
        out = graph.model_copy(deep=True)
        out.edge(edge.id).failures.append(mode)
        out.edges.append(recovery)
        return out

