"""Where a side grasp goes: the open gripper's way down to it, clear of the object's top."""

import numpy as np

from agentchord.actions.grasping.side_plan import strikes_top
from agentchord.features.frame import make_static_frame

# A bottle 20 cm tall, 6 cm across, standing at (0, 0.5); its top at 20 cm.
BOTTLE = make_static_frame(objects={"bottle": {"pos": (0.0, 0.5, 0.1), "extent": (0.06, 0.06, 0.2)}}).objects["bottle"]
TOP = 0.2
TOWARD_Y = np.array([0.0, 1.0, 0.0])  # the fingers point along +y, at the bottle from in front


def test_a_gripper_coming_straight_down_over_the_top_strikes_it():
    assert strikes_top(np.array([0.0, 0.45, 0.35]), np.array([0.0, 0.45, 0.1]), TOWARD_Y, BOTTLE, TOP)


def test_a_gripper_coming_down_in_front_of_the_fingertips_reach_misses_it():
    # The pre-grasp 12 cm in front of the bottle: the finger tips end 8 cm short of its near side.
    assert not strikes_top(np.array([0.0, 0.38, 0.35]), np.array([0.0, 0.38, 0.1]), TOWARD_Y, BOTTLE, TOP)


def test_a_gripper_coming_down_beside_it_misses_it():
    assert not strikes_top(np.array([0.2, 0.5, 0.35]), np.array([0.2, 0.5, 0.1]), TOWARD_Y, BOTTLE, TOP)


def test_a_gripper_passing_over_it_above_the_band_misses_it():
    assert not strikes_top(np.array([0.0, 0.3, 0.3]), np.array([0.0, 0.7, 0.3]), TOWARD_Y, BOTTLE, TOP)
