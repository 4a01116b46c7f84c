"""The ALOHA robot's names and numbers, shared by every layer."""

from agentchord.features.frame import ARMS as FRAME_ARMS
from agentchord.gym.aloha import ARMS as GYM_ARMS
from agentchord.robot.aloha import ARM_PREFIX, ARMS, other_arm


def test_other_arm_is_the_arm_that_is_not_the_one_given():
    assert other_arm("left") == "right"
    assert other_arm("right") == "left"
    assert {other_arm(arm) for arm in ARMS} == set(ARMS)


def test_every_layer_names_the_same_arms_in_alohas_order():
    # gym-aloha's action vector is the left arm's joints then the right's.
    assert ARMS == ("left", "right") == FRAME_ARMS == GYM_ARMS
    assert set(ARM_PREFIX) == set(ARMS)
