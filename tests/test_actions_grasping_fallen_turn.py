"""Turning a fallen tall object upright in hand: the grasp across it, where it turns, the turn."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from agentchord.actions.grasping.fallen_turn import TURN_FROM_BASE, fallen_grasp_frame, turn_pose, turned
from agentchord.actions.grasping.top_grasp import FINGERTIP_REACH
from agentchord.features.frame import make_static_frame


def _lying_bottle(yaw_deg: float, pos=(0.0, 0.5, 0.03)):
    """A 20 cm bottle, 6 cm across, lying with its top towards ``yaw_deg`` (about world z)."""
    rotation = Rotation.from_euler("z", yaw_deg, degrees=True) * Rotation.from_euler("y", 90, degrees=True)
    x, y, z, w = rotation.as_quat()
    values = {"pos": pos, "quat": (w, x, y, z), "axis": rotation.as_matrix()[:, 2], "extent": (0.06, 0.06, 0.2)}
    return make_static_frame(objects={"bottle": values}).objects["bottle"]


@pytest.mark.parametrize("yaw_deg", [0.0, 70.0, 180.0, -120.0])
def test_the_fingers_close_across_the_axis_from_above(yaw_deg):
    bottle = _lying_bottle(yaw_deg)
    rotation, point = fallen_grasp_frame(bottle)
    np.testing.assert_allclose(rotation[:, 0], [0.0, 0.0, -1.0], atol=1e-9)  # approach straight down
    np.testing.assert_allclose(rotation[:, 2], bottle.axis, atol=1e-9)  # tool z towards the top
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(point[:2], bottle.pos[:2])
    assert point[2] - FINGERTIP_REACH > 0.0  # the finger tips stay off the table


@pytest.mark.parametrize("yaw_deg", [0.0, 90.0, 180.0, -45.0])
def test_the_turn_ends_upright_in_a_side_grasp_facing_away_from_the_shoulder(yaw_deg):
    base = np.array([-0.3, 0.0, 0.0])
    bottle = _lying_bottle(yaw_deg)
    rotation, point = fallen_grasp_frame(bottle)
    lifted, yaw = turn_pose(bottle, point, rotation, 0.0, base)
    upright = turned(rotation, yaw, 1.0)
    np.testing.assert_allclose(upright[:, 2], [0.0, 0.0, 1.0], atol=1e-9)  # the object's axis: up
    outward = np.r_[(lifted - base)[:2], 0.0]
    np.testing.assert_allclose(upright[:, 0], outward / np.linalg.norm(outward), atol=1e-9)
    np.testing.assert_allclose(turned(rotation, yaw, 0.0), rotation, atol=1e-12)
    # The top only rises on the way: the object's axis (tool z) never points below level.
    assert all(turned(rotation, yaw, s)[2, 2] >= -1e-9 for s in np.linspace(0.0, 1.0, 21))


def test_a_bottle_beside_the_shoulder_is_turned_away_from_it():
    base = np.array([-0.3, 0.0, 0.0])
    bottle = _lying_bottle(0.0, pos=(-0.2, 0.05, 0.03))
    rotation, point = fallen_grasp_frame(bottle)
    lifted, _ = turn_pose(bottle, point, rotation, 0.0, base)
    assert np.linalg.norm(lifted[:2] - base[:2]) == pytest.approx(TURN_FROM_BASE)
    # Lifted by half its length and 6 cm: the bottom clears the table as it turns.
    assert lifted[2] == pytest.approx(point[2] + 0.1 + 0.06)


def test_a_grasp_slid_towards_the_top_is_lifted_that_much_higher():
    bottle = _lying_bottle(30.0)
    rotation, point = fallen_grasp_frame(bottle)
    base = np.array([-0.3, 0.0, 0.0])
    plain, _ = turn_pose(bottle, point, rotation, 0.0, base)
    slid, _ = turn_pose(bottle, point, rotation, 0.04, base)
    toward_bottom, _ = turn_pose(bottle, point, rotation, -0.04, base)
    assert slid[2] - plain[2] == pytest.approx(0.04)
    assert toward_bottom[2] == pytest.approx(plain[2])
