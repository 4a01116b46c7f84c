"""Kinds of phrasing read in general (not one writer's sentences): each rule with variants of its own words.

Each test names the structure of English it checks (an intensifier before a place, ``there`` for the last
place, a pronoun with one possible referent, a row of two objects, arms as a joint subject, ...), and
checks that variants across verbs, objects and scenes give the same goal as the plain imperative, and
that near misses are refused rather than read wrongly.
"""

from __future__ import annotations


from grounding import goal, refused, same

P1, P2, T, H, C, W, B = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block",
                         "setup_coffee_tray", "fold_towel", "blocks_and_cup")


# --- places ---------------------------------------------------------------------------------------


def test_an_intensifier_before_a_place_is_no_side() -> None:
    same(P2, "put the cup next to the bottle", ["put the cup down right next to the bottle", "set the cup just beside the bottle",
                                                "place the cup directly next to the bottle"])
    same(B, "put the red block behind the cup", ["put the red block right behind the cup", "put the red block directly behind the cup"])
    # "to the right of": a side, not an intensifier.
    assert goal(B, "put the red block to the right of the cup")[0]["offset"][0] > 0


def test_beside_a_region_is_a_point_just_outside_it() -> None:
    beside = goal(H, "put the block next to the target")
    assert beside[0]["kind"] == "placed" and beside[0]["at"] == (0.021, 0.45)  # the side the block is on: left
    same(H, "put the block next to the target", ["put the block down right beside the target, not on it",
                                                 "place the block beside the target area, not in it"])
    left = goal(H, "put the block to the left of the target")[0]["at"]
    right = goal(H, "put the block to the right of the target")[0]["at"]
    assert left[0] < 0.12 < right[0]


def test_two_objects_to_one_side_are_a_row_in_their_present_order() -> None:
    row = goal(B, "the two blocks should be side by side on the left of the cup")
    assert [(g["obj"], g["relative_to"]) for g in row] == [("blue_block", "cup"), ("red_block", "blue_block")]
    assert all(g["offset"][0] < 0 for g in row)
    # To the right, the red block (now on the left of the blue one) is beside the cup, the blue one beyond it.
    right = goal(B, "put both blocks next to each other to the right of the cup")
    assert [(g["obj"], g["relative_to"]) for g in right] == [("red_block", "cup"), ("blue_block", "red_block")]
    assert all(g["offset"][0] > 0 for g in right)


def test_there_is_the_place_last_named() -> None:
    same(B, "put the blue block in the cup, then put the red block in the cup",
         ["put the blue block in the cup, then put the red block in there too",
          "Drop the blue block into the cup. After that put the red one in there as well."])


def test_to_the_front_is_the_scene_front_region_or_refused() -> None:
    same(C, "move the tray forward", ["carry the tray to the front", "push tray with two hand to the front"])
    refused(B, "move the red block to the front")
    assert goal(B, "move the red block to the front of the table")[0]["at"][1] < 0.48  # the table's near edge: said so


def test_a_direction_said_twice_or_after_an_amount_is_one_way() -> None:
    same(C, "move the tray forward", ["carry the tray a bit further forward", "push the tray about ten centimetres forward",
                                      "slide the tray roughly 5 cm forward"])


# --- references -----------------------------------------------------------------------------------


def test_it_with_nothing_before_is_the_scene_only_object() -> None:
    same(H, "pick up the block with the left arm and put it on the target",
         ["pick it up with the left arm and put it on the target", "Left arm grab it, then put it on the target."])
    refused(B, "pick it up and put it in the cup")  # three objects: "it" names none of them


def test_a_colour_the_one_object_has_still_describes_it() -> None:
    same(B, "put the blue block into the cup", ["drop the blue block into the white bowl", "put the blue cube in the white bowl"])
    refused(B, "put the blue block in the red bowl")  # the bowl-like cup is white: a contradiction, not a modifier
    refused(P1, "pour water into the blue cup")


def test_a_pronoun_after_a_fold_is_the_cloth_which_is_not_moved() -> None:
    refused(W, "fold the towel once, then pick it up and put it down to the right")


# --- arms -----------------------------------------------------------------------------------------


