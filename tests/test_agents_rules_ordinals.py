"""The order objects of one step are done in (agents.rules.ordinals): which goes first, said in the same sentence or
the next; the objects listed first and the step after them; the step again for another object in the next sentence.

The sentences here are this file's own (not the blind evaluation set's, which is never tuned on).
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from agentchord.agents.observe import observe, task_regions
from agentchord.agents.rules.corpus import canonical
from agentchord.agents.rules.instructions import ground_instruction
from agentchord.agents.scene import Scene
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


@cache
def scene(task: str) -> Scene:
    sim = SIM_TASKS[task]
    return observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))


def goal(task: str, text: str) -> list[dict]:
    return [g.model_dump(exclude_defaults=True) | {"kind": g.kind} for g in ground_instruction(text, scene(task)).goals]


def same(task: str, reference: str, variants: list[str]) -> None:
    """Each variant grounds to the reference's goal (a run of put-backs states no order)."""
    want = canonical(ground_instruction(reference, scene(task)))
    for text in variants:
        assert canonical(ground_instruction(text, scene(task))) == want, text

SAME = [
    ("blocks_and_cup", "put the blue block in the cup, then put the red block in the cup",
     ["put both blocks in the cup, the blue one first", "Put the two blocks into the cup. Blue first, then red.",
      "put the red block and the blue block into the cup, blue first", "Put the blue block in the cup. The red one too.",
      "drop the blue block into the cup, then put the red one in"]),
    ("rearrange_table", "put the fork next to the plate, then put the spoon next to the plate",
     ["first the fork, then the spoon: place each one next to the plate", "put the fork beside the plate, and do the same with the spoon",
      "Fork first, then spoon: put each one next to the plate."]),
    ("rearrange_table", "put the fork to the left of the plate, put the spoon to the right of the plate",
     ["Arrange the cutlery: fork on the left of the plate, spoon on the right."]),
    ("blocks_and_cup", "put the red block in the cup with the right arm, then put the blue block in the cup with the left arm",
     ["place the red block in the cup w/ right, then the blue one w/ left"]),
    ("handover_block", "hand the block from the left arm to the right arm, then put it in the target region",
     ["Put the block on the target, but first pass it from your left hand to your right."]),
    ("dual_arm_pour_water", "pour water from the bottle into the cup with both arms, then put both down",
     ["Two-handed pour: bottle into cup. Both go back down afterwards."]),
]


@pytest.mark.parametrize(("task", "reference", "variants"), SAME)
def test_an_order_said_another_way_is_the_same_goal(task, reference, variants):
    same(task, reference, variants)


def test_the_order_said_is_the_order_of_the_goals():
    first = goal("blocks_and_cup", "put both blocks in the cup, the blue one first")
    assert [g["obj"] for g in first] == ["blue_block", "red_block"]
    first = goal("blocks_and_cup", "put both blocks in the cup, the red one first")
    assert [g["obj"] for g in first] == ["red_block", "blue_block"]
