"""The symbolic state of the offline reasoner: the facts of an observation, and those a goal asks for.

Facts (tuples of strings):

- ``free a`` / ``home a``: arm ``a`` holds nothing / is at home;
- ``holding a o``; ``lifted a``: the held object lifted clear of the table;
- ``on_table o``; ``upright o``; ``fallen o``;
- ``at o KEY``: ``o`` released at a destination: ``spot`` (where it was taken from),
  ``region:NAME``, ``rel:ANCHOR:DX:DY:YAW``, ``in:C``, ``on:S``, ``fold:FAR``;
- ``presented a c``: a container held up to be poured into;
- ``pour_ready a s c`` / ``tilted a``; ``poured s c MODE`` (``table`` or ``held``);
  ``under_pour c``: a vessel is tilted over container ``c`` (it is not moved until upright again);
- ``grip_low a``: arm ``a``, still to hand its object over, holds it standing but low;
- ``handover_ready a o``; ``handed o GIVER RECEIVER``; ``over a corner``.

The skills that make them true or false are in :mod:`~agentchord.agents.rules.skills`; the
node constraints each fact stands for, in :mod:`~agentchord.agents.rules.constraints`.
"""

from __future__ import annotations

import math

from agentchord.agents.scene import ArmState, Scene, SceneObject
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.goals import Folded, GoalSpec, HandedOver, Inserted, Inside, On, Placed, Poured
from agentchord.agents.rules.planner import Fact
from agentchord.robot.aloha import ARMS  # re-exported: the arms, as facts name them


#: Facts that record an event: a constraint of the node where they became true only.
EVENT_FACTS = frozenset({"poured", "handed"})


def initial_state(scene: Scene, goal: GoalSpec | None = None) -> frozenset[Fact]:
    """The facts of an observation: the first one, or one taken mid-task (a re-plan).

    A held object that must stay upright is upright in the hand (``tilted`` for its arm
    when it is held tipped, as in the middle of a pour). With ``goal``, a destination the
    goal asks for that already holds in the scene (an object released at its place, a
    cloth corner laid on its partner) is a fact, so a re-plan does not do it again.
    """
    facts: set[Fact] = set()
    objects = {o.name: o for o in scene.objects}
    held = {arm.holding: arm.name for arm in scene.arms if arm.holding}
    for arm in ARMS:
        holder = next((a for a in scene.arms if a.name == arm), None)
        if holder is not None and holder.holding:
            facts.add(("holding", arm, holder.holding))
            obj = objects.get(holder.holding)
            if obj is not None and kb.keeps_upright(obj):
                facts.add(("upright", obj.name))
                if obj.axis[2] < HELD_TILTED_Z:
                    facts.add(("tilted", arm))
                    facts |= {("under_pour", c) for c in poured_into(scene).get(arm, [])}
            if goal is not None and obj is not None and _gives_low(holder, obj, goal):
                facts.add(("grip_low", arm))
        else:
            facts.add(("free", arm))
            if holder is None or holder.home:
                facts.add(("home", arm))
    for obj in scene.objects:
        if obj.name in held:
            continue
        facts.add(("on_table", obj.name))
        facts |= {("reach", arm, obj.name) for arm in (ARMS if obj.reachable_by is None else obj.reachable_by)}
        if kb.keeps_upright(obj):
            facts.add(("upright", obj.name) if obj.axis[2] > 0.8 else ("fallen", obj.name))
    if goal is not None:
        for name, key in _destinations(goal):
            if name not in held and _already_at(name, key, objects, scene):
                facts.add(("at", name, key))
    return frozenset(facts)


#: Axis height (cos 45 deg) under which a held upright object counts as tipped in the hand.
HELD_TILTED_Z = 0.707
#: How far (m) beyond a container's rim a tipped vessel's mouth may be and still pour into it.
POUR_REACH = 0.05


def _gives_low(holder: ArmState, obj: SceneObject, goal: GoalSpec) -> bool:
    """Whether ``holder`` is still to hand ``obj`` over and holds it standing but low: the
    receiver's fingers, taken low too, would find no room (a fallen bar taken by its middle)."""
    gives = any(isinstance(g, HandedOver) and g.obj == obj.name and g.giver == holder.name for g in goal.goals)
    standing = obj.axis[2] > math.cos(math.radians(kb.HANDOVER_STANDING_DEG))
    bottom = obj.pos[2] - 0.5 * obj.extent[2] * obj.axis[2]
    return gives and standing and holder.ee[2] - bottom < kb.HANDOVER_GRIP_LOW * obj.extent[2]


