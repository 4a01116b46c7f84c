"""Point-cloud geometry: back-projection of depth images and the cylinder / box fits."""

from __future__ import annotations

import numpy as np
import pytest

from agentchord.features.pointcloud import (
    backproject,
    fit_box,
    fit_circle,
    fit_cylinder,
    focal_length,
    orient,
    quat_from_axis,
    voxel_downsample,
)


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


def _cylinder_surface(centre, axis, radius, half, view_dir, n=1500, seed=0):
    """Points on the part of a solid cylinder's surface facing ``view_dir`` (a distant camera)."""
    rng = np.random.default_rng(seed)
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    angle = rng.uniform(0, 2 * np.pi, n)
    normals = np.outer(np.cos(angle), e1) + np.outer(np.sin(angle), e2)
    side = centre + radius * normals + np.outer(rng.uniform(-half, half, n), axis)
    side = side[normals @ view_dir > 0]
    r = radius * np.sqrt(rng.uniform(0, 1, n))
    cap_sign = 1.0 if axis @ view_dir > 0 else -1.0
    cap = centre + cap_sign * half * axis + np.outer(r * np.cos(angle), e1) + np.outer(r * np.sin(angle), e2)
    return np.concatenate([side, cap[: n // 3]])


@pytest.mark.parametrize("tilt_deg", [0.0, 50.0, 95.0])
def test_cylinder_fit_recovers_the_pose_from_one_side(tilt_deg):
    tilt = np.radians(tilt_deg)
    axis = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    centre = np.array([0.1, 0.5, 0.12])
    view = np.array([0.0, -1.0, 1.0]) / np.sqrt(2)
    points = _cylinder_surface(centre, axis, 0.03, 0.09, view)
    points = points + np.random.default_rng(1).normal(0, 0.0005, points.shape)
    # A centroid of the visible surface is biased towards the camera: the fit is not.
    assert np.linalg.norm(points.mean(axis=0) - centre) > 0.01
    camera = centre + 50.0 * view  # far away: the synthetic views are orthographic
    fit = fit_cylinder(points, radius=0.028, half_height=0.085, viewpoints=camera)
    assert np.linalg.norm(fit.pos - centre) < 0.002
    assert abs(fit.axis @ axis) > np.cos(np.radians(1.0))
    assert fit.axis[2] >= 0  # oriented up without a previous estimate
    # With a previous estimate the sign follows it, even past horizontal.
    hinted = fit_cylinder(points, radius=0.028, half_height=0.085, axis_hint=axis, viewpoints=camera)
    assert hinted.axis @ axis > np.cos(np.radians(1.0))


def test_box_fit_recovers_a_yawed_box():
    rng = np.random.default_rng(2)
    half = np.array([0.02, 0.03, 0.025])
    yaw = 1.1
    rot = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1.0]])
    centre = np.array([0.05, 0.55, 0.025])
    view = np.array([0.3, -1.0, 1.2])
    view /= np.linalg.norm(view)
    faces = []
    for k in range(3):
        for sign in (-1.0, 1.0):
            if sign * rot[:, k] @ view <= 0:
                continue  # faces turned away from the camera are not seen
            local = rng.uniform(-half, half, (600, 3))
            local[:, k] = sign * half[k]
            faces.append(centre + local @ rot.T)
    points = np.concatenate(faces)
    fit = fit_box(points, half, viewpoints=centre + 50.0 * view)
    assert np.linalg.norm(fit.pos - centre) < 0.001
    np.testing.assert_allclose(fit.size, half, atol=0.001)
    for k in range(3):  # axes matched to the nominal sizes (up to sign)
        assert abs(fit.rot[:, k] @ rot[:, k]) > np.cos(np.radians(1.0))
    assert fit.axis[2] > 0


def test_circle_voxels_and_quaternions():
    angle = np.linspace(0, np.pi, 50)
    centre, radius = fit_circle(np.column_stack([1 + 0.5 * np.cos(angle), -2 + 0.5 * np.sin(angle)]))
    np.testing.assert_allclose(centre, [1, -2], atol=1e-9)
    assert radius == pytest.approx(0.5)
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
