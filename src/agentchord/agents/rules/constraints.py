"""The node constraints (Eq. 3) a fact stands for, in the expression language.

The composer writes, at each node, the constraints of the facts that hold there
(:mod:`~agentchord.agents.rules.facts`): each is <= 0 when the fact holds.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from agentchord.agents.scene import Scene, SceneObject
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.planner import Fact


#: An upright bound, ``tilt(obj) - X`` (X in degrees), matched with its spaces removed.
_UPRIGHT = re.compile(r"tilt\((\w+)\)-(\d+(?:\.\d+)?)")


def upright_bound(constraint: str) -> tuple[str, float] | None:
    """``(obj, X)`` of an upright bound ``tilt(obj) - X`` (X in degrees), else ``None``."""
    match = _UPRIGHT.fullmatch("".join(constraint.split()))
    return (match.group(1), float(match.group(2))) if match else None


def rounded(values: Iterable[float]) -> list[float]:
    """Numbers as written into a graph (its constraints and step arguments): rounded to 4 decimals."""
    return [round(float(v), 4) for v in values]


def fact_constraints(fact: Fact, scene: Scene) -> list[str]:
    """The node constraints (<= 0 when the fact holds) of one fact, in the expression language."""
    objects = {o.name: o for o in scene.objects}
    kind = fact[0]
    if kind == "holding":
        return [f"0.5 - holding({fact[1]}, {fact[2]})"]
    if kind == "upright":
        return []  # see upright_constraints: only while it stands on the table
    if kind == "lifted":
        return []
    if kind == "at":
        return _at_constraints(fact[1], fact[2], objects, scene)
    if kind == "presented":
        return [f"dist({fact[1]}.ee, {rounded(kb.RECEIVE_POSE)}) - 0.03", f"tilt({fact[2]}) - 15"]
    if kind == "pour_ready":
        _, arm, s, c = fact
        # Where the bottle is (a bottle held off centre is carried to where a centred one would be), at the tool's height.
        return [f"norm(xy({s}.pos - {c}.top - {list(kb.POUR_OFFSET)})) - 0.03",
                f"abs({arm}.ee[2] - {c}.top[2] - {kb.POUR_OFFSET[2]:g}) - 0.03", f"tilt({s}) - 15"]
    if kind == "poured":
        _, s, c, _ = fact
        return [f"{kb.POUR_MIN_TILT:g} - tilt({s})", f"norm(xy({s}.top - {c}.top)) - 0.5 * {c}.extent[0] - 0.01"]
    if kind == "handover_ready":
        return [f"dist({fact[1]}.ee, {rounded(kb.HANDOVER_POSE)}) - 0.03"]
    if kind == "handed":
        _, o, g, r = fact
        return [f"holding({g}, {o}) - 0.5"]
    if kind == "mated":
        return [f"0.1 - {fact[1]}.bottom[2]", f"0.1 - {fact[2]}.bottom[2]"]
    if kind == "inserted":
        return [f"norm(xy({fact[1]}.pos - {fact[2]}.pos)) - 0.5 * ({fact[1]}.extent[0] + {fact[2]}.extent[0])"]
    if kind == "over":
        far = _fold_partner(fact[2])
        return [f"norm(xy({fact[2]}.pos - {far}.pos)) - 0.06"]
    return []


def upright_constraints(state: frozenset[Fact]) -> list[str]:
    """Objects that must stand upright and stand on the table, not yet placed anywhere."""
    placed = {f[1] for f in state if f[0] == "at"}
    return [f"tilt({f[1]}) - 15" for f in sorted(state) if f[0] == "upright" and ("on_table", f[1]) in state and f[1] not in placed]


def _fold_partner(near: str) -> str:
    stem, corner = near.rsplit("_", 1)
    return f"{stem}_t{corner[1]}"


def _at_constraints(name: str, key: str, objects: dict[str, SceneObject], scene: Scene) -> list[str]:
    kind, _, rest = key.partition(":")
    parts = rest.split(":")
    released = [f"holding(left, {name}) - 0.5", f"holding(right, {name}) - 0.5"]
    obj = objects.get(name)
    upright = [f"tilt({name}) - 10"] if obj is not None and kb.keeps_upright(obj) else []
    if kind == "fold":
        return released + [f"dist({name}.pos, {parts[0]}.pos) - 0.045"]
    if kind == "spot":
        return released + upright + [f"{name}.bottom[2] - 0.01"]
    if kind == "region":
        region = next(r for r in scene.regions if r.name == parts[0])
        return released + upright + [f"norm(xy({name}.pos - {rounded([*region.center, 0.0])})) - {region.radius:g}"]
    if kind == "xy":
        return released + upright + [f"norm(xy({name}.pos - [{parts[0]}, {parts[1]}, 0.0])) - 0.03"]
    if kind == "rel":
        anchor, dx, dy = parts[0], parts[1], parts[2]
        lying = [f"tilt({name}) - 15"] if obj is not None and kb.is_flat(obj) else upright
        return released + [f"norm(xy({name}.pos - {anchor}.pos) - [{dx}, {dy}, 0.0]) - 0.03"] + lying
    if kind in ("in", "on"):
        return released + [over_footprint(name, objects[parts[0]])]
    return released


def over_footprint(name: str, host: SceneObject) -> str:
    """<= 0 while ``name``'s centre lies over ``host``'s footprint (released in it or on it).

    A round or small host's footprint is the disc its shorter side spans (Eq. 19's relational
    misalignment). A wide one (carried by
    both arms by its ends) is long: its footprint is a rectangle in its own frame, less the
    handles at its ends. The disc would read a capsule slid along a tray, still inside it, as out
    (one 6.7 cm from the centre of a tray 23 cm long inside).
    """
    half = [0.5 * host.extent[0], 0.5 * host.extent[1]]
    if not kb.is_wide(host):
        return f"misaligned({name}.pos, {host.name}.pos, {round(min(half), 4):g})"  # Eq. 19's template
    half[0 if half[0] >= half[1] else 1] -= 2 * kb.HANDLE_INSET
    x, y = rounded(half)
    return f"max(abs(local({host.name}, {name}.pos)[0]) - {x:g}, abs(local({host.name}, {name}.pos)[1]) - {y:g})"
