"""Where a held object sits in the hand (actions/grasping/in_hand.py)."""

import numpy as np
import pytest

from agentchord.actions.grasping.in_hand import axis_offset_in_tool, grasp_height_share, side_held_object
from agentchord.features.frame import make_static_frame
from agentchord.solvers.poses import grasp_frame

BOTTLE = {"pos": (0.10, 0.50, 0.09), "extent": (0.06, 0.06, 0.18)}
TOOL_X = grasp_frame(np.array([1.0, 0.0, 0.0]))  # approach +x, fingers across y, up z
TOOL_Y = grasp_frame(np.array([0.0, 1.0, 0.0]))  # approach +y


def _frame(ee, bottle=BOTTLE, holding=(("right", "bottle"),)):
    return make_static_frame(objects={"bottle": bottle}, arms={"right": {"ee": ee}}, holding=set(holding))


def test_a_side_held_upright_bottle_is_found_only_for_the_arm_that_holds_it():
    frame = _frame((0.10, 0.50, 0.09))
    assert side_held_object(frame, "right", TOOL_X) == "bottle"
    assert side_held_object(frame, "left", TOOL_X) is None
    assert side_held_object(_frame((0.10, 0.50, 0.09), holding=()), "right", TOOL_X) is None


def test_an_object_held_across_the_tools_up_axis_is_not_side_held():
    lying = {"pos": (0.10, 0.50, 0.03), "axis": (1.0, 0.0, 0.0), "extent": (0.06, 0.06, 0.18)}
    assert side_held_object(_frame((0.10, 0.50, 0.03), bottle=lying), "right", TOOL_X) is None


def test_a_centred_hold_has_no_axis_offset():
    np.testing.assert_allclose(axis_offset_in_tool(_frame((0.10, 0.50, 0.09)), "right", "bottle", TOOL_X), 0.0, atol=1e-12)


def test_an_axis_out_along_the_approach_is_read_in_the_tool_frame():
    # The tool stopped 3 cm short of the bottle's axis: the axis is 3 cm ahead along the approach.
    frame = _frame((0.07, 0.50, 0.12))
    np.testing.assert_allclose(axis_offset_in_tool(frame, "right", "bottle", TOOL_X), (0.03, 0.0, 0.0), atol=1e-12)
    # The same hold seen with the tool approaching along +y: ahead is the tool's x, whatever the world axis.
    frame = _frame((0.10, 0.47, 0.12))
    np.testing.assert_allclose(axis_offset_in_tool(frame, "right", "bottle", TOOL_Y), (0.03, 0.0, 0.0), atol=1e-12)


def test_a_tilted_axis_is_measured_at_the_tool_not_at_the_top():
    tilt = np.radians(10.0)
    axis = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    tilted = {"pos": (0.10, 0.50, 0.09), "axis": tuple(axis), "extent": (0.06, 0.06, 0.18)}
    # The tool on the axis, 4 cm above the centre: no offset, though the top leans 1.6 cm out.
    on_axis = np.array([0.10, 0.50, 0.09]) + 0.04 * axis
    offset = axis_offset_in_tool(_frame(tuple(on_axis), bottle=tilted), "right", "bottle", TOOL_X)
    assert np.linalg.norm(offset) < 1e-9


@pytest.mark.parametrize(("z", "share"), [(0.0, 0.0), (0.09, 0.5), (0.1476, 0.82), (0.18, 1.0)])
def test_the_grasp_height_share_runs_from_bottom_to_top(z, share):
    assert grasp_height_share(_frame((0.10, 0.50, z)), "right", "bottle") == pytest.approx(share)
