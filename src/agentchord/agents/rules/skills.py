"""Skills as STRIPS operators over the scene: the composer's planning domain.

Each skill is grounded over the scene's arms and objects, filtered by category
(:mod:`~agentchord.agents.rules.knowledge`): a wide object takes both arms, a flat one
is lifted clear before it is carried, a pour needs a vessel and a container. Every
ground operator carries the atomic-action steps of its edge. :func:`fact_constraints`
turns the facts of a state into the node constraints (Eq. 3) of the language.

Facts (tuples of strings):

- ``free a`` / ``home a``: arm ``a`` holds nothing / is at home;
- ``holding a o``; ``lifted a``: the held object lifted clear of the table;
- ``on_table o``; ``upright o``; ``fallen o``;
- ``at o KEY``: ``o`` released at a destination: ``spot`` (where it was taken from),
  ``region:NAME``, ``rel:ANCHOR:DX:DY:YAW``, ``in:C``, ``on:S``, ``fold:FAR``;
- ``presented a c``: a container held up to be poured into;
- ``pour_ready a s c`` / ``tilted a``; ``poured s c MODE`` (``table`` or ``held``);
- ``handover_ready a o``; ``handed o GIVER RECEIVER``; ``over a corner``.
"""

from __future__ import annotations

from collections.abc import Iterable

from agentchord.agents.scene import Scene, SceneObject
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.goals import Folded, GoalSpec, HandedOver, Inside, On, Placed, Poured
from agentchord.agents.rules.planner import Fact, Operator

ARMS = ("left", "right")
#: Facts that record an event: a constraint of the node where they became true only.
EVENT_FACTS = frozenset({"poured", "handed"})


def other(arm: str) -> str:
    """The other arm."""
    return "right" if arm == "left" else "left"


def _call(fn: str, **args) -> dict:
    return {"fn": fn, "args": args} if args else {"fn": fn}


def _r(values: Iterable[float]) -> list[float]:
    return [round(float(v), 4) for v in values]


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
        else:
            facts.add(("free", arm))
            if holder is None or holder.home:
                facts.add(("home", arm))
    for obj in scene.objects:
        if obj.name in held:
            continue
        facts.add(("on_table", obj.name))
        if kb.keeps_upright(obj):
            facts.add(("upright", obj.name) if obj.axis[2] > 0.8 else ("fallen", obj.name))
    if goal is not None:
        for name, key in _destinations(goal):
            if name not in held and _already_at(name, key, objects, scene):
                facts.add(("at", name, key))
    return frozenset(facts)


#: Axis height (cos 45 deg) under which a held upright object counts as tipped in the hand.
HELD_TILTED_Z = 0.707


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
    """Whether a released object already rests at a destination (the tolerances of :func:`fact_constraints`)."""
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
        stages.append(frozenset(wanted))
    if goal.home:
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


def ground(scene: Scene, goal: GoalSpec) -> list[Operator]:
    """Every ground operator the goal could use in this scene."""
    objects = {o.name: o for o in scene.objects}
    arm_of: dict[str, str] = {}
    givers: dict[str, str] = {}
    for g in goal.goals:
        if isinstance(g, Poured) and g.arm:
            arm_of.setdefault(g.source, g.arm)
        if isinstance(g, HandedOver):
            givers[g.obj] = g.giver
    destinations: dict[str, list[tuple[str, str | None]]] = {}
    for g in goal.goals:
        if isinstance(g, (Placed, Inside, On)):
            key = placed_key(g) if isinstance(g, Placed) else (f"in:{g.container}" if isinstance(g, Inside) else f"on:{g.support}")
            destinations.setdefault(g.obj, []).append((key, g.arm))
    ops: list[Operator] = []
    cloths = kb.cloth_names(objects)
    corners = {f"{c}_{k}" for c in cloths for k in kb.CLOTH_CORNERS}
    for name, obj in objects.items():
        if name in corners:
            continue
        if kb.is_wide(obj):
            ops += _two_arm_ops(obj, scene, destinations.get(name, []))
            continue
        for arm in ARMS:
            # A handed-over object is first taken by its giver; a pour names its arm.
            # (A handed-over object that is then poured is poured by its receiver: the giver takes it.)
            may_grasp = givers[name] == arm if name in givers else arm_of.get(name, arm) == arm
            ops += _one_arm_ops(arm, obj, scene, destinations.get(name, []), may_grasp, name in givers)
    for cloth in cloths:
        ops += _fold_ops(cloth, objects)
    for g in goal.goals:
        if isinstance(g, Poured):
            ops += _pour_ops(g)
        if isinstance(g, HandedOver):
            ops += _handover_ops(g)
    levelled = {op.arms[0] for op in ops if op.name.startswith("untilt(")}
    for arm in sorted(set(ARMS) - levelled):
        # An object seen tipped in the hand (a re-plan in the middle of a pour) is levelled first.
        ops.append(
            Operator(
                name=f"untilt({arm})", arms=(arm,), objects=(), pre=frozenset({("tilted", arm)}),
                add=frozenset(), delete=frozenset({("tilted", arm)}), cost=80,
                steps=({arm: _call("rotate_eef", angle=-kb.POUR_TILT)},), semantic="The held object upright again.", skill="pour",
            )
        )
    for arm in ARMS:
        ops.append(
            Operator(
                name=f"back({arm})", arms=(arm,), objects=(), pre=frozenset({("free", arm)}),
                pre_not=frozenset({("home", arm)}), add=frozenset({("home", arm)}), cost=100,
                steps=({arm: _call("back")},), semantic=f"{arm.capitalize()} arm home.", skill="back",
            )
        )
    for obj in objects.values():
        if kb.keeps_upright(obj):
            ops += _set_upright_ops(obj)
    return ops


