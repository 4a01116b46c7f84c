"""How a step's verb is said (agents.rules.verbs, and the verb slips of agents.rules.phrasing): a subject, "let's",
causatives, the receiver before the thing, the object left out, phrasal verbs, amounts of a pour, swapping, turning.

The sentences here are this file's own (not the blind evaluation set's, which is never tuned on).
"""

from __future__ import annotations

import pytest

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.rules.instructions import ground_instruction, read_instruction
from grounding import goal, same, scene


SAME = [
    ("blocks_and_cup", "put the red block into the cup",
     ["you pick up the red block and you drop it into the cup", "let's put the red block in the cup",
      "make the red block end up in the cup", "grab the red block, then place in the cup", "drop the red block off in the cup",
      "hmm, let's put the red block in the cup for now, we can do the blue one later",
      "move the red block into the cup, don't bother moving the blue one", "red block -> cup"]),
    ("single_arm_pour_water", "pour water from the bottle into the cup",
     ["make some water go into the cup", "tip some of it into the cup from the bottle", "pour a little into the cup",
      "a splash of water into the cup please", "poor water from the bottle into the cup",
      "don't pour it all over the table, pour water from the bottle into the cup", "tip the bottle over the cup so some water goes in"]),
    ("dual_arm_pour_water", "pick up the cup with the left arm, pick up the bottle with the right arm, pour water from the bottle into the cup "
     "with the right arm, put both down",
     ["Both arms: left one grabs the cup, right one grabs the bottle and pours. Then set both on the table."]),
    ("dual_arm_pour_water", "pick up the cup with the left arm, pour water from the bottle into the cup with the right arm",
     ["lift the cup with the left arm and pour it a little water with the right arm"]),
    ("dual_arm_pour_water", "pick up the bottle with the right arm and the cup with the left arm, pour into it, then put them back",
     ["hold the bottle in your right hand and the cup in your left, bring them together and pour, then put them back where you got them"]),
    ("setup_coffee_tray", "put the capsule into the tray", ["load the capsule into the tray", "slot the capsule into the tray"]),
    ("single_arm_pour_water", "pick up the bottle, pour water from the bottle into the cup, put the bottle back",
     ["Grab the bottle, give the cup a splash of water, then stand the bottle back up."]),
    ("handover_block", "pick up the block with the left arm, hand it over to the right arm, put it in the target region with the right arm",
     ["Have the left arm pick the block up and hand it off, and then have the right arm set it down in the target area."]),
    ("blocks_and_cup", "stack the red block on the blue block", ["Take the red block and place it on the blue block so they're stacked."]),
    ("single_arm_pour_water", "pour water from the bottle into the cup with the right arm",
     ["Pour into the cup with the bottle, right arm", "Ok robot, here's the deal: pour water from the bottle into the cup with your right arm."]),
    ("rearrange_table", "put the fork and the spoon next to the plate",
     ["line the fork and the spoon up next to the plate", "tidy up the fork and the spoon so they're arranged beside the plate",
      "put the fork and the spoon next to the plate, then turn them so they face away from you"]),
    ("blocks_and_cup", "put the red block where the blue block was, then put the blue block where the red block was",
     ["swap the red block and the blue block", "swap where the red block and the blue block are"]),
    ("dual_arm_pour_water", "put the cup where the bottle was, then put the bottle where the cup was",
     ["swap the bottle and the cup so the cup ends up where the bottle was and the bottle where the cup was"]),
    ("handover_block", "pick up the block with the left arm, hand it over to the right arm, put it in the target region",
     ["Could the left arm pick up the block? Then it passes it to the right arm, which places it in the target region."]),
]


@pytest.mark.parametrize(("task", "reference", "variants"), SAME)
def test_a_verb_said_another_way_is_the_same_goal(task, reference, variants):
    same(task, reference, variants)


@pytest.mark.parametrize(("task", "text"), [("single_arm_pour_water", "tip half of it into the cup"),
                                            ("single_arm_pour_water", "pour half of the water into the cup")])
def test_a_stated_fraction_of_a_pour_is_refused_not_read_as_a_pour(task, text):
    with pytest.raises(InstructionNotGroundedError):
        ground_instruction(text, scene(task))


def test_a_real_word_is_read_as_a_verb_only_where_a_verb_goes():
    """"Poor" before its object is a slip for "pour"; the same word elsewhere is left alone."""
    where = scene("single_arm_pour_water")
    assert read_instruction("poor water from the bottle into the cup", where).prepared.corrected == {"poor": "pour"}
    assert read_instruction("put the poor cup next to the bottle", where).prepared.corrected == {}


def test_a_pour_with_nothing_said_is_into_the_one_vessel_it_can_be():
    """"... and pour": into the container in hand, else the scene's one; none to pour into (the blocks scene has no
    vessel to pour from) is refused."""
    assert goal("single_arm_pour_water", "pick up the bottle and pour")[0] == {"kind": "poured", "source": "bottle", "target": "cup"}
    with pytest.raises(InstructionNotGroundedError, match="pour into"):
        ground_instruction("pick up the red block and pour", scene("blocks_and_cup"))


def test_water_given_to_a_vessel_is_a_pour_never_a_hand_over_of_it():
    got = goal("single_arm_pour_water", "give the cup some water")
    assert [g["kind"] for g in got] == ["poured", "placed"] and got[0]["target"] == "cup"
