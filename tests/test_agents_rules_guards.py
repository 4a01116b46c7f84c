"""General guards against wrong goals: what a reader cannot account for is refused, never planned without it.

- a word that names a scene object is never dropped from a noun phrase (``the fork n spoon`` read as the spoon);
- a direction said after a move verb (``push it back``) is a way to move, the same way as the table's back,
  never a put-back or the way towards the robot;
- an arm said as ``the other one`` is the arm not holding what is in hand, or refused;
- an arm said not to be used (``but don't use your left arm``) gives the step to the other arm, or the
  instruction is refused: it is never dropped as a negated step that states no goal.
"""

from __future__ import annotations


from grounding import goal, refused, same, scene

P2, T, H, C, B = "dual_arm_pour_water", "rearrange_table", "handover_block", "setup_coffee_tray", "blocks_and_cup"


def test_an_object_word_inside_a_noun_phrase_is_never_dropped() -> None:
    # Two objects run together with no "and": refused, not read as the last one.
    refused(T, "put the fork spoon next to the plate")
    refused(B, "put the red block cup on the left side of the table")
    refused(P2, "pick up the bottle cup")
    # A word of the object's own description still describes it.
    assert goal(C, "put the coffee capsule in the tray")[0]["obj"] == "capsule"


def test_shorthand_for_and_joins_two_objects() -> None:
    same(T, "put the fork and the spoon by the plate", ["put the fork n spoon by the plate", "put the fork & spoon by the plate",
                                                        "put the fork + the spoon by the plate"])
    same(B, "put the red block and the blue block in the cup", ["put the red block n the blue block in the cup"])


def test_back_after_a_move_verb_is_away_from_the_robot() -> None:
    # The coffee scene's forward spot is where "back" goes, as "further away" does.
    same(C, "move the tray forward", ["push the tray back a bit", "shove the tray back", "slide the tray back a little"])
    # With no region that way: a nudge away from the robot (y grows), never towards it.
    moved = goal(B, "push the cup back")[0]
    start = next(o for o in scene(B).objects if o.name == "cup").pos
    assert moved["at"][1] > start[1]
    # "back where it was" is still a put-back, and "closer" still comes towards the robot.
    assert "at" not in goal(B, "move the red block back where it was")[0]
    assert goal(B, "push the cup closer")[0]["at"][1] < start[1]


def test_the_other_arm_is_the_one_not_holding_what_is_in_hand() -> None:
    pour = goal(P2, "pick up the cup with your left hand, and pour the bottle into it with the other one")[0]
    assert pour["kind"] == "poured" and pour["arm"] == "right"
    pour = goal(P2, "hold the cup in the right hand, then pour water from the bottle into it using the other hand")[0]
    assert pour["arm"] == "left"
    # Nothing in hand: no arm to be the other of; refused, not left to the planner.
    refused(B, "put the red block in the cup with the other hand")


def test_an_arm_said_not_to_be_used_is_read_or_refused_never_dropped() -> None:
    assert goal(H, "move the block onto the target, but don't use your left arm") == goal(H, "move the block onto the target with the right arm")
    same(B, "put the red block in the cup with the right arm", ["put the red block in the cup without using the left hand",
                                                               "put the red block in the cup and never use the left arm"])
    refused(H, "Move the block onto the target. Don't use your left arm.")  # said on its own: not read, so refused
    refused(H, "pick up the block with the left arm, don't use your left arm")  # contradicts the arm named
    refused(B, "don't use the right hand")


def test_a_step_said_again_by_an_addressed_arm_is_that_arms_with_its_own_side() -> None:
    fork_left = "put the fork to the left of the plate with the left arm"
    expected = goal(T, f"{fork_left}, then put the spoon to the right of the plate with the right arm")
    for said in ("Left arm, bring the fork over next to the plate on its left side. Right arm, do the same with the spoon on the right side.",
                 "Left arm, put the fork next to the plate on its left. Right arm, same thing with the spoon on the other side."):
        assert goal(T, said) == expected
    assert goal(B, "Left hand, put the red block in the cup. Right hand, do the same with the blue block.") == goal(
        B, "put the red block in the cup with the left arm, then put the blue block in the cup with the right arm")


def test_back_with_an_amount_and_no_verb_is_never_dropped() -> None:
    # "tray back a bit": a way to move said without a verb; read as a move or refused, never a put-back that states nothing.
    assert goal(C, "put the capsule in the tray, then push the tray back a little") == goal(
        C, "put the capsule in the tray, then move the tray forward")
    refused(C, "pod in the tray, then tray back a bit")
