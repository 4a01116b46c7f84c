"""The task library: hand-written recovery-augmented graphs shipped with the package."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from agentchord.graph.loader import load_graph
from agentchord.graph.models import TaskGraph


def library_path(task: str) -> Path:
    """Path of a task's library graph.

    Raises:
        KeyError: No graph for that task in the library.
    """
    path = Path(str(resources.files("agentchord.library") / "graphs" / f"{task}.yaml"))
    if not path.is_file():
        raise KeyError(f"no library graph for task {task!r} (have: {', '.join(library_tasks())})")
    return path


def library_tasks() -> list[str]:
    """Names of the tasks with a library graph."""
    folder = resources.files("agentchord.library") / "graphs"
    return sorted(p.name[: -len(".yaml")] for p in folder.iterdir() if p.name.endswith(".yaml"))


def load_task_graph(task: str) -> TaskGraph:
    """Load a task's library graph."""
    return load_graph(library_path(task))
