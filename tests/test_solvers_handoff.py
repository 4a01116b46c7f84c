"""Hand-off spots: where one arm sets an object down for the other."""

import numpy as np
import pytest

from agentchord.features.frame import make_static_frame
from agentchord.solvers import handoff
from agentchord.solvers.exceptions import NoHandoffSpotError
from agentchord.solvers.handoff import _in_approach_corridor, handoff_spot
from agentchord.solvers.reach import REACH

BOTTLE = {"extent": (0.055, 0.055, 0.192)}
CUP = {"extent": (0.049, 0.049, 0.096)}


def _frame(bottle_at, cup_at, taker_tool=(0.2, 0.5, 0.3)):
    """The dual-arm pour's bottle held up by the left arm, the cup standing on the table."""
    return make_static_frame(
        objects={"bottle": {**BOTTLE, "pos": bottle_at}, "cup": {**CUP, "pos": cup_at}},
        arms={"left": {"ee": bottle_at}, "right": {"ee": taker_tool}},
        holding={("left", "bottle")},
    )


def test_a_spot_is_in_both_arms_reach_and_clear_of_the_other_objects():
    frame = _frame((-0.167, 0.61, 0.196), (-0.109, 0.727, 0.048))
    spot = handoff_spot(frame, "bottle", placer="left", taker="right")
    point = np.r_[spot, 0.096][None, :]
    assert REACH["right"].slack(point)[0] >= handoff.TAKER_MARGIN
    assert REACH["left"].slack(point)[0] >= handoff.PLACER_MARGIN
    assert np.linalg.norm(spot - [-0.109, 0.727]) >= 0.0275 + 0.0245 + handoff.OBJECT_CLEARANCE


@pytest.mark.parametrize("corridors", [True, False])
def test_a_spot_is_out_of_the_way_an_arm_comes_to_grasp_another_object(corridors, monkeypatch):
    # Dual-arm pour, stress seed 38: without the corridors the bottle went down 8 cm from the cup, on
    # the left shoulder's side, where the left hand going to take the cup struck it.
    if not corridors:
        monkeypatch.setattr(handoff, "APPROACH_CORRIDOR_LENGTH", -1.0)
    cup = np.array([-0.109, 0.727])
    spot = handoff_spot(_frame((-0.167, 0.61, 0.196), (*cup, 0.048)), "bottle", placer="left", taker="right")
    monkeypatch.undo()
    in_the_way = _in_approach_corridor(spot[None, :], cup, 0.0245, 0.0275)[0]
    assert in_the_way != corridors


def test_a_spot_in_the_way_is_taken_where_no_other_is_clear(monkeypatch):
    frame = _frame((-0.167, 0.61, 0.196), (-0.109, 0.727, 0.048))
    monkeypatch.setattr(handoff, "APPROACH_CORRIDOR_LENGTH", -1.0)  # no corridors: the nearest clear spot
    nearest = handoff_spot(frame, "bottle", placer="left", taker="right")
    monkeypatch.setattr(handoff, "APPROACH_CORRIDOR_LENGTH", 10.0)
    monkeypatch.setattr(handoff, "APPROACH_CORRIDOR_HALF_WIDTH", 10.0)  # every spot in some arm's way
    np.testing.assert_allclose(handoff_spot(frame, "bottle", placer="left", taker="right"), nearest)


def test_no_spot_both_arms_reach_is_an_error_naming_the_object():
    frame = _frame((-0.167, 0.61, 0.196), (-0.109, 0.727, 0.048))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(handoff, "SPOT_GRID", ((1.5, 1.6), (1.5, 1.6), 0.02))  # far beyond both shells
        with pytest.raises(NoHandoffSpotError, match="bottle"):
            handoff_spot(frame, "bottle", placer="left", taker="right")


def test_a_spot_keeps_clear_of_where_the_program_carries_a_held_object_next():
    frame = _frame((-0.167, 0.61, 0.196), (0.0, 0.62, 0.052))
    free = handoff_spot(frame, "bottle", placer="left", taker="right")
    held_cup_at = free.copy()  # the other arm brings the cup right there next
    spot = handoff_spot(frame, "bottle", placer="left", taker="right", carried_to=[held_cup_at])
    assert np.linalg.norm(spot - held_cup_at) >= 0.0255 + handoff.CARRIED_CLEARANCE
