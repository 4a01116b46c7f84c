"""Where a clause puts things: beside an object or a region, in a row, at a named place, or back where they were.

The placing half of :mod:`agentchord.agents.rules.instructions`: given the objects a clause moves and the place
its grammar read (a :class:`~agentchord.agents.rules.language.Where`), the goal each object ends in, with the
arm that holds it (:class:`~agentchord.agents.rules.references.Context` keeps who holds what).
"""

from __future__ import annotations

from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.goals import Goal, Inside, On, Placed
from agentchord.agents.rules.language import Clause, NounPhrase, Where
from agentchord.agents.rules.references import MARK_WORDS, Context


def _beside(obj: str, anchor: str, direction: tuple[float, float], ctx: Context, arm: str | None) -> Placed:
    if direction[0]:
        ctx.sides[anchor] = "left" if direction[0] < 0 else "right"  # "..., the spoon to the other side of the plate"
    o, a = ctx.objects[obj], ctx.objects[anchor]
    d = kb.beside_distance(o, a)
    long_flat = kb.is_flat(o) and max(o.extent[:2]) > 3 * min(o.extent[:2])
    return Placed(obj=obj, relative_to=anchor, offset=(round(direction[0] * d, 4), round(direction[1] * d, 4)),
                  yaw=90.0 if long_flat and kb.is_flat(a) else None, arm=arm)


def _relation(where: Where | None, ctx: Context) -> Where | None:
    """``at`` a phrase like ``the left of the plate``, ``the front of the cup``, ``the top of it``: the relation it states."""
    if where is None or where.relation != "at":
        return where
    np = where.phrases[0]
    if np.of is None or not np.words or ctx.table_place(np) is not False:
        return where
    last = np.words[-1]
    if last in ("left", "right"):
        return Where("side_of", (np.of,), side=last)
    if last == "front":
        return Where("front_of", (np.of,))
    if last in ("back", "rear"):
        return Where("behind", (np.of,))
    if last == "top":
        return Where("on_top", (np.of,))
    if last in ("side", "edge") and len(np.words) > 1 and np.words[-2] in ("left", "right"):
        return Where("side_of", (np.of,), side=np.words[-2])
    if np.words in (("other", "side"), ("opposite", "side")):
        # "the other side of the plate": the side an object was just put beside it is not this one.
        anchor = ctx.resolve(np.of)
        if anchor not in ctx.sides:
            raise ctx.error(np.text, "says the other side, but nothing was put on one side of it before")
        return Where("side_of", (np.of,), side="right" if ctx.sides[anchor] == "left" else "left")
    return where


def place_at(names: list[str], where: Where | None, c: Clause, ctx: Context) -> list[Goal]:
    where = _relation(where, ctx)
    # "... the fork to the left of the plate and the spoon on the right": a bare side after an anchor is the anchor's side.
    if where is not None and where.relation == "at" and ctx.last_anchor and where.phrases[0].of is None \
            and where.phrases[0].words in (("left",), ("right",), ("left", "side"), ("right", "side")):
        where = Where("side_of", (NounPhrase(words=tuple(ctx.last_anchor.split("_"))),), side=where.phrases[0].words[0])
    arms = {n: ctx.arm_of(c.arm, n) for n in names}
    if where is None or where.relation == "back":
        return _put_back(names, arms, ctx)
    if where.relation in ("next_to", "side_of", "front_of", "behind"):
        anchor_np = where.phrases[0]
        if where.relation == "side_of" and ctx.table_place(anchor_np) is not False:
            point = kb.table_point([where.side])
            return [Placed(obj=n, at=point, arm=arms[n]) for n in names]
        if (beside := _beside_region(names, anchor_np, where, ctx)) is not None:
            return [Placed(obj=n, at=point, arm=arms[n]) for n, point in beside]
        anchor = ctx.resolve(anchor_np, exclude=tuple(names))
        anchor = ctx.inside.get(anchor, anchor)
        ctx.last_anchor = anchor
        if where.relation == "side_of" and len(names) == 2:
            return _row(names, anchor, where.side, ctx, arms)
        if where.relation == "side_of":
            directions = [kb.DIRECTION_WORDS[where.side]] * len(names)
        elif where.relation == "front_of":
            directions = [(0.0, -1.0)] * len(names)
        elif where.relation == "behind":
            directions = [(0.0, 1.0)] * len(names)
        elif len(names) == 2:
            # Table setting: each on its own side of the anchor where they lie on opposite sides, else the first named on the left.
            sides = [-1.0 if ctx.objects[n].pos[0] < ctx.objects[anchor].pos[0] else 1.0 for n in names]
            directions = [(sides[0], 0.0), (sides[1], 0.0)] if sides[0] != sides[1] else [(-1.0, 0.0), (1.0, 0.0)]
        else:
            side = -1.0 if ctx.objects[names[0]].pos[0] < ctx.objects[anchor].pos[0] else 1.0
            directions = [(side, 0.0)] * len(names)
        if len(names) > 2 or len(set(directions)) < len(names):
            raise ctx.error(c.text, f"puts {len(names)} objects at one place beside the {anchor}")
        return [_beside(n, anchor, d, ctx, arms[n]) for n, d in zip(names, directions, strict=True)]
    if where.relation == "spot_of":
        other = ctx.objects[ctx.resolve(where.phrases[0], exclude=tuple(names))]
        return [Placed(obj=n, at=(round(other.pos[0], 3), round(other.pos[1], 3)), arm=arms[n]) for n in names]
    if where.relation == "between":
        a, b = (ctx.objects[ctx.resolve(p, exclude=tuple(names))] for p in where.phrases)
        point = (round(0.5 * (a.pos[0] + b.pos[0]), 3), round(0.5 * (a.pos[1] + b.pos[1]), 3))
        return [Placed(obj=n, at=point, arm=arms[n]) for n in names]
    np = where.phrases[0]
    if where.relation == "on_top":
        if np.of is not None and np.words and np.words[-1] == "top":
            np = np.of
        support = ctx.resolve(np, exclude=tuple(names))
        return [On(obj=n, support=support, arm=arms[n]) for n in names]
    named = ctx.region(np) if set(np.words) & {"region", "area", "zone", "spot", "position", *MARK_WORDS} else None
    if named is not None:  # "the forward position": the scene's region of that name, not a part of the table
        return [Placed(obj=n, region=named, arm=arms[n]) for n in names]
    table = ctx.table_place(np)
    if table is None:
        return _put_back(names, arms, ctx)
    if table is not False:
        return [Placed(obj=n, at=table, arm=arms[n]) for n in names]
    region = ctx.region(np)
    if region is not None:
        return [Placed(obj=n, region=region, arm=arms[n]) for n in names]
    if set(np.words) & {"region", "area", "zone"}:
        regions = ", ".join(r.name for r in ctx.scene.regions) or "none"
        raise ctx.error(np.text, f"names no region of the scene (regions: {regions}; or a part of the table: its left side, front right corner, centre)")
    host = ctx.resolve(np, exclude=tuple(names))
    if where.prep == "in" or (where.prep == "at" and kb.is_container(ctx.objects[host])) \
            or (where.prep == "on" and kb.is_container(ctx.objects[host]) and not kb.is_flat(ctx.objects[host])):
        ctx.inside.update(dict.fromkeys(names, host))
        return [Inside(obj=n, container=host, arm=arms[n]) for n in names]
    if where.prep == "on":
        return [On(obj=n, support=host, arm=arms[n]) for n in names]
    return [_beside(n, host, (-1.0 if ctx.objects[n].pos[0] < ctx.objects[host].pos[0] else 1.0, 0.0), ctx, arms[n]) for n in names]