def _released(arm: str, name: str) -> frozenset[Fact]:
    return frozenset({("holding", arm, name), ("lifted", arm), ("presented", arm, name), ("over", arm, name), ("handover_ready", arm, name), ("pour_ready", arm, "*", "*")})


def _one_arm_ops(
    arm: str, obj: SceneObject, scene: Scene, dests: list[tuple[str, str | None]], may_grasp: bool, handed: bool = False
) -> list[Operator]:
    name = obj.name
    # Prefer the arm on the object's side: the other arm reaches across the table.
    reach = 0 if kb.near_arm(obj) == arm else 400
    ops = [] if not may_grasp else [
        Operator(
            name=f"grasp({arm}, {name})", arms=(arm,), objects=(name,),
            pre=frozenset({("free", arm), ("on_table", name)}),
            add=frozenset({("holding", arm, name)} | ({("upright", name)} if kb.keeps_upright(obj) else set())),
            delete=frozenset({("free", arm), ("home", arm), ("on_table", name), ("at", name, "*"), ("fallen", name), ("pour_ready", "*", "*", name)}),
            cost=190 + reach,
            # The giver of a handover holds the object high: the receiver takes it low.
            steps=({arm: _call("grasp", **_grasp_args(obj), **({"height": kb.HANDOVER_GIVER_HEIGHT} if handed else {}))},),
            semantic=f"{arm.capitalize()} gripper holds the {name}.", skill="grasp",
        )
    ]
    if kb.is_flat(obj):
        ops.append(
            Operator(
                name=f"lift({arm}, {name})", arms=(arm,), objects=(name,), pre=frozenset({("holding", arm, name)}),
                pre_not=frozenset({("lifted", arm)}), add=frozenset({("lifted", arm)}), cost=60,
                steps=({arm: _call("move_by_offset", offset=[0.0, 0.0, kb.FLAT_LIFT])},),
                semantic=f"The {name} lifted clear of the table.", skill="lift",
            )
        )
    for key, wanted_arm in dests:
        if wanted_arm and wanted_arm != arm:
            continue
        args, extra_pre = _place_args(obj, key, scene)
        pre = {("holding", arm, name)} | extra_pre | ({("lifted", arm)} if kb.is_flat(obj) else set())
        ops.append(
            Operator(
                name=f"place({arm}, {name}, {key})", arms=(arm,), objects=(name,),
                pre=frozenset(pre), pre_not=frozenset({("tilted", arm)}),
                add=frozenset({("free", arm), ("on_table", name), ("at", name, key)}),
                delete=_released(arm, name), cost=170 + reach,
                steps=({arm: _call("place", **args)},), semantic=f"The {name} released {_where(key)}.", skill="place",
            )
        )
    return ops


def _grasp_args(obj: SceneObject) -> dict:
    """A one-arm grasp's arguments; a tall object seen fallen is set upright and taken again from
    its side (``reseat``): the nominal hold a pour or an upright place needs, not the fallen-object hold."""
    args = kb.grasp_args(obj)
    if kb.is_tall(obj) and obj.axis[2] <= 0.8 and args.get("mode", "auto") != "top":
        args["reseat"] = True
    return args


