"""Where things go and which way (agents.rules.places): a direction as the destination, how far as a nudge, the spot
a direction leads to, a place said again, the other side of an anchor, where another object was.

The sentences here are this file's own (not the blind evaluation set's, which is never tuned on).
"""

from __future__ import annotations

import pytest

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.rules.instructions import ground_instruction
from grounding import goal, same, scene


SAME = [
    ("blocks_and_cup", "move the blue block forward",
     ["pick up the blue block and set it down a bit further away", "put the blue block down further from you",
      "the blue block should be a little further away than it is now"]),
    ("handover_block", "move the block closer", ["pick the block up and put it back down a little nearer to you"]),
    ("blocks_and_cup", "move the red block left",
     ["slide the red block over a little to the left", "the red block should go a little more to the left",
      "move the red block a few centimetres to the left", "take the red block and put it back where it was, a bit to the left"]),
    ("setup_coffee_tray", "put the capsule in the tray, then move the tray forward",
     ["put the capsule in the tray, then lift the tray and set it down further from you",
      "put the capsule in the tray, then shove the tray back a bit, away from me",
      "put the capsule in the tray, then carry the tray forward to the spot"]),
    ("rearrange_table", "put the spoon next to the plate",
     ["bring the spoon over to the right, near the plate", "Put the spoon next to the plate. Right next to it.",
      "put the spoon down beside the plate, just beside"]),
    ("rearrange_table", "put the fork to the left of the plate, then put the spoon to the right of the plate",
     ["put the fork beside the plate, then the spoon on the opposite side of the plate",
      "move the fork next to the plate, then move the spoon to the other side of the plate"]),
    ("dual_arm_pour_water", "pick up the cup, then put it where it was", ["grab the cup and put it back where you found it"]),
    ("rearrange_table", "put the fork and the spoon next to the plate", ["lay out the fork and spoon either side of the plate"]),
]


@pytest.mark.parametrize(("task", "reference", "variants"), SAME)
def test_a_place_said_another_way_is_the_same_goal(task, reference, variants):
    same(task, reference, variants)


def test_how_far_makes_a_put_a_nudge_not_the_tables_side():
    """"The cup goes a bit to the left" moves it 10 cm; "the cup goes to the left" is the table's left side."""
    nudged = goal("blocks_and_cup", "the cup goes a bit to the left")
    side = goal("blocks_and_cup", "put the cup to the left side of the table")
    assert nudged == goal("blocks_and_cup", "move the cup left") and nudged != side


def test_where_another_object_was_is_its_spot_at_the_start():
    cup, bottle = (next(o for o in scene("dual_arm_pour_water").objects if o.name == n) for n in ("cup", "bottle"))
    got = goal("dual_arm_pour_water", "put the bottle where the cup is, then put the cup where the bottle was")
    assert got == [{"kind": "placed", "obj": "bottle", "at": (round(cup.pos[0], 3), round(cup.pos[1], 3))},
                   {"kind": "placed", "obj": "cup", "at": (round(bottle.pos[0], 3), round(bottle.pos[1], 3))}]


@pytest.mark.parametrize(("task", "text"), [("blocks_and_cup", "carry the red block forward to the spot"),
                                            ("rearrange_table", "put the spoon on the other side of the plate")])
def test_a_place_with_nothing_to_lead_to_is_refused(task, text):
    """A spot no region of the scene is that way; "the other side" of an anchor nothing was put beside yet."""
    with pytest.raises(InstructionNotGroundedError):
        ground_instruction(text, scene(task))


def test_a_side_slip_before_an_arm_or_a_side_is_that_side():
    """"The lift hand", "the light arm": a real word one edit from a side, where a side goes, is that side."""
    assert goal("blocks_and_cup", "put the red block on the blue block with the light arm") == goal(
        "blocks_and_cup", "put the red block on the blue block with the right arm")


def test_a_part_of_the_table_no_rule_knows_is_refused_not_read_as_the_table():
    """"The rite side of the table" is no part of it the rules know: refused, not a put-back (which would lose it)."""
    with pytest.raises(InstructionNotGroundedError):
        ground_instruction("put the red block on the rite side of the table", scene("blocks_and_cup"))
