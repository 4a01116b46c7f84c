"""What the rules-reader tests share: the seed-0 scene of a task, and an instruction's grounded goal."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.rules.corpus import canonical
from agentchord.agents.rules.instructions import ground_instruction
from agentchord.agents.scene import Scene
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


@cache
def scene(task: str) -> Scene:
    """The scene the blind set's labels are written in (seed 0)."""
    sim = SIM_TASKS[task]
    return observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))


def goal(task: str, text: str) -> list[dict]:
    """The goals ``text`` grounds to in ``task``'s scene, as dicts with their kind."""
    return [g.model_dump(exclude_defaults=True) | {"kind": g.kind} for g in ground_instruction(text, scene(task)).goals]


def same(task: str, reference: str, variants: list[str]) -> None:
    """Each variant grounds to the reference's goal (a run of put-backs states no order)."""
    want = canonical(ground_instruction(reference, scene(task)))
    for text in variants:
        assert canonical(ground_instruction(text, scene(task))) == want, text


def refused(task: str, text: str) -> None:
    """``text`` is refused in ``task``'s scene (not read as some goal)."""
    with pytest.raises(InstructionNotGroundedError):
        ground_instruction(text, scene(task))
