"""Whether a goal spec makes physical sense in a scene, before any planning.

The STRIPS planner reasons over symbols: it would happily plan "put the cup into the red
block" or "put the tray into the capsule". These checks refuse such goals with the reason:
the receiving object is not a container, or the object does not fit through its opening; an
object set on top of an open container it would fall into; a stack or a containment that
closes a cycle (also refused by the goal spec itself); a goal naming an object the scene
does not have.
"""

from __future__ import annotations

from pydantic import ValidationError

from agentchord.agents.rules import knowledge as kb
from agentchord.agents.rules.goals import GoalSpec, Inside, On, Placed, Poured, static_problems
from agentchord.agents.scene import Scene, SceneObject, arms_reaching, grasp_reach
from agentchord.solvers.reach import BASE, table_distance
from agentchord.graph.models import TaskGraph
from agentchord.graph.validation import Problem

#: Fraction of the container's smaller horizontal size an object's smaller horizontal size may fill: what its
#: walls leave of the outer size seen (a 5 cm cup with 5 mm walls opens 4 cm; a 4.9 cm bottle does not go in).
FIT_FRACTION = 0.8


def goal_problems(goal: GoalSpec, scene: Scene) -> list[str]:
    """Every reason ``goal`` cannot be achieved in ``scene``; empty when it is sound.

    Args:
        goal: The goal spec (from a file or read from an instruction).
        scene: The first observation.
    """
    objects = {obj.name: obj for obj in scene.objects}
    cloth = set(kb.cloth_names(objects))
    problems = list(static_problems(goal))
    for index, item in enumerate(goal.goals):
        where = f"goals[{index}]"
        missing = [n for n in item.objects() if n not in objects and n.rsplit("_", 1)[0] not in cloth]
        if missing and objects:
            problems.append(f"{where}: the scene has no {', '.join(map(repr, missing))} (it has {', '.join(objects)})")
            continue
        if isinstance(item, Inside) and item.obj in objects and item.container in objects:
            problems += _fit(where, objects[item.obj], objects[item.container], "put into")
        elif isinstance(item, On) and item.obj in objects and item.support in objects:
            problems += _falls_in(where, objects[item.obj], objects[item.support])
        elif isinstance(item, Poured) and item.source in objects and item.target in objects:
            if not kb.is_pourable(objects[item.source]):
                problems.append(f"{where}: {item.source!r} is not a vessel to pour from")
            if not kb.is_container(objects[item.target]):
                problems.append(f"{where}: {item.target!r} is not a container: nothing can be poured into it")
        elif isinstance(item, Placed) and item.at is not None and item.obj in objects:
            problems += _beyond_reach(where, objects[item.obj], (float(item.at[0]), float(item.at[1])))
        elif isinstance(item, Placed) and item.region is not None:
            regions = [r.name for r in scene.regions]
            if item.region not in regions:
                known = ", ".join(regions) or "none"
                problems.append(f"{where}: the scene has no region {item.region!r} (regions: {known})")
    return problems


def _fit(where: str, obj: SceneObject, container: SceneObject, verb: str) -> list[str]:
    if not kb.is_container(container):
        return [f"{where}: {container.name!r} is not a container: nothing can be {verb} it"]
    inner = min(container.extent[0], container.extent[1]) * FIT_FRACTION
    size = min(obj.extent[0], obj.extent[1])
    if size >= inner:
        return [
            f"{where}: {obj.name!r} ({size * 100:.1f} cm across) does not fit into {container.name!r} "
            f"({inner * 100:.1f} cm inside)"
        ]
    return []


def _beyond_reach(where: str, obj: SceneObject, point: tuple[float, float]) -> list[str]:
    """A table point no arm reaches to set ``obj`` down (the measured reach of each arm from its base)."""
    if arms_reaching(point, obj.extent):
        return []
    limit = grasp_reach(obj.extent)
    far = ", ".join(f"{arm} {table_distance(arm, point):.2f} m" for arm in BASE)
    return [f"{where}: ({point[0]:.2f}, {point[1]:.2f}) m is beyond both arms' reach for {obj.name!r}: each reaches "
            f"{limit:.2f} m from its base, and the point is {far} away"]


def _falls_in(where: str, obj: SceneObject, support: SceneObject) -> list[str]:
    """An object set on top of an open container it fits into falls in: it cannot rest on the rim."""
    if not kb.is_container(support) or _fit(where, obj, support, "put into"):
        return []
    size = min(obj.extent[0], obj.extent[1])
    inner = min(support.extent[0], support.extent[1]) * FIT_FRACTION
    return [
        f"{where}: {obj.name!r} ({size * 100:.1f} cm across) fits through the opening of {support.name!r} "
        f"({inner * 100:.1f} cm inside): set on top of it, it falls in (to put it in: kind inside, "
        f"container {support.name})"
    ]


def stated_goal(graph: TaskGraph) -> GoalSpec | None:
    """The goal a composer stated in ``success.goal_spec`` (None when it stated none, or an invalid one)."""
    if not graph.success.goal_spec:
        return None
    try:
        return GoalSpec.model_validate(graph.success.goal_spec)
    except ValidationError:
        return None


def spec_problems(error: ValidationError, where: str = "success.goal_spec") -> list[Problem]:
    """A goal spec's validation errors, one problem each, at its path (``success.goal_spec.goals[0].kind``)."""
    return [
        Problem(where + "".join(f"[{part}]" if isinstance(part, int) else f".{part}" for part in detail["loc"]),
                detail["msg"].removeprefix("Value error, "))
        for detail in error.errors()
    ]


def stated_goal_problems(graph: TaskGraph, scene: Scene) -> list[Problem]:
    """What is wrong with the goal the composer states: missing, not a goal spec, or not in this scene.

    The goal spec is what the episode is judged by when the instruction is not the task's own
    (``agentchord schema goal``): its objects must be the scene's, its regions the scene's, and
    it must be possible in the scene (nothing put into a block, ...).
    """
    where = "success.goal_spec"
    if not graph.success.goal_spec:
        return [Problem(where, "state the goal: what must hold at the end, as a goal spec ({\"goals\": [...], \"home\": true})")]
    try:
        goal = GoalSpec.model_validate(graph.success.goal_spec)
    except ValidationError as error:
        return spec_problems(error, where)
    problems = []
    for line in goal_problems(goal, scene):  # "goals[1]: what is wrong"
        head, _, rest = line.partition(": ")
        problems.append(Problem(f"{where}.{head}", rest) if head.startswith("goals[") and rest else Problem(where, line))
    return problems