def test_from_one_hand_to_the_other_is_a_handover() -> None:
    same(H, "hand the block over, then put it on the target",
         ["pass the block from one hand to the other and then place it on the target",
          "move the block from hand to hand, then put it on the target",
          "transfer the block from one arm to the other one, then set it on the target"])


def test_an_arm_without_its_determiner() -> None:
    same(H, "hand the block over to the right arm", ["give the block to right arm", "pass the block over to right hand"])


def test_left_and_right_together_are_both_arms() -> None:
    same(C, "move the tray forward with both arms",
         ["left and right together lift the tray by the two ends and set it down further away",
          "the left and right arms carry the tray forward", "then use both hands to carry the tray forward"])


def test_both_of_them_then_each_one_named_with_its_arm() -> None:
    want = goal(P2, "pick up the cup with the left arm and the bottle with the right arm, then pour into the cup")
    assert want[0]["kind"] == "poured" and want[0]["hold_target"]
    same(P2, "pick up the cup with the left arm and the bottle with the right arm, then pour into the cup",
         ["Pick up both of them at once, cup in your left and bottle in your right, then pour into the cup",
          "grab them both, the cup in your left hand and the bottle in your right hand, then pour into the cup"])


def test_keep_it_up_is_holding_it() -> None:
    same(P2, "lift the cup with your left arm and hold it, then pour water into it with the right arm",
         ["lift the cup with your left arm and keep it in the air while the right one pours water into it",
          "pick up the cup with the left hand and keep it up while the right hand pours into it"])


# --- verbs, amounts, talk -------------------------------------------------------------------------


def test_water_given_or_added_to_a_cup_is_a_pour() -> None:
    same(P1, "pour water into the cup", ["give water in the red cup", "add a little water to the cup", "put some water into the cup",
                                         "pour me a little water, just a splash in the cup is fine"])


def test_a_remark_about_the_speaker_is_talk() -> None:
    same(P1, "pour water into the cup", ["I'm so thirsty after that meeting, honestly. Pour water into the cup.",
                                         "We were busy all day. Could you pour water into the cup?"])


def test_order_left_free_is_no_step() -> None:
    same(B, "put both blocks in the cup", ["Take both blocks and put them in the cup please, doesn't matter which one goes first.",
                                           "put both blocks in the cup in any order", "put both blocks in the cup, the order doesn't matter"])


def test_once_after_a_verb_is_one_time() -> None:
    same(W, "fold the towel in half", ["fold the towel once", "I'd like the towel folded once so it's only half as deep"])


# --- end states and cloth parts -------------------------------------------------------------------


def test_a_host_with_things_placed_around_it() -> None:
    same(T, "put the fork to the left of the plate, then put the spoon to the right of the plate",
         ["What I want to see is the plate with the fork on its left and the spoon on its right, both lying up-and-down instead of "
          "sideways like they are now.", "I'd like to see the plate with the fork on its left and the spoon on its right"])
    refused(T, "the plate with the fork on its right, both lying sideways")


def test_an_object_sitting_some_way_is_moved_that_way() -> None:
    same(C, "put the capsule in the tray, then move the tray forward",
         ["I need the tray sitting a little further from you with the capsule in it.",
          "I want the tray sitting further away with the capsule inside it"])


def test_the_near_corners_one_at_a_time_brought_to_the_far_edge_fold() -> None:
    same(W, "fold the towel in half",
         ["left hand takes the bottom left corner, right hand the bottom right one, and fold it up to the top edge",
          "take the near right corner with your right hand and the near left one with your left, then lay them on the far edge",
          "grab the corners of the towel nearest to you and bring em over to the other side, like folding a napkin",
          "take the two corners closest to you and bring them over to the opposite edge",
          "fold the towel once, with the crease closest to you"])
    refused(W, "fold the towel once, with the crease farthest from you")  # a crease said elsewhere: not read as this fold


def test_a_single_corner_or_a_side_laid_on_another_part_is_not_the_fold() -> None:
    same(W, "fold the towel in half", ["bring the bottom corners to the top corners", "lay the bottom corners of the towel on its top corners",
                                       "take the bottom edge of the towel and lay it on the top edge"])
    # A partial or diagonal fold is another fold than near edge onto far edge: refused, never read as it.
    refused(W, "bring the bottom left corner to the top right corner")
    refused(W, "put the near left corner on the far right corner")
    refused(W, "lay the top corners on the bottom corners")
