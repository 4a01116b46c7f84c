"""Kinds of phrasing read in general (writers G and K's failures, each read by kind, never by sentence): end-state
frames after a time clause, "would you mind V-ing, and then V-ing", greetings and tags as talk, a learner's
prepositions, a topic said first and taken up by a pronoun, demonstratives, a likeness as how, the fold said by
its crease or by nothing at all, a held pour said "while you do it", beside what sits in a container. Each with
variants across verbs, objects and scenes, and a near miss refused."""

from __future__ import annotations


from grounding import goal, refused, same

P1, P2, T, H, W, B, C = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "fold_towel",
                         "blocks_and_cup", "setup_coffee_tray")


def test_an_end_state_frame_after_a_time_clause() -> None:
    same(P1, "pour water into the cup , put the bottle back",
         ["When you're done I want there to be water in the cup, and the bottle should still be standing up on the table.",
          "What I want at the end is water in the cup and the bottle standing where it was, nothing knocked over.",
          "once you've finished I'd like water in the cup and the bottle back where it was"])
    same(B, "put the blue block on the red block", ["When I come back I want the blue block sitting on top of the red one.",
                                                     "by the time I'm back I want the blue block on top of the red block",
                                                     "what I'm after is the blue block on top of the red block"])
    # The frame names a state of an object the scene lacks: refused, never dropped.
    refused(B, "When you're done I want the yellow block in the cup")


def test_would_you_mind_governs_every_step() -> None:
    same(C, "put the capsule into the tray , then move the tray forward",
         ["Would you mind dropping the capsule into the tray, and then moving the tray further away from you?",
          "do you mind putting the capsule into the tray, then pushing the tray further away from you"])
    same(B, "put the red block in the cup , then move the blue block to the left side of the table",
         ["would you mind putting the red block in the cup, and then moving the blue block to the left side of the table?"])


def test_greetings_and_tags_are_talk() -> None:
    same(H, "move the block to the target", ["Hey there! Would you mind moving that block over to the target? Thanks a bunch.",
                                              "hi there, move the block to the target for now"])
    same(C, "move the tray forward",
         ["Can you shift the tray further away from you? Leave the capsule where it is for now."])


def test_a_learners_prepositions() -> None:
    same(B, "put the red block next to the blue block", ["Please put the red cube next of the blue cube.",
                                                          "put the red block beside of the blue block"])
    same(B, "put the red block inside the cup", ["put the red block inside of the cup", "put the red block into of the cup"])
    same(H, "pick up the block , put it on the target", ["pick up the block, then put it on the target place"])
    refused(B, "put the red block next of the green block")


def test_a_topic_said_first_and_taken_up_by_a_pronoun() -> None:
    same(B, "put the red block in the cup , put the blue block next to the cup",
         ["put the red block in the cup and the blue block put it next to the cup",
          "the red block, put it in the cup, and the blue block, put it next to the cup"])
    same(P1, "pour water from the bottle into the cup", ["the bottle, pour it into the cup"])
    refused(B, "the green block, put it in the cup")


def test_a_demonstrative_before_an_object_is_its_determiner() -> None:
    same(B, "move the red block to the left side of the table", ["move that red block to the left side of the table",
                                                                  "move this red block over to the left side of the table"])


def test_a_likeness_is_how_not_what() -> None:
    same(T, "put the fork and the spoon next to the plate", ["Please put fork and spoon near the plate, like when we are eating dinner.",
                                                             "put the fork and the spoon next to the plate the way we do at home"])
    same(W, "fold the towel in half", ["fold the towel in half like you're folding laundry", "fold the towel like we fold sheets"])
    # A likeness that names an object may say what to do: refused, never dropped.
    refused(T, "put the spoon next to the plate like you did with the fork")


def test_the_fold_by_its_crease_or_with_nothing_named() -> None:
    same(W, "fold the towel in half", ["I want the towel folded in half with the fold on my side.", "fold it",
                                       "could you just fold it over once, bottom to top?"])
    # Another object named before it, or no cloth in the scene: not the cloth.
    refused(B, "fold it")


def test_a_held_pour_said_while_you_do_it() -> None:
    same(P2, "hold the cup , then pour water from the bottle into the cup",
         ["can u pour me some water but hold the cup up in the air while u do it lol",
          "pour water from the bottle into the cup, and keep the cup lifted while you do it"])
    refused(P2, "hold the cup while you do it")


def test_beside_what_sits_in_a_container_is_beside_the_container() -> None:
    goals = goal(B, "put the red block in the cup and the blue block beside the red one")
    assert goals[1]["relative_to"] == "cup"


def test_the_far_side_is_the_side() -> None:
    same(B, "move the cup to the right side of the table", ["move the cup over to the far right side", "put the cup on the far right side of the table"])
    # The far corner is still the back corner.
    assert goal(B, "move the cup to the far right corner")[0]["at"] == goal(B, "move the cup to the back right corner")[0]["at"]