def _where(key: str) -> str:
    kind, _, rest = key.partition(":")
    parts = rest.split(":")
    return {
        "spot": "where it was taken from",
        "region": f"in the {parts[0]} region",
        "xy": f"at ({rest.replace(':', ', ')})",
        "rel": f"beside the {parts[0]}",
        "in": f"inside the {parts[0]}",
        "on": f"on top of the {parts[0]}",
        "fold": f"on the {parts[0]}",
    }.get(kind, key)


def _place_args(obj: SceneObject, key: str, scene: Scene) -> tuple[dict, set[Fact]]:
    """Arguments of ``place`` for a destination, and what must hold there."""
    kind, _, rest = key.partition(":")
    parts = rest.split(":")
    objects = {o.name: o for o in scene.objects}
    if kind == "spot":
        return {"obj": obj.name, "target": _r(obj.pos[:2])}, set()
    if kind == "region":
        region = next(r for r in scene.regions if r.name == parts[0])
        return {"obj": obj.name, "target": _r(region.center)}, set()
    if kind == "xy":
        return {"obj": obj.name, "target": [float(parts[0]), float(parts[1])]}, set()
    if kind == "rel":
        args = {"obj": obj.name, "target": [float(parts[1]), float(parts[2])], "relative_to": parts[0]}
        if parts[3]:
            args["yaw"] = float(parts[3])
        return args, {("on_table", parts[0])}
    if kind == "in":
        return {"obj": obj.name, "target": [0.0, 0.0], "relative_to": parts[0], "z_offset": kb.RELEASE_CLEARANCE}, {("on_table", parts[0])}
    if kind == "on":
        height = objects[parts[0]].extent[2]
        return {"obj": obj.name, "target": [0.0, 0.0], "relative_to": parts[0], "z_offset": round(height + kb.RELEASE_CLEARANCE, 4)}, {("on_table", parts[0])}
    raise ValueError(f"unknown destination {key!r}")


def _two_arm_ops(obj: SceneObject, scene: Scene, dests: list[tuple[str, str | None]]) -> list[Operator]:
    name = obj.name
    both = ("left", "right")
    grasp = {
        arm: _call("grasp", obj=name, mode="top", offset=kb.handle_offset(obj, arm), offset_frame="object", lift=0.0) for arm in both
    }
    ops = [
        Operator(
            name=f"grasp_both({name})", arms=both, objects=(name,),
            pre=frozenset({("free", "left"), ("free", "right"), ("on_table", name)}),
            add=frozenset({("holding", "left", name), ("holding", "right", name)}),
            delete=frozenset({("free", a) for a in both} | {("home", a) for a in both} | {("on_table", name), ("at", name, "*")}),
            cost=190, steps=(grasp,), semantic=f"Both grippers hold the {name} by its handles.", skill="grasp",
        ),
        Operator(
            name=f"lift_both({name})", arms=both, objects=(name,),
            pre=frozenset({("holding", "left", name), ("holding", "right", name)}),
            pre_not=frozenset({("lifted", "left")}), add=frozenset({("lifted", "left"), ("lifted", "right")}), cost=60,
            steps=({arm: _call("move_by_offset", offset=[0.0, 0.0, kb.TWO_ARM_LIFT]) for arm in both},),
            semantic=f"The {name} lifted by both arms.", skill="lift",
        ),
    ]
    for key, _ in dests:
        args, extra = _place_args(obj, key, scene)
        ops.append(
            Operator(
                name=f"place_both({name}, {key})", arms=both, objects=(name,),
                pre=frozenset({("holding", "left", name), ("holding", "right", name), ("lifted", "left")} | extra),
                add=frozenset({("free", "left"), ("free", "right"), ("on_table", name), ("at", name, key)}),
                delete=_released("left", name) | _released("right", name), cost=170,
                steps=({arm: _call("place", **args) for arm in both},), semantic=f"The {name} set down {_where(key)}.", skill="place",
            )
        )
    return ops


