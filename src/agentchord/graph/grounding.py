"""Whether a graph can run in a scene: ``graph check``, then its objects against the scene's.

A graph that passes ``graph check`` can still name objects the chosen scene lacks (a
graph written for another task); its first expression would then fail mid-episode.
:func:`require_runnable` is called before every execution, so that such a graph is
refused, with every problem, before the first tick.
"""

from __future__ import annotations

from collections.abc import Iterable

from agentchord.graph.exceptions import GraphNotRunnableError
from agentchord.graph.models import TaskGraph
from agentchord.graph.validation import Problem, check_graph


def check_scene(graph: TaskGraph, scene_objects: Iterable[str], scene: str = "the") -> list[Problem]:
    """Every graph object that the scene does not have.

    Args:
        graph: The graph.
        scene_objects: Names the scene's feature frame will hold (objects, cloth points).
        scene: How to name the scene in messages (a task name).
    """
    names = list(scene_objects)
    known = set(names)
    listed = ", ".join(names) or "no objects"
    problems = [
        Problem(f"objects[{i}]", f"the {scene} scene has no object {name!r} (it has {listed})")
        for i, name in enumerate(graph.objects)
        if name not in known
    ]
    # The goal the graph is judged by names objects too (a cloth by its name: its points are ``towel_bl`` ...).
    goals = (graph.success.goal_spec or {}).get("goals")
    for i, goal in enumerate(goals if isinstance(goals, list) else []):
        for key, name in (goal.items() if isinstance(goal, dict) else ()):
            if key in GOAL_OBJECT_FIELDS and isinstance(name, str) and name not in known and not any(n.startswith(f"{name}_") for n in known):
                problems.append(Problem(f"success.goal_spec.goals[{i}].{key}", f"the {scene} scene has no object {name!r} (it has {listed})"))
    return problems


#: Fields of a goal spec's goals that name a scene object.
GOAL_OBJECT_FIELDS = frozenset({"obj", "container", "support", "source", "target", "relative_to", "into", "cloth"})


def require_runnable(graph: TaskGraph, scene_objects: Iterable[str], scene: str = "the", source: str = "graph") -> None:
    """Refuse a graph that fails ``graph check`` or names objects the scene lacks.

    Args:
        graph: The graph about to run.
        scene_objects: Names the scene's feature frame will hold.
        scene: How to name the scene in messages.
        source: Where the graph came from (its file), to prefix each problem.

    Raises:
        GraphNotRunnableError: Every problem, one ``SOURCE: path: message`` line each.
    """
    problems = check_graph(graph) + check_scene(graph, scene_objects, scene)
    if problems:
        raise GraphNotRunnableError(source, [str(problem) for problem in problems])