def _row(names: list[str], anchor: str, side: str, ctx: Context, arms: dict[str, str | None]) -> list[Goal]:
    """Two objects to one side of an anchor ("the two blocks side by side on the left of the cup"): a row on that
    side, keeping their present left-to-right order: the one nearer that side of the anchor beside it, the other beside that one."""
    sign = kb.DIRECTION_WORDS[side][0]
    near, far = sorted(names, key=lambda n: sign * ctx.objects[n].pos[0])
    first = _beside(near, anchor, (sign, 0.0), ctx, arms[near])
    return [first, _beside(far, near, (sign, 0.0), ctx, arms[far])]


def _beside_region(names: list[str], np: NounPhrase, where: Where, ctx: Context) -> list[tuple[str, tuple[float, float]]] | None:
    """Beside a scene region (``next to the target, not on it``): a point just outside it, on the side said or else
    the side the object is on (the region's radius, the object's half-size and a 4 cm gap); None where ``np`` names
    an object, or no region."""
    if any(w in kb.words(o) for o in ctx.scene.objects for w in np.words) or (region := ctx.region(np)) is None:
        return None
    if where.relation not in ("next_to", "side_of", "front_of", "behind"):
        return None
    area = next(r for r in ctx.scene.regions if r.name == region)
    out = []
    for n in names:
        o = ctx.objects[n]
        d = area.radius + 0.5 * max(o.extent[:2]) + kb.NEXT_TO_GAP
        if where.relation == "next_to":
            ux, uy = (-1.0 if o.pos[0] < area.center[0] else 1.0, 0.0)
        else:
            ux, uy = kb.DIRECTION_WORDS[where.side] if where.relation == "side_of" else (0.0, -1.0 if where.relation == "front_of" else 1.0)
        out.append((n, (round(area.center[0] + ux * d, 3), round(area.center[1] + uy * d, 3))))
    return out


def _put_back(names: list[str], arms: dict[str, str | None], ctx: Context) -> list[Goal]:
    """Each object put back where it was; one never taken, moved or placed is there already ("cup and bottle both on
    the table" after a pour from the bottle: the bottle is put back, the cup never left)."""
    back = [n for n in names if n in ctx.touched] if ctx.touched else names
    return [Placed(obj=n, arm=arms[n]) for n in back]


#: A place said only as a spot ("forward to the spot"): the words it may have.
SPOT_WORDS = frozenset({"spot", "region", "position", "area", "place", "zone", "mark", "forward"})


def direction_region(direction: str, ctx: Context) -> str | None:
    """The scene region a direction names (``forward`` in the coffee scene), if any."""
    return next((r.name for r in ctx.scene.regions if direction == r.name.lower() or direction in r.description.lower().split()), None)