def _pour_ops(goal: Poured) -> list[Operator]:
    s, c = goal.source, goal.target
    ops = []
    for arm in ARMS:
        if goal.arm and arm != goal.arm:
            continue
        held_by = other(arm)
        for mode, support in (("table", {("on_table", c), ("upright", c)}), ("held", {("presented", held_by, c)})):
            ops.append(
                Operator(
                    name=f"approach_pour({arm}, {s}, {c}, {mode})", arms=(arm,), objects=(s, c),
                    pre=frozenset({("holding", arm, s), ("upright", s)} | support), pre_not=frozenset({("tilted", arm), ("pour_ready", arm, s, c)}),
                    add=frozenset({("pour_ready", arm, s, c)}), cost=110,
                    steps=({arm: _call("move_to_obj", obj=c, offset=list(kb.POUR_OFFSET), yaw=kb.POUR_YAW)},),
                    semantic=f"The {s} held upright beside the {c}, offset for pouring.", skill="approach",
                )
            )
            ops.append(
                Operator(
                    name=f"tilt({arm}, {s}, {c}, {mode})", arms=(arm,), objects=(s, c),
                    pre=frozenset({("pour_ready", arm, s, c)} | support), add=frozenset({("tilted", arm), ("poured", s, c, mode)}),
                    delete=frozenset({("pour_ready", arm, s, c)}), cost=80,
                    steps=({arm: _call("rotate_eef", angle=kb.POUR_TILT)},),
                    semantic=f"The {s} tilted, its mouth above the {c}.", skill="pour",
                )
            )
        ops.append(
            Operator(
                name=f"untilt({arm})", arms=(arm,), objects=(s, c), pre=frozenset({("tilted", arm)}),
                add=frozenset(), delete=frozenset({("tilted", arm)}), cost=80,
                steps=({arm: _call("rotate_eef", angle=-kb.POUR_TILT)},), semantic=f"The {s} upright again.", skill="pour",
            )
        )
    if goal.hold_target:
        for arm in ARMS:
            pos, yaw = kb.RECEIVE_POSE, 0.0 if arm == "left" else 180.0
            ops.append(
                Operator(
                    name=f"present({arm}, {c})", arms=(arm,), objects=(c,), pre=frozenset({("holding", arm, c)}),
                    pre_not=frozenset({("presented", arm, c)}), add=frozenset({("presented", arm, c)}), cost=110,
                    # Poses taken relative to the container are void once it moves.
                    delete=frozenset({("pour_ready", "*", "*", c)}),
                    steps=({arm: _call("move_to_target", pos=list(pos), yaw=yaw)},),
                    semantic=f"The {c} held steady, upright, where it can be poured into.", skill="present",
                )
            )
    return ops


def _handover_ops(goal: HandedOver) -> list[Operator]:
    g, r, o = goal.giver, goal.receiver, goal.obj
    yaw_g, yaw_r = (0.0, 180.0) if g == "left" else (180.0, 0.0)
    retreat = [-kb.HANDOVER_RETREAT if g == "left" else kb.HANDOVER_RETREAT, 0.0, 0.03]
    return [
        Operator(
            name=f"offer({g}, {o})", arms=(g,), objects=(o,), pre=frozenset({("holding", g, o)}),
            pre_not=frozenset({("handover_ready", g, o)}), add=frozenset({("handover_ready", g, o)}), cost=110,
            steps=({g: _call("move_to_target", pos=list(kb.HANDOVER_POSE), yaw=yaw_g)},),
            semantic=f"The {o} held up by the {g} arm at the handover pose.", skill="offer",
        ),
        Operator(
            name=f"handover({g}->{r}, {o})", arms=(g, r), objects=(o,),
            pre=frozenset({("handover_ready", g, o), ("holding", g, o), ("free", r)}),
            add=frozenset({("holding", r, o), ("free", g), ("handed", o, g, r)}),
            delete=_released(g, o) | {("free", r), ("home", r)}, cost=300,
            steps=(
                {r: _call("grasp", obj=o, height=kb.HANDOVER_RECEIVER_HEIGHT, lift=0.0, yaw=yaw_r)},
                {g: _call("open_gripper")},
                {g: _call("move_by_offset", offset=retreat)},
            ),
            semantic=f"The {r} gripper holds the {o}; the {g} gripper released it.", skill="handover",
        ),
    ]


