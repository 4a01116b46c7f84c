"""Point-cloud geometry: back-projection of depth images, down-sampling, axes and quaternions."""

from __future__ import annotations

import numpy as np

from agentchord.features.pointcloud import backproject, focal_length, orient, quat_from_axis, voxel_downsample


def _look_at(cam_pos: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Camera axes as columns (x right, y up, looking along -z) aimed at ``target``."""
    back = cam_pos - target
    back /= np.linalg.norm(back)
    right = np.cross([0.0, 0.0, 1.0], back)
    right /= np.linalg.norm(right)
    return np.column_stack([right, np.cross(back, right), back])


def _plane_depth(cam_pos, cam_rot, normal, offset, fovy, width, height) -> np.ndarray:
    """Exact depth image (distance along the viewing axis) of the plane ``normal . x = offset``."""
    f = focal_length(fovy, height)
    rows, cols = np.indices((height, width))
    rays_cam = np.stack([(cols + 0.5 - width / 2) / f, -(rows + 0.5 - height / 2) / f, -np.ones((height, width))], axis=-1)
    rays = rays_cam @ cam_rot.T  # unit depth along the viewing axis
    return (offset - normal @ cam_pos) / (rays @ normal)


def test_backprojection_of_a_plane_gives_the_plane():
    cam_pos = np.array([0.3, -0.4, 0.8])
    cam_rot = _look_at(cam_pos, np.array([0.0, 0.2, 0.0]))
    normal = np.array([0.1, -0.2, 1.0])
    normal /= np.linalg.norm(normal)
    offset = 0.05
    depth = _plane_depth(cam_pos, cam_rot, normal, offset, fovy=50.0, width=64, height=48)
    assert depth.min() > 0
    points = backproject(depth, 50.0, cam_pos, cam_rot)
    assert points.shape == (64 * 48, 3)
    np.testing.assert_allclose(points @ normal, offset, atol=1e-9)
    # Pixels are rays through the camera centre, and depth is measured along the viewing axis.
    np.testing.assert_allclose((points - cam_pos) @ -cam_rot[:, 2], depth.reshape(-1), atol=1e-9)
    # A mask keeps exactly its pixels, in row-major order.
    mask = np.zeros_like(depth, dtype=bool)
    mask[10, 20] = mask[30, 5] = True
    np.testing.assert_allclose(backproject(depth, 50.0, cam_pos, cam_rot, mask), points[[10 * 64 + 20, 30 * 64 + 5]])


def test_image_centre_lies_on_the_optical_axis():
    depth = np.full((4, 4), 2.0)
    points = backproject(depth, 60.0, np.zeros(3), np.eye(3))
    centre = points.reshape(4, 4, 3)[1:3, 1:3].mean(axis=(0, 1))
    np.testing.assert_allclose(centre, [0.0, 0.0, -2.0], atol=1e-12)
    # Row 0 is the top of the image: camera +y.
    assert points.reshape(4, 4, 3)[0, 0, 1] > 0 and points.reshape(4, 4, 3)[0, 0, 0] < 0


def test_voxels_and_quaternions():
    cloud = np.array([[0.0001, 0, 0], [0.0002, 0, 0], [0.01, 0, 0]])
    assert len(voxel_downsample(cloud, 0.003)) == 2
    np.testing.assert_allclose(quat_from_axis(np.array([0.0, 0.0, 1.0])), [1, 0, 0, 0])
    q = quat_from_axis(np.array([1.0, 0.0, 0.0]))  # a quarter turn about y
    np.testing.assert_allclose(q, [np.cos(np.pi / 4), 0, np.sin(np.pi / 4), 0], atol=1e-12)


def test_axis_sign_follows_the_last_estimate_only_while_it_is_informative():
    down_tilted = np.array([0.9, 0.0, -0.2]) / np.linalg.norm([0.9, 0.0, -0.2])
    previous = np.array([0.8, 0.0, 0.1]) / np.linalg.norm([0.8, 0.0, 0.1])
    np.testing.assert_allclose(orient(down_tilted, previous), down_tilted)  # past horizontal in a pour
    np.testing.assert_allclose(orient(down_tilted, None), -down_tilted)  # first sight: the top points up
    # After a big jump (a fallen bottle set upright again) the up-pointing end is the top.
    np.testing.assert_allclose(orient(np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 0.0])), [0.0, 0.0, 1.0])