def poured_into(scene: Scene) -> dict[str, list[str]]:
    """Arm -> the containers under the mouth of the vessel it holds tipped (a re-plan mid-pour).

    Such a container is not moved before the vessel is upright again (``under_pour``).
    """
    objects = {o.name: o for o in scene.objects}
    out: dict[str, list[str]] = {}
    for holder in scene.arms:
        vessel = objects.get(holder.holding or "")
        if vessel is None or not kb.keeps_upright(vessel) or vessel.axis[2] >= HELD_TILTED_Z:
            continue
        mouth = [p + 0.5 * vessel.extent[2] * a for p, a in zip(vessel.pos, vessel.axis, strict=True)]
        for c in scene.objects:
            rim = 0.5 * max(c.extent[0], c.extent[1]) + POUR_REACH
            if c.name != vessel.name and kb.is_container(c) and math.dist(mouth[:2], c.pos[:2]) <= rim:
                out.setdefault(holder.name, []).append(c.name)
    return out


def _destinations(goal: GoalSpec) -> list[tuple[str, str]]:
    out: list[tuple[str, str]] = []
    for g in goal.goals:
        if isinstance(g, Placed):
            out.append((g.obj, placed_key(g)))
        elif isinstance(g, Inside):
            out.append((g.obj, f"in:{g.container}"))
        elif isinstance(g, On):
            out.append((g.obj, f"on:{g.support}"))
        elif isinstance(g, Folded):
            out += [(f"{g.cloth}_bl", f"fold:{g.cloth}_tl"), (f"{g.cloth}_br", f"fold:{g.cloth}_tr")]
    return out


def _already_at(name: str, key: str, objects: dict[str, SceneObject], scene: Scene) -> bool:
    """Whether a released object already rests at a destination (the tolerances of :func:`~agentchord.agents.rules.constraints.fact_constraints`)."""
    obj = objects.get(name)
    if obj is None:
        return False
    kind, _, rest = key.partition(":")
    parts = rest.split(":")

    def xy_dist(x: float, y: float) -> float:
        return float(((obj.pos[0] - x) ** 2 + (obj.pos[1] - y) ** 2) ** 0.5)

    upright = not kb.keeps_upright(obj) or obj.axis[2] >= UPRIGHT_PLACED_Z
    if kind == "fold":
        far = objects.get(parts[0])
        return far is not None and sum((a - b) ** 2 for a, b in zip(obj.pos, far.pos, strict=True)) ** 0.5 <= 0.045
    if kind == "region":
        region = next((r for r in scene.regions if r.name == parts[0]), None)
        return region is not None and upright and xy_dist(*region.center) <= region.radius
    if kind == "xy":
        return upright and xy_dist(float(parts[0]), float(parts[1])) <= 0.03
    if kind == "rel":
        anchor = objects.get(parts[0])
        return anchor is not None and upright and xy_dist(anchor.pos[0] + float(parts[1]), anchor.pos[1] + float(parts[2])) <= 0.03
    if kind in ("in", "on"):
        host = objects.get(parts[0])
        if host is None or xy_dist(host.pos[0], host.pos[1]) > 0.5 * min(host.extent[0], host.extent[1]):
            return False
        rim = host.pos[2] + 0.5 * host.extent[2]
        return obj.pos[2] < rim if kind == "in" else obj.pos[2] > rim
    return False  # "spot": where it was taken from is not in an observation


#: Axis height (cos 10 deg) of an object placed upright.
UPRIGHT_PLACED_Z = 0.985


def goal_facts(goal: GoalSpec, scene: Scene) -> list[frozenset[Fact]]:
    """The facts each goal predicate asks for, in the goal's order (cumulative), then home."""
    stages: list[frozenset[Fact]] = []
    wanted: set[Fact] = set()
    for g in goal.goals:
        if isinstance(g, Poured):
            wanted.add(("poured", g.source, g.target, "held" if g.hold_target else "table"))
        elif isinstance(g, Placed):
            wanted.add(("at", g.obj, placed_key(g)))
        elif isinstance(g, Inside):
            wanted.add(("at", g.obj, f"in:{g.container}"))
        elif isinstance(g, On):
            wanted.add(("at", g.obj, f"on:{g.support}"))
        elif isinstance(g, HandedOver):
            wanted.add(("handed", g.obj, g.giver, g.receiver))
        elif isinstance(g, Folded):
            wanted |= {("at", f"{g.cloth}_bl", f"fold:{g.cloth}_tl"), ("at", f"{g.cloth}_br", f"fold:{g.cloth}_tr")}
        elif isinstance(g, Inserted):
            wanted.add(("inserted", g.obj, g.into))
        stages.append(frozenset(wanted))
    # An insertion ends the task with both hands on the mated pair: nobody goes home after it.
    if goal.home and not any(isinstance(g, Inserted) for g in goal.goals):
        stages.append(frozenset(wanted | {("home", "left"), ("home", "right")}))
    return stages


def placed_key(goal: Placed) -> str:
    """The destination key of a placed goal."""
    if goal.region:
        return f"region:{goal.region}"
    if goal.at is not None:
        return f"xy:{goal.at[0]:g}:{goal.at[1]:g}"
    if goal.relative_to:
        yaw = "" if goal.yaw is None else f"{goal.yaw:g}"
        return f"rel:{goal.relative_to}:{goal.offset[0]:g}:{goal.offset[1]:g}:{yaw}"
    return "spot"