def _fold_ops(cloth: str, objects: dict[str, SceneObject]) -> list[Operator]:
    ops = []
    for near, far, arm in ((f"{cloth}_bl", f"{cloth}_tl", "left"), (f"{cloth}_br", f"{cloth}_tr", "right")):
        key = f"fold:{far}"
        ops += [
            Operator(
                name=f"pinch({arm}, {near})", arms=(arm,), objects=(near,), pre=frozenset({("free", arm), ("on_table", near)}),
                add=frozenset({("holding", arm, near)}), delete=frozenset({("free", arm), ("home", arm), ("on_table", near), ("at", near, "*")}),
                cost=190, steps=({arm: _call("grasp", **kb.grasp_args(objects[near]))},),
                semantic=f"{arm.capitalize()} gripper pinches the {near} corner.", skill="grasp",
            ),
            Operator(
                name=f"fold_lift({arm}, {near})", arms=(arm,), objects=(near,), pre=frozenset({("holding", arm, near)}),
                pre_not=frozenset({("lifted", arm)}), add=frozenset({("lifted", arm)}), cost=110,
                steps=({arm: _call("move_to_obj", obj=far, offset=list(kb.FOLD_LIFT_OFFSET))},),
                semantic=f"The {near} corner lifted off the table.", skill="lift",
            ),
            Operator(
                name=f"fold_over({arm}, {near})", arms=(arm,), objects=(near,), pre=frozenset({("holding", arm, near), ("lifted", arm)}),
                pre_not=frozenset({("over", arm, near)}), add=frozenset({("over", arm, near)}), cost=110,
                steps=({arm: _call("move_to_obj", obj=far, offset=list(kb.FOLD_OVER_OFFSET))},),
                semantic=f"The {near} corner carried over the {far} corner.", skill="carry",
            ),
            Operator(
                name=f"fold_place({arm}, {near})", arms=(arm,), objects=(near,), pre=frozenset({("holding", arm, near), ("over", arm, near)}),
                add=frozenset({("free", arm), ("on_table", near), ("at", near, key)}), delete=_released(arm, near), cost=170,
                steps=({arm: _call("place", obj=near, target=list(kb.FOLD_PLACE_OFFSET), relative_to=far, z_offset=kb.FOLD_RELEASE_HEIGHT)},),
                semantic=f"The {near} corner laid on the {far} corner.", skill="place",
            ),
        ]
    return ops


def _set_upright_ops(obj: SceneObject) -> list[Operator]:
    """Recovery skill: a free arm sets a fallen object upright (the busy arm parks out of its way)."""
    name = obj.name
    ops = []
    for arm in ARMS:
        busy = other(arm)
        steps = ({arm: _call("grasp", obj=name)}, {arm: _call("place", obj=name)}, {arm: _call("back")})
        ops.append(
            Operator(
                name=f"set_upright({arm}, {name})", arms=(arm,), objects=(name,), pre=frozenset({("free", arm), ("fallen", name)}),
                add=frozenset({("upright", name), ("on_table", name), ("home", arm)}), delete=frozenset({("fallen", name)}),
                cost=560 + (0 if kb.near_arm(obj) == arm else 200),
                steps=({busy: _call("move_to_target", pos=list(kb.PARK_POSE[busy][0]), yaw=kb.PARK_POSE[busy][1])}, *steps),
                semantic=f"The {name} set upright by the {arm} arm.", skill="set_upright",
            )
        )
    return ops


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
        return [f"dist({fact[1]}.ee, {_r(kb.RECEIVE_POSE)}) - 0.03", f"tilt({fact[2]}) - 15"]
    if kind == "pour_ready":
        _, arm, s, c = fact
        return [f"dist({arm}.ee, {c}.top + {list(kb.POUR_OFFSET)}) - 0.03", f"tilt({s}) - 15"]
    if kind == "poured":
        _, s, c, _ = fact
        return [f"{kb.POUR_MIN_TILT:g} - tilt({s})", f"norm(xy({s}.top - {c}.top)) - 0.5 * {c}.extent[0] - 0.01"]
    if kind == "handover_ready":
        return [f"dist({fact[1]}.ee, {_r(kb.HANDOVER_POSE)}) - 0.03"]
    if kind == "handed":
        _, o, g, r = fact
        return [f"holding({g}, {o}) - 0.5"]
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
        return released + upright + [f"norm(xy({name}.pos - {_r([*region.center, 0.0])})) - {region.radius:g}"]
    if kind == "xy":
        return released + upright + [f"norm(xy({name}.pos - [{parts[0]}, {parts[1]}, 0.0])) - 0.03"]
    if kind == "rel":
        anchor, dx, dy = parts[0], parts[1], parts[2]
        return released + [f"norm(xy({name}.pos - {anchor}.pos) - [{dx}, {dy}, 0.0]) - 0.03"] + ([f"tilt({name}) - 15"] if obj is not None and kb.is_flat(obj) else upright)
    if kind in ("in", "on"):
        host = objects[parts[0]]
        radius = round(0.5 * min(host.extent[0], host.extent[1]), 4)
        return released + [f"norm(xy({name}.pos - {parts[0]}.pos)) - {radius:g}"]
    return released
