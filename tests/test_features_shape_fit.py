"""Shape fits to point clouds: a cylinder seen from one side, a yawed box, a circle."""

from __future__ import annotations

import numpy as np
import pytest

from agentchord.features.shape_fit import fit_box, fit_circle, fit_cylinder


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


def test_circle_fit_through_half_a_circle():
    angle = np.linspace(0, np.pi, 50)
    centre, radius = fit_circle(np.column_stack([1 + 0.5 * np.cos(angle), -2 + 0.5 * np.sin(angle)]))
    np.testing.assert_allclose(centre, [1, -2], atol=1e-9)
    assert radius == pytest.approx(0.5)
