"""What should be true at the end (agents.rules.end_states and agents.rules.held_pour): water in a vessel, back as it
was, a thing said to be in another, an object never taken already where it was; a pour said to be done holding the
vessel, before or after the pour, in the same sentence or another.

The sentences here are this file's own (not the blind evaluation set's, which is never tuned on).
"""

from __future__ import annotations

import pytest

from agentchord.agents.exceptions import InstructionNotGroundedError
from agentchord.agents.rules.instructions import ground_instruction
from grounding import goal, same, scene


SAME = [
    ("dual_arm_pour_water", "pour water from the bottle into the cup",
     ["I'd like the cup full of water, and the bottle back where it was",
      "I'd like the cup to have water in it and the bottle standing where it was",
      "End state: the cup has water in it, cup and bottle both upright on the table"]),
    ("setup_coffee_tray", "put the capsule into the tray, then move the tray forward",
     ["the tray should be further away, with the capsule in it", "push the tray forward with the capsule sitting in it",
      "I'd like the capsule to be in the tray and the tray to be pushed farther away."]),
    ("dual_arm_pour_water", "hold the cup, then pour water from the bottle into the cup, then put both back",
     ["fill the cup from the bottle while you hold it up in the air, then put both back",
      "pour some water into the cup. Keep the cup lifted while pouring.",
      "Pour water into the cup. The cup should be held off the table while you pour, not sitting on it.",
      "do the pour with the cup held up, not on the table. Pour water from the bottle into the cup."]),
    ("dual_arm_pour_water", "pick up the cup with the left arm, pour water from the bottle into the cup",
     ["Pour water from the bottle into the cup while holding the cup in the air with the left arm."]),
]


@pytest.mark.parametrize(("task", "reference", "variants"), SAME)
def test_an_end_state_said_another_way_is_the_same_goal(task, reference, variants):
    same(task, reference, variants)


def test_a_put_back_of_what_was_never_taken_is_no_goal():
    """After a pour from the bottle, "both back on the table" puts the bottle back; the cup never left its place."""
    assert goal("single_arm_pour_water", "pour water from the bottle into the cup, then put the cup and the bottle back") == [
        {"kind": "poured", "source": "bottle", "target": "cup"}, {"kind": "placed", "obj": "bottle"}]


def test_a_held_pour_with_no_pour_is_refused():
    with pytest.raises(InstructionNotGroundedError, match="no pour"):
        ground_instruction("hold the cup up while you pour", scene("dual_arm_pour_water"))
