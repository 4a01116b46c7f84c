"""Simulated tasks (paper Appendix B): seeded scenes and success checks, one module per task.

Every module of this package that defines ``TASK`` (a :class:`SimTask`) is registered under
``TASK.name``: adding a task is adding a module. A task outside the package is registered the
same way from the ``AGENTCHORD_TASKS`` environment variable (module files, or folders of them,
separated by ``os.pathsep``) or from an installed package's ``agentchord.tasks`` entry point
(docs/scenes.md).
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import os
import pkgutil
import sys
from pathlib import Path

from agentchord.harness import SuccessTracker, Verdict
from agentchord.sim.exceptions import TaskPluginError
from agentchord.sim.tasks.base import SimTask
from agentchord.sim.tasks.goal_tracker import GoalTracker


def _discover() -> dict[str, SimTask]:
    tasks: dict[str, SimTask] = {}
    for module_info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if module_info.name in ("base", "goal_tracker", "gym_aloha_common"):
            continue
        module = importlib.import_module(f"{__name__}.{module_info.name}")
        task = getattr(module, "TASK", None)
        if task is not None:
            tasks[task.name] = task
    return tasks


#: Environment variable naming task modules outside the package (files or folders, os.pathsep-separated).
TASKS_VARIABLE = "AGENTCHORD_TASKS"
#: Entry-point group an installed package registers its tasks under (each entry names a ``TASK`` object).
ENTRY_POINT_GROUP = "agentchord.tasks"


def _task_files(value: str) -> list[Path]:
    files: list[Path] = []
    for part in (p for p in value.split(os.pathsep) if p.strip()):
        path = Path(part).expanduser()
        if path.is_dir():
            files += sorted(f for f in path.glob("*.py") if not f.name.startswith("_"))
        elif path.is_file() and path.suffix == ".py":
            files.append(path)
        else:
            raise TaskPluginError(f"{TASKS_VARIABLE}: {part!r} is neither a .py file nor a folder of them")
    return files


def _load_file(path: Path) -> object:
    name = f"agentchord_user_tasks.{path.stem}"
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise TaskPluginError(f"{TASKS_VARIABLE}: {path}: not a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling (worker pools) look modules up by name
    try:
        spec.loader.exec_module(module)
    except Exception as error:  # a user's module: any failure is its file's, reported as such
        del sys.modules[name]
        raise TaskPluginError(f"{TASKS_VARIABLE}: {path}: importing it raised {type(error).__name__}: {error}") from error
    if not hasattr(module, "TASK"):
        raise TaskPluginError(f"{TASKS_VARIABLE}: {path}: defines no TASK (the task object, e.g. TASK = MyScene())")
    return module.TASK


def _register(tasks: dict[str, SimTask], task: object, where: str) -> None:
    if isinstance(task, type):
        raise TaskPluginError(f"{where}: its TASK is the class {task.__name__}, not a task: make one, TASK = {task.__name__}()")
    missing = [attr for attr in ("name", "description", "sample_scene", "success_tracker") if not hasattr(task, attr)]
    if missing:
        raise TaskPluginError(f"{where}: its TASK has no {', '.join(missing)} (a task: docs/scenes.md)")
    name = task.name  # type: ignore[attr-defined]
    if not isinstance(name, str) or not name.isidentifier():
        raise TaskPluginError(f"{where}: its TASK's name {name!r} is not a plain identifier (letters, digits, _)")
    if name in tasks:
        raise TaskPluginError(f"{where}: a task named {name!r} exists already; give yours another name")
    tasks[name] = task  # type: ignore[assignment]


def _plugins(tasks: dict[str, SimTask]) -> dict[str, SimTask]:
    for entry in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        where = f"entry point {entry.name} = {entry.value} ({ENTRY_POINT_GROUP})"
        try:
            task = entry.load()
        except Exception as error:  # an installed package's module: reported with its entry point
            raise TaskPluginError(f"{where}: loading it raised {type(error).__name__}: {error}") from error
        _register(tasks, task, where)
    for path in _task_files(os.environ.get(TASKS_VARIABLE, "")):
        _register(tasks, _load_file(path), f"{TASKS_VARIABLE}: {path}")
    return tasks


#: Every simulated task by name: the package's, then the plugins'.
SIM_TASKS: dict[str, SimTask] = _plugins(_discover())


def judge_by_goal(goal: object | None, constraints: list[str], regions: dict | None = None) -> GoalTracker:
    """A success check that judges ``goal`` (a planned goal spec) on the world, in any task's scene."""
    tracker = GoalTracker()
    tracker.expect(goal, constraints, regions)
    return tracker


__all__ = ["ENTRY_POINT_GROUP", "SIM_TASKS", "TASKS_VARIABLE", "GoalTracker", "SimTask", "SuccessTracker", "TaskPluginError",
           "Verdict", "judge_by_goal"]
