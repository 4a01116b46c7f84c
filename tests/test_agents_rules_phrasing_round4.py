"""Kinds of phrasing read in general (writers H, G and K's failures, each read by kind, never by sentence): steps run
together and other telegraphic steps, both/two arms as a subject, purposes and likenesses that add nothing, a held
pour said as a condition, distances said by where you stand, "the same thing with X on the other side", and a pour
"into it" whose source is the scene's one vessel. Each with variants across verbs, objects and scenes, and a near
miss refused."""

from __future__ import annotations


from grounding import refused, same

P1, P2, T, H, W, B, C = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "fold_towel",
                         "blocks_and_cup", "setup_coffee_tray")


def test_steps_run_together_are_a_step_per_verb() -> None:
    same(C, "put the capsule into the tray", ["pick up capsule put in tray", "grab the capsule drop it in the tray"])
    same(B, "put the red block in the cup", ["take red block put in cup"])
    # A topic said before its step is one step, not two: "and the blue cube put it beside ...".
    same(B, "put the red block in the cup , then put the blue block next to the red block",
         ["put the red block in the cup and the blue block put it beside the red one"])
    # An arm before its verb is its subject, never a step of its own.
    same(P1, "put the bottle back with the right arm", ["have the right arm put the bottle back"])


def test_a_verb_made_a_noun_and_a_particle_before_its_object() -> None:
    same(P1, "pick up the bottle with the right arm , then pour water into the cup , then put the bottle back with the right arm",
         ["Take the bottle with right hand and make pour to the cup, after put back bottle standing.",
          "take the bottle with the right hand, do a pour into the cup, then set back bottle"])
    refused(P1, "make pour to the plate")


def test_both_or_two_arms_as_a_subject_and_a_move_with_no_object() -> None:
    same(C, "put the capsule into the tray , then move the tray forward with both arms",
         ["pick up capsule put in tray, after that both arm lift tray and bring forward",
          "put the capsule in the tray, after two arms take tray and bring more far",
          "put the capsule in the tray, then two hands carry the tray and move forward"])


def test_a_purpose_or_a_likeness_adds_nothing() -> None:
    same(T, "put the spoon next to the plate", ["can you put the spoon next to the plate so i can eat my soup",
                                                 "put the spoon next to the plate so that we have room"])
    same(T, "put the fork to the left of the plate", ["put the fork on the left of the plate, the way my mother always laid the table"])
    same(W, "fold the towel", ["can you fold the towel like a sandwich", "fold the towel like a book"])
    # A purpose that says where is a place, never dropped: here it says the side.
    same(T, "put the spoon to the left of the plate", ["put the spoon next to the plate so it is on the left"])
    # A purpose naming a scene object may say what to do: kept, and refused rather than dropped.
    refused(T, "put the spoon next to the plate so i can reach the fork")


def test_a_held_pour_said_as_a_condition() -> None:
    held = "hold the cup , then pour water into the cup"
    same(P2, held, ["Pour while the cup's off the table, not on it.",
                    "pour water into the cup. Don't put the cup down while you're pouring, just hold it up",
                    "fill the cup, and don't pour while the cup is sitting on the table, lift it up first",
                    "pour water into the cup. Do the pouring with the cup held up, not on the table."])
    refused(P2, "pour water into the cup while it's on the table")


def test_distances_said_from_where_you_stand() -> None:
    forward = "move the tray forward"
    same(C, forward, ["Grab the tray by both handles and scoot it back a little, away from you.",
                      "move the whole tray a touch further back",
                      "lift the tray and set it down about ten centimetres farther out",
                      "Can you shift the tray back a few centimetres, away from you?",
                      "push the tray back a little, still centred"])
    same(H, "move the block forward", ["scoot the block a touch further away from you"])


def test_the_same_thing_on_the_other_side() -> None:
    same(T, "put the fork to the left of the plate , then put the spoon to the right of the plate",
         ["put the fork to the left of the plate, then same thing with the spoon on the other side",
          "put the fork to the left of the plate, and the same again for the spoon on the other side"])
    # No side said before: "the other side" of nothing is refused, never guessed.
    refused(T, "put the fork next to the plate, then same thing with the spoon on the other side")


def test_water_poured_into_it_is_not_the_vessel_it_comes_from() -> None:
    same(P1, "move the cup next to the bottle , then pour water into the cup",
         ["Move the cup over next to the bottle, then pour some water in it."])
    same(P2, "move the cup next to the bottle , then pour water into the cup", ["put the cup beside the bottle and pour water into it"])


def test_a_drink_given_to_a_vessel_and_courtesies() -> None:
    same(P1, "pour water into the cup", ["robot can u give the cup a drink from the bottle pleeease", "give the cup a drink",
                                         "pour water into the cup, if it's no trouble", "pour water into the cup if you don't mind"])
    same(C, "move the tray forward", ["move the tray a touch further back, if it's no trouble"])
    # A drink given to what the scene lacks is refused, never poured elsewhere.
    refused(P1, "give the plant a drink")
