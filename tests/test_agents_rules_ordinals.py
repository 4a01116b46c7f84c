"""The order objects of one step are done in (agents.rules.ordinals): which goes first, said in the same sentence or
the next; the objects listed first and the step after them; the step again for another object in the next sentence.

The sentences here are this file's own (not the blind evaluation set's, which is never tuned on).
"""

from __future__ import annotations

import pytest

from grounding import goal, same


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
