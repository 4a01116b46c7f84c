"""A plan's reach check: every nominal grasp and place within the reach of the arm that makes it.

A plan that sends an arm to an object beyond its reach fails on the robot, slowly (the approach
sweeps what lies in its way, the grasp closes on nothing); caught here, it is refused before the
robot moves, with what would do instead. The check follows the nominal path in order and keeps
track of where each object is on the table: where the scene saw it, until a ``place`` sets it down
somewhere else, and unknown while a hand holds it (a hand-over in the air is not checked: the
object is where the giver brought it). Each ``grasp`` of an object whose place is known, and each
``place`` at a place the plan states (absolute, or beside an object whose place is known), is
measured against the arm's measured reach (:mod:`agentchord.solvers.reach`): a top grasp or a
place from above within ``TOP_REACH`` of the arm's base, a side grasp within ``SIDE_REACH``.

The composer's and the conductor's replies are checked (``agents.checks``), and ``graph check
--task`` checks a graph file on the task's scene.
"""

from __future__ import annotations

import math
from typing import Any

from agentchord.agents.scene import SIDE_GRASP_HEIGHT, Scene, SceneObject
from agentchord.graph.exceptions import GraphError
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import nominal_path
from agentchord.graph.validation import Problem
from agentchord.solvers.reach import BASE, SIDE_REACH, TOP_REACH, table_distance

#: How far (m) past its measured reach an arm is still let try (the measured reach keeps 2 cm in hand).
REACH_SLACK = 0.01
#: A spot both arms reach from above, for the hand-over the message suggests: mid-table, in front of the bases.
HANDOFF_SPOT = (0.0, 0.5)


def reach_problems(graph: TaskGraph, scene: Scene) -> list[Problem]:
    """Every nominal grasp or place of ``graph`` beyond the reach of its arm, in ``scene``.

    Args:
        graph: The plan (its nominal path is followed; recovery edges start wherever the robot is).
        scene: The observation it was planned on (object poses, the arms).

    Returns:
        One problem per action out of reach, at ``edges[i].actions``; empty when every one is within reach.
    """
    try:
        path = nominal_path(graph)
    except GraphError:
        return []  # an unsound graph: check_graph reports why
    objects = {obj.name: obj for obj in scene.objects}
    where: dict[str, tuple[float, float] | None] = {name: (obj.pos[0], obj.pos[1]) for name, obj in objects.items()}
    reach_of: dict[str, float] = {}
    index = {edge.id: i for i, edge in enumerate(graph.edges)}
    problems: list[Problem] = []
    for edge_id in path:
        edge = graph.edge(edge_id)
        for arm, call in edge.calls:
            if arm not in BASE:
                continue
            args = call.args
            obj = args.get("obj")
            if call.fn == "grasp" and isinstance(obj, str) and obj in objects:
                reach = _grasp_reach(args, objects[obj])
                reach_of[obj] = reach
                spot = where.get(obj)
                if spot is not None:
                    point = _offset_point(spot, args, objects[obj])
                    problems += _beyond(edge_id, index[edge_id], arm, f"grasp of {obj} where it lies", point, reach)
                where[obj] = None
            elif call.fn == "place" and isinstance(obj, str) and obj in objects:
                placed = _place_point(args, where)
                if placed is not None:
                    reach = reach_of.get(obj, TOP_REACH)
                    problems += _beyond(edge_id, index[edge_id], arm, f"place of {obj}", placed, reach)
                where[obj] = placed
            elif call.fn in ("move_to_obj", "move_by_offset", "move_to_target", "rotate_eef") and isinstance(obj, str):
                where[obj] = None
    return problems


def _grasp_reach(args: dict[str, Any], obj: SceneObject) -> float:
    mode = args.get("mode", "auto")
    if mode == "side":
        return SIDE_REACH
    if mode == "top":
        return TOP_REACH
    return SIDE_REACH if obj.extent[2] >= SIDE_GRASP_HEIGHT else TOP_REACH


def _offset_point(spot: tuple[float, float], args: dict[str, Any], obj: SceneObject) -> tuple[float, float]:
    """Where on the table the grasp takes the object: its centre moved by the grasp's offset."""
    offset = args.get("offset") or (0.0, 0.0, 0.0)
    try:
        dx, dy = float(offset[0]), float(offset[1])
    except (TypeError, ValueError, IndexError):
        return spot
    if args.get("offset_frame") == "object":
        w, x, y, z = obj.quat
        yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        dx, dy = dx * math.cos(yaw) - dy * math.sin(yaw), dx * math.sin(yaw) + dy * math.cos(yaw)
    return spot[0] + dx, spot[1] + dy


def _place_point(args: dict[str, Any], where: dict[str, tuple[float, float] | None]) -> tuple[float, float] | None:
    """The table point a place states (absolute, or from an anchor whose place is known); None if it states none."""
    target = args.get("target")
    if args.get("within_reach") or target is None:
        return None
    try:
        tx, ty = float(target[0]), float(target[1])
    except (TypeError, ValueError, IndexError):
        return None
    anchor = args.get("relative_to")
    if anchor is None:
        return tx, ty
    spot = where.get(anchor)
    return None if spot is None else (spot[0] + tx, spot[1] + ty)


def _beyond(edge_id: str, i: int, arm: str, what: str, point: tuple[float, float], reach: float) -> list[Problem]:
    distance = table_distance(arm, point)
    if distance <= reach + REACH_SLACK:
        return []
    kind = "from above" if reach == TOP_REACH else "with a side grasp"
    bx, by = BASE[arm]
    others = [other for other in BASE if other != arm and table_distance(other, point) <= reach]
    advice = [f"use the {other} arm (it reaches it: {table_distance(other, point):.2f} m from its base)" for other in others]
    hx, hy = HANDOFF_SPOT
    advice.append(
        f"or a hand-over: the arm that reaches it sets it down mid-table (e.g. `place` with `\"target\": [{hx}, {hy}]`), "
        f"then the {arm} arm takes it there"
    )
    return [Problem(
        f"edges[{i}].actions",
        f"edge {edge_id!r}: the {arm} arm's {what} at ({point[0]:.2f}, {point[1]:.2f}) is {distance:.2f} m from its base "
        f"({bx:.3f}, {by:.3f}), {distance - reach:.2f} m beyond its reach {kind} ({reach:.2f} m): {'; '.join(advice)}",
    )]
