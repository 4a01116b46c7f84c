"""Which arm does a step (agents.rules.arm_words): a side alone, an arm referred back to, a hand-over said from the
receiver's side or on the way, an arm for each object, two arms as subjects of one sentence.

The sentences here are this file's own (not the blind evaluation set's, which is never tuned on).
"""

from __future__ import annotations

import pytest

from grounding import goal, same


SAME = [
    ("handover_block", "pick up the block with the left arm, hand it over to the right arm, put it in the target region with the right arm",
     ["grab the block w/ left, pass to right, then right puts it in the target region",
      "pick the block up with the left, give it the right one, and have that one put it in the target region",
      "left arm picks up the block and gives it to the right one, which puts it in the target area"]),
    ("dual_arm_pour_water", "hand the bottle over to the left arm, put the bottle on the left side of the table with the left arm",
     ["hand the bottle over to your left arm and let that one set it on the left side of the table",
      "pass the bottle to the left arm and have it put the bottle on the left side of the table"]),
    ("handover_block", "hand the block from the left arm to the right arm, then put it in the target region",
     ["the right hand takes the block from the left hand, then puts it in the target region",
      "move the block onto the target, passing it from the left hand to the right hand on the way"]),
    ("blocks_and_cup", "put the red block next to the cup with the left arm, put the blue block next to the cup with the right arm",
     ["use the left arm for the red block and the right one for the blue block, and put them both next to the cup",
      "the left arm takes the red block and the right arm takes the blue block, then both put them next to the cup"]),
    ("dual_arm_pour_water", "pick up the cup with the left arm, pour water from the bottle into the cup with the right arm, put both back",
     ["with the left arm hold up the cup; the right arm then pours the bottle into it. Put both back afterwards.",
      "lift the cup w/ left, pour w/ right, put both back"]),
    ("blocks_and_cup", "put the red block into the cup with the left arm", ["The red block needs to go in the cup. Use your left hand."]),
]


@pytest.mark.parametrize(("task", "reference", "variants"), SAME)
def test_an_arm_said_another_way_is_the_same_goal(task, reference, variants):
    same(task, reference, variants)


def test_a_side_that_names_a_place_is_not_an_arm():
    """"With the left side" is no arm: a side before a part word stays a place (and is refused here, not read as an arm)."""
    assert goal("blocks_and_cup", "put the red block on the left side of the table") == [
        {"kind": "placed", "obj": "red_block", "at": (-0.12, 0.52)}]
