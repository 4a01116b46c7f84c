"""Simulated tasks (paper Appendix B): seeded scenes and success checks, one module per task."""

from agentchord.worlds.sim.tasks.base import SimTask, SuccessTracker, Verdict
from agentchord.worlds.sim.tasks.single_arm_pour_water import SingleArmPourWater

#: Every simulated task by name.
SIM_TASKS: dict[str, SimTask] = {task.name: task for task in (SingleArmPourWater(),)}

__all__ = ["SIM_TASKS", "SimTask", "SuccessTracker", "Verdict"]
