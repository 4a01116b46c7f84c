"""One seeded trial of a simulated task: its world, built from the scene the seed draws.

The entry point of the simulator for the layers above it (episodes, the command line):
they get a :class:`~agentchord.worlds.protocol.World` here and never name the simulator's
classes.
"""

from __future__ import annotations

import numpy as np

from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

#: Mixed into the seed of a trial's scene draw (the disturbance schedule draws from the bare seed).
SCENE_SALT = 0x5CE7E


def scene_rng(seed: int) -> np.random.Generator:
    """The generator a trial's scene is drawn from."""
    return np.random.default_rng([seed, SCENE_SALT])


def open_world(task: str, seed: int) -> SimWorld:
    """The simulated world of ``task``'s trial ``seed``: the same seed, the same scene.

    Raises:
        KeyError: Unknown task.
    """
    if task not in SIM_TASKS:
        raise KeyError(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})")
    opener = getattr(SIM_TASKS[task], "open_world", None)
    if opener is not None:  # an environment we did not write (gym-aloha): its own world and sampler
        return opener(seed)
    return SimWorld(SIM_TASKS[task].sample_scene(scene_rng(seed)))
