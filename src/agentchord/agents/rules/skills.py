"""Skills as STRIPS operators over the scene: the composer's planning domain.

Each skill is grounded over the scene's arms and objects, filtered by category
(:mod:`~agentchord.agents.rules.knowledge`): a wide object takes both arms, a flat one
is lifted clear before it is carried, a pour needs a vessel and a container. Every
ground operator carries the atomic-action steps of its edge. Operators read and write
the facts of :mod:`~agentchord.agents.rules.facts`.
"""

from __future__ import annotations

from agentchord.agents.scene import Scene, SceneObject, grasp_reach
from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.constraints import rounded
from agentchord.agents.rules.facts import ARMS, placed_key, poured_into
from agentchord.agents.rules.goals import GoalSpec, HandedOver, Inserted, Inside, On, Placed, Poured
from agentchord.agents.rules.planner import Fact, Operator
from agentchord.robot.aloha import other_arm
from agentchord.solvers.reach import table_distance


def _call(fn: str, **args) -> dict:
    return {"fn": fn, "args": args} if args else {"fn": fn}


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
    handed = set(givers)
    held_by = {arm.holding: arm.name for arm in scene.arms if arm.holding}
    for g in goal.goals:
        if isinstance(g, Poured):
            ops += _pour_ops(g)
        if isinstance(g, Inserted) and g.obj in objects and g.into in objects:
            ops += _insert_ops(g, objects[g.obj], objects[g.into])
        if isinstance(g, HandedOver):
            ops += _handover_ops(g, objects.get(g.obj))
        elif isinstance(g, (Placed, Inside, On)) and g.arm and held_by.get(g.obj, g.arm) != g.arm and g.obj not in handed:
            # To be put down by the arm that does not hold it (a re-plan after the other arm took it
            # back): it is handed over first.
            handed.add(g.obj)
            ops += _handover_ops(HandedOver(obj=g.obj, giver=held_by[g.obj], receiver=g.arm), objects.get(g.obj))
    levelled = {op.arms[0] for op in ops if op.name.startswith("untilt(")}
    under = poured_into(scene)
    for arm in sorted(set(ARMS) - levelled):
        # An object seen tipped in the hand (a re-plan in the middle of a pour) is levelled first.
        ops.append(
            Operator(
                name=f"untilt({arm})", arms=(arm,), objects=(), pre=frozenset({("tilted", arm)}),
                add=frozenset(), delete=frozenset({("tilted", arm)} | {("under_pour", c) for c in under.get(arm, [])}), cost=80,
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
    return frozenset({("holding", arm, name), ("lifted", arm), ("presented", arm, name), ("over", arm, name),
                      ("handover_ready", arm, name), ("pour_ready", arm, "*", "*")})


def _one_arm_ops(
    arm: str, obj: SceneObject, scene: Scene, dests: list[tuple[str, str | None]], may_grasp: bool, handed: bool = False
) -> list[Operator]:
    name = obj.name
    # Prefer the arm on the object's side: the other arm reaches across the table.
    reach = 0 if kb.near_arm(obj) == arm else 400
    ops = [] if not may_grasp else [
        Operator(
            name=f"grasp({arm}, {name})", arms=(arm,), objects=(name,),
            # Only where the arm reaches it (``reach`` facts: the scene's ``reachable_by``, then
            # wherever a place or a hand-off on the table left it).
            pre=frozenset({("free", arm), ("on_table", name), ("reach", arm, name)}),
            add=frozenset({("holding", arm, name)} | ({("upright", name)} if kb.keeps_upright(obj) else set())),
            # Taken off the table, it is wherever the hand brings it: reached again once set down.
            delete=frozenset({("free", arm), ("home", arm), ("on_table", name), ("at", name, "*"), ("fallen", name),
                              ("pour_ready", "*", "*", name), ("reach", "*", name)}),
            cost=190 + reach,
            # The giver of a handover holds the object high: the receiver takes it low.
            steps=({arm: _call("grasp", **_grasp_args(obj), **(_giver_hold(obj) if handed else {}))},),
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
        args, extra_pre = _place_args(obj, key, scene)
        point = _place_point(args, scene)
        reachers = set(ARMS) if point is None else {a for a in ARMS if table_distance(a, point) <= grasp_reach(obj.extent)}
        # The arm the goal names places it, where it reaches the place; else the arm that does.
        if wanted_arm and wanted_arm != arm and wanted_arm in reachers:
            continue
        if arm not in reachers:
            continue  # the place is beyond this arm's reach: the other arm's, after a hand-off
        pre = {("holding", arm, name)} | extra_pre | ({("lifted", arm)} if kb.is_flat(obj) else set())
        # The object placed into or onto (not beside): two placements there are one after the other, in the
        # goal's order, not both arms reaching into the same cup at once.
        anchor = args.get("relative_to")
        target = args.get("target") or (1.0, 1.0)
        into = isinstance(anchor, str) and max(abs(float(t)) for t in target[:2]) < INTO_RADIUS
        ops.append(
            Operator(
                name=f"place({arm}, {name}, {key})", arms=(arm,), objects=(name, anchor) if into else (name,),
                # A container is not moved from under a vessel still tilted over it.
                pre=frozenset(pre), pre_not=frozenset({("tilted", arm), ("under_pour", name)}),
                add=frozenset({("free", arm), ("on_table", name), ("at", name, key)} | {("reach", a, name) for a in reachers}),
                delete=_released(arm, name) | {("reach", a, name) for a in set(ARMS) - reachers}, cost=170 + reach,
                steps=({arm: _call("place", **args)},), semantic=f"The {name} released {_where(key)}.", skill="place",
                spot=point,
            )
        )
    if may_grasp or handed:
        ops.append(_handoff_op(arm, obj))
    return ops


#: Offset (m) from an anchor within which a placement is into or onto it (beside one is farther).
INTO_RADIUS = 0.06
#: Cost (ticks) of setting an object down for the other arm, on top of the places it saves.
HANDOFF_COST = 260


def _handoff_op(arm: str, obj: SceneObject) -> Operator:
    """``arm`` sets ``obj`` down on a free spot both arms reach (chosen when it runs), for the other arm:
    how an object on one side of the table reaches a place or an arm on the other."""
    name, other = obj.name, other_arm(arm)
    pre = {("holding", arm, name)} | ({("lifted", arm)} if kb.is_flat(obj) else set())
    return Operator(
        name=f"handoff({arm}, {name})", arms=(arm,), objects=(name,),
        pre=frozenset(pre), pre_not=frozenset({("tilted", arm), ("reach", other, name)}),
        add=frozenset({("free", arm), ("on_table", name), ("reach", arm, name), ("reach", other, name)}),
        delete=_released(arm, name) | {("at", name, "*")}, cost=HANDOFF_COST,
        steps=({arm: _call("place", obj=name, within_reach=other)}, {arm: _call("back")}),
        semantic=f"The {name} set down where the {other} arm reaches it.", skill="place",
    )


def _place_point(args: dict, scene: Scene) -> tuple[float, float] | None:
    """The table point a place's arguments name (from the anchor's observed place when relative)."""
    target = args.get("target")
    if target is None:
        return None
    anchor = args.get("relative_to")
    if anchor is None:
        return float(target[0]), float(target[1])
    found = next((o for o in scene.objects if o.name == anchor), None)
    return None if found is None else (found.pos[0] + float(target[0]), found.pos[1] + float(target[1]))


def _giver_hold(obj: SceneObject) -> dict:
    """How the giver of a hand-over holds the object: a bar high on its side (the receiver takes it low);
    a small object from above by its upper half (the receiver takes it under the giver's fingertips)."""
    if _grasp_args(obj).get("mode") == "top" and max(obj.extent) <= kb.SMALL_HANDOFF:
        return {"offset": [0.0, 0.0, kb.HANDOFF_GIVER_RAISE]}
    return {"height": kb.HANDOVER_GIVER_HEIGHT}


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
        return {"obj": obj.name, "target": rounded(obj.pos[:2])}, set()
    if kind == "region":
        region = next(r for r in scene.regions if r.name == parts[0])
        return {"obj": obj.name, "target": rounded(region.center)}, set()
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
        held_by = other_arm(arm)
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
                    pre=frozenset({("pour_ready", arm, s, c)} | support), add=frozenset({("tilted", arm), ("poured", s, c, mode), ("under_pour", c)}),
                    delete=frozenset({("pour_ready", arm, s, c)}), cost=80,
                    steps=({arm: _call("rotate_eef", angle=kb.POUR_TILT)},),
                    semantic=f"The {s} tilted, its mouth above the {c}.", skill="pour",
                )
            )
        ops.append(
            Operator(
                name=f"untilt({arm})", arms=(arm,), objects=(s, c), pre=frozenset({("tilted", arm)}),
                add=frozenset(), delete=frozenset({("tilted", arm), ("under_pour", c)}), cost=80,
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


def _handover_ops(goal: HandedOver, obj: SceneObject | None) -> list[Operator]:
    g, r, o = goal.giver, goal.receiver, goal.obj
    yaw_g, yaw_r = (0.0, 180.0) if g == "left" else (180.0, 0.0)
    retreat = [-kb.HANDOVER_RETREAT if g == "left" else kb.HANDOVER_RETREAT, 0.0, 0.03]
    high = {**(_grasp_args(obj) if obj is not None else {"obj": o}), "height": kb.HANDOVER_GIVER_HEIGHT}
    if obj is not None and "offset" in _giver_hold(obj):
        # A small object held from above: offered where it is held (the hand keeps its orientation),
        # taken under the giver's fingertips (the grasp's hand-off), the giver then lets go.
        offer = {g: _call("move_to_target", pos=[-kb.HANDOFF_POSE[0] if g == "left" else kb.HANDOFF_POSE[0], *kb.HANDOFF_POSE[1:]])}
        take = ({r: _call("grasp", obj=o, lift=0.0)}, {g: _call("open_gripper")}, {g: _call("back")})
    else:
        offer = {g: _call("move_to_target", pos=list(kb.HANDOVER_POSE), yaw=yaw_g)}
        take = (
            {r: _call("grasp", obj=o, height=kb.HANDOVER_RECEIVER_HEIGHT, lift=0.0, yaw=yaw_r)},
            {g: _call("open_gripper")},
            {g: _call("move_by_offset", offset=retreat)},
        )
    return [
        Operator(
            # Held low (a fallen bar taken by its middle, seen in a re-plan): set it down standing, take it high.
            name=f"regrip({g}, {o})", arms=(g,), objects=(o,), pre=frozenset({("holding", g, o), ("grip_low", g)}),
            add=frozenset(), delete=frozenset({("grip_low", g)}), cost=360,
            steps=({g: _call("place", obj=o)}, {g: _call("grasp", **high)}),
            semantic=f"The {o} held high by the {g} arm.", skill="regrip",
        ),
        Operator(
            name=f"offer({g}, {o})", arms=(g,), objects=(o,), pre=frozenset({("holding", g, o)}),
            pre_not=frozenset({("handover_ready", g, o), ("grip_low", g)}), add=frozenset({("handover_ready", g, o)}), cost=110,
            steps=(offer,),
            semantic=f"The {o} held up by the {g} arm at the handover pose.", skill="offer",
        ),
        Operator(
            name=f"handover({g}->{r}, {o})", arms=(g, r), objects=(o,),
            pre=frozenset({("handover_ready", g, o), ("holding", g, o), ("free", r)}),
            add=frozenset({("holding", r, o), ("free", g), ("handed", o, g, r)}),
            delete=_released(g, o) | {("free", r), ("home", r)}, cost=300,
            steps=take,
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
        busy = other_arm(arm)
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


def _insert_ops(goal: Inserted, obj: SceneObject, host: SceneObject) -> list[Operator]:
    """Insertion in mid-air: each arm takes one of the pair from above near its far end (the peg's tip and
    the socket's opening stay free), both present them facing each other, the peg's arm inserts."""
    arm = goal.arm or ("right" if obj.pos[0] >= host.pos[0] else "left")
    other = other_arm(arm)
    name, into = obj.name, host.name
    grasps = {arm: _call("grasp", obj=name, mode="top", offset_frame="object", offset=_far_end(obj, host)),
              other: _call("grasp", obj=into, mode="top", offset_frame="object", offset=_far_end(host, obj))}
    side = 1.0 if arm == "right" else -1.0
    present = {arm: _call("move_to_target", pos=[side * kb.INSERT_PRESENT[0], kb.INSERT_PRESENT[1], kb.INSERT_PRESENT[2]]),
               other: _call("move_to_target", pos=[-side * kb.INSERT_HOLD[0], kb.INSERT_HOLD[1], kb.INSERT_HOLD[2]])}
    holds = frozenset({("holding", arm, name), ("holding", other, into)})
    return [
        Operator(
            name=f"grasp_pair({arm}, {name}, {other}, {into})", arms=(arm, other), objects=(name, into),
            pre=frozenset({("free", arm), ("free", other), ("on_table", name), ("on_table", into), ("reach", arm, name), ("reach", other, into)}),
            add=holds, delete=frozenset({("free", arm), ("free", other), ("home", arm), ("home", other), ("on_table", name), ("on_table", into)}),
            cost=200, steps=(grasps,), semantic=f"{arm.capitalize()} gripper holds the {name}, {other} the {into}.", skill="grasp",
        ),
        Operator(
            name=f"present({name}, {into})", arms=(arm, other), objects=(name, into), pre=holds,
            pre_not=frozenset({("mated", name, into)}), add=frozenset({("mated", name, into)}), cost=110,
            steps=(present,), semantic=f"The {name} and the {into} held up facing each other.", skill="move",
        ),
        Operator(
            name=f"insert({arm}, {name}, {into})", arms=(arm,), objects=(name, into), pre=holds | {("mated", name, into)},
            add=frozenset({("inserted", name, into)}), cost=120,
            steps=({arm: _call("insert", obj=name, into=into)},), semantic=f"The {name} inside the {into}.", skill="insert",
        ),
    ]


def _far_end(obj: SceneObject, other: SceneObject) -> list[float]:
    """Object-frame offset of a top grasp near the end of ``obj``'s long axis away from ``other``."""
    w, x, y, z = obj.quat
    yaw_axis = [1 - 2 * (y * y + z * z), 2 * (x * y + w * z)]  # the object's x axis, in the table plane
    along = yaw_axis[0] * (other.pos[0] - obj.pos[0]) + yaw_axis[1] * (other.pos[1] - obj.pos[1])
    return [-kb.INSERT_GRIP_OFFSET if along > 0 else kb.INSERT_GRIP_OFFSET, 0.0, 0.0]
