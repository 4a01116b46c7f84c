"""Kinds of phrasing read in general: self-corrections, hesitations and tags, an arm said not to be used, vague
"things" for what is named. Each with variants across verbs, objects and scenes, and a near miss refused."""

from __future__ import annotations


from grounding import refused, same

P1, P2, T, H, W, B = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "fold_towel",
                      "blocks_and_cup")


def test_a_corrected_phrase_replaces_the_phrase_of_its_kind() -> None:
    # An object's colour, an arm, an object noun: the word of that kind in the clause before.
    same(B, "put the red block in the cup", ["put the blue block in the cup, no, the red one",
                                             "Put the blue block in the cup — sorry, I mean the red one — please."])
    same(T, "put the spoon to the left of the plate with the left arm",
         ["put the spoon to the left of the plate with the right arm, no wait, the left one",
          "put the spoon to the left of the plate with the right hand — actually, the left hand"])
    same(B, "put the blue block in the cup", ["put the red block in the cup, no, the blue block"])


def test_a_corrected_clause_replaces_the_clause_with_its_verb() -> None:
    same(P2, "hold the cup with the left arm and pour with the right arm",
         ["hold the bottle in the left hand and — sorry, I mean hold the cup in the left hand — and pour with the right"])
    same(T, "move the spoon to the right of the plate",
         ["move the fork to the right of the plate — no wait, move the spoon to the right of the plate"])
    # A restart says the verb again: it is read once.
    same(P1, "pour water from the bottle into the cup with the left arm",
         ["use the right arm to pour — no wait, the left one — pour water from the bottle into the cup"])


def test_a_correction_that_fits_nothing_or_may_amend_is_refused() -> None:
    # Another verb may add to the clause rather than replace it.
    refused(H, "put the block on the target with your right hand — actually, pick it up with the left first")
    # Two object phrases the noun could replace.
    refused(B, "put the red block next to the cup, no, the block")
    refused(B, "put the red block on the blue block, no, the cup")  # the object, or its place?
    # Not corrections: "no rush", a greeting's "sorry", "actually" opening the ask.
    same(B, "put the red block in the cup", ["put the red block in the cup, no rush", "hi, sorry to bother you, put the red block in the cup",
                                             "hmm, actually put the red block in the cup"])


def test_hesitations_and_tags_are_talk() -> None:
    same(P1, "pour water from the bottle into the cup", ["uh pour water from the bottle into the cup yeah",
                                                         "pour water from the bottle into the cup lol",
                                                         "um, pour water from the bottle into the cup and that's it"])
    same(B, "put the red block in the cup, then put the blue block next to the cup",
         ["put the red block in the cup and then you can put the blue block next to the cup you know"])


def test_an_arm_said_not_to_be_used() -> None:
    same(P1, "pour water from the bottle into the cup with the left arm",
         ["use your left hand to pour water from the bottle into the cup, not the right one",
          "pour water from the bottle into the cup, not with your right hand"])
    same(B, "put the red block in the cup with the right arm", ["put the red block in the cup with the right hand, not the left one"])
    refused(B, "put the red block in the cup with the right hand, not the right one")


def test_things_are_the_objects_named() -> None:
    same(P2, "pick up the cup with the left arm, pour the bottle into it with the right arm, then put them back down",
         ["pick up the cup with the left arm, pour the bottle into it with the right arm, then put your things back down",
          "pick up the cup with the left arm, pour the bottle into it with the right arm, then put the stuff back down"])
    refused(B, "put the things in the cup")
