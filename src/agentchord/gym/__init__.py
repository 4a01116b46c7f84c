"""Gymnasium environments of the simulated tasks, registered on import.

    import gymnasium
    import agentchord.gym
    env = gymnasium.make("agentchord/SingleArmPourWater-v0", disturb="shift")

(or, without the import: ``gymnasium.make("agentchord.gym:agentchord/SingleArmPourWater-v0")``).
AgentChord itself as the expert that answers each step: :class:`AgentChordExpert`
(``agentchord.gym.expert``).
"""

from __future__ import annotations

import gymnasium

from agentchord.sim.tasks import SIM_TASKS

#: Namespace of the environment ids.
NAMESPACE = "agentchord"


def env_id(task: str) -> str:
    """``single_arm_pour_water`` -> ``agentchord/SingleArmPourWater-v0``."""
    return f"{NAMESPACE}/{''.join(part.capitalize() for part in task.split('_'))}-v0"


#: Environment id -> task name.
ENV_IDS: dict[str, str] = {env_id(task): task for task in sorted(SIM_TASKS)}


def _register() -> None:
    for eid, task in ENV_IDS.items():
        if eid not in gymnasium.registry:
            gymnasium.register(id=eid, entry_point="agentchord.gym.env:make_env", kwargs={"task": task},
                               disable_env_checker=True)


_register()



def __getattr__(name: str):
    # The expert imports the agents and the executor: only for who asks for it.
    if name == "AgentChordExpert":
        from agentchord.gym.expert import AgentChordExpert

        return AgentChordExpert
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["ENV_IDS", "NAMESPACE", "AgentChordExpert", "env_id"]
