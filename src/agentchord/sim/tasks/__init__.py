"""Simulated tasks (paper Appendix B): seeded scenes and success checks, one module per task.

Every module of this package that defines ``TASK`` (a :class:`SimTask`) is registered under
``TASK.name``: adding a task is adding a module.
"""

from __future__ import annotations

import importlib
import pkgutil

from agentchord.harness import SuccessTracker, Verdict
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


#: Every simulated task by name.
SIM_TASKS: dict[str, SimTask] = _discover()


def judge_by_goal(goal: object | None, constraints: list[str], regions: dict | None = None) -> GoalTracker:
    """A success check that judges ``goal`` (a planned goal spec) on the world, in any task's scene."""
    tracker = GoalTracker()
    tracker.expect(goal, constraints, regions)
    return tracker


__all__ = ["SIM_TASKS", "GoalTracker", "SimTask", "SuccessTracker", "Verdict", "judge_by_goal"]
