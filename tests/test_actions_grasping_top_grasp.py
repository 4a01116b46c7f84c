"""Where a top-down grasp takes an object: its long direction and the tool centre."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from agentchord.actions.grasping.top_grasp import FINGERTIP_REACH, lies_on_side, long_axis, on_its_edge, plain_top_grasp
from agentchord.features.frame import make_static_frame, tilt_deg


def _object(rotation: Rotation, extent=(0.165, 0.016, 0.011), pos=(-0.1, 0.6, 0.005)):
    x, y, z, w = rotation.as_quat()
    values = {"pos": pos, "quat": (w, x, y, z), "axis": rotation.as_matrix()[:, 2], "extent": extent}
    return make_static_frame(objects={"obj": values}).objects["obj"]


def test_a_flat_object_upside_down_is_grasped_as_if_the_right_way_up():
    # A fork that flipped over lies as flat as before: its tilt of 180 deg is not "on its side".
    along_y = Rotation.from_euler("z", 90, degrees=True)
    flipped = along_y * Rotation.from_euler("x", 180, degrees=True)
    up_dir, up_point = plain_top_grasp(_object(along_y))
    down_dir, down_point = plain_top_grasp(_object(flipped))
    assert tilt_deg(_object(flipped).axis) == pytest.approx(180.0)
    assert not lies_on_side(_object(flipped))
    np.testing.assert_allclose(down_point, up_point, atol=1e-9)
    assert abs(float(np.dot(down_dir, up_dir))) == pytest.approx(1.0)
    assert up_point[2] < 0.05  # the finger tips near the table, not a fork's length above it


def test_the_fingers_close_across_the_longer_horizontal_side():
    fork = _object(Rotation.from_euler("z", 90, degrees=True))  # its 16.5 cm side along world y
    long_dir, _ = plain_top_grasp(fork)
    np.testing.assert_allclose(np.abs(long_dir), [0.0, 1.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(np.abs(long_axis(fork)), [0.0, 1.0, 0.0], atol=1e-9)


def test_a_bottle_lying_on_its_side_is_taken_along_its_axis_from_its_upper_side():
    # Axis along world x, 6 cm across, lying with its centre 3 cm above the table.
    lying = _object(Rotation.from_euler("y", 90, degrees=True), extent=(0.06, 0.06, 0.2), pos=(0.1, 0.5, 0.03))
    assert lies_on_side(lying)
    long_dir, point = plain_top_grasp(lying)
    np.testing.assert_allclose(np.abs(long_dir), [1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(point[:2], [0.1, 0.5])
    # The top at 6 cm, the finger tips 3 cm below it (70 % of 6 cm is more than the 3 cm cap).
    assert point[2] - FINGERTIP_REACH == pytest.approx(0.03)


def test_the_finger_tips_stay_off_the_table_for_a_flat_object():
    card = _object(Rotation.identity(), extent=(0.08, 0.05, 0.002), pos=(0.0, 0.5, 0.001))
    _, point = plain_top_grasp(card)
    assert point[2] - FINGERTIP_REACH == pytest.approx(0.004)


def test_a_flat_object_on_its_edge_is_taken_across_its_faces_at_its_own_height():
    # Rearrange, stress seed 35: a fork (14 cm long, 1.6 cm wide) standing on its edge against the
    # plate was taken for a bottle lying down: the fingers closed 8 cm above it, across its length.
    # Here its length (local x) lies along world y, its width (local y) stands up, its faces
    # (local z, its axis) look along world x.
    on_edge = Rotation.from_matrix(np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]))
    fork = _object(on_edge, extent=(0.141, 0.016, 0.009), pos=(-0.15, 0.58, 0.008))
    assert lies_on_side(fork) and on_its_edge(fork)
    long_dir, point = plain_top_grasp(fork)
    np.testing.assert_allclose(np.abs(long_dir), [0.0, 1.0, 0.0], atol=1e-9)  # the fingers close along x
    np.testing.assert_allclose(np.abs(long_axis(fork)), [0.0, 1.0, 0.0], atol=1e-9)
    # 1.6 cm high: the finger tips 70 % of the way down it, not 8 cm above it.
    assert point[2] - FINGERTIP_REACH == pytest.approx(0.016 - 0.7 * 0.016)


def test_a_bottle_or_capsule_lying_down_is_not_on_its_edge():
    lying = _object(Rotation.from_euler("y", 90, degrees=True), extent=(0.06, 0.06, 0.2), pos=(0.1, 0.5, 0.03))
    assert lies_on_side(lying) and not on_its_edge(lying)
    # Coffee tray, real seed 84: a capsule 2.7 cm tall and 3.3 cm across lying on its round side is
    # taken across its round side (its axis the long direction), not across its flat ends.
    capsule = _object(Rotation.from_euler("y", 90, degrees=True), extent=(0.033, 0.033, 0.027), pos=(-0.14, 0.6, 0.017))
    assert lies_on_side(capsule) and not on_its_edge(capsule)
    long_dir, _ = plain_top_grasp(capsule)
    np.testing.assert_allclose(np.abs(long_dir), [1.0, 0.0, 0.0], atol=1e-9)
    flat = _object(Rotation.identity())
    assert not lies_on_side(flat) and not on_its_edge(flat)
