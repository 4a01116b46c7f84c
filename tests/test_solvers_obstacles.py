"""Obstacle spheres built from feature-frame objects: they cover the object, tightly enough."""

import numpy as np
import pytest

from agentchord.features.frame import make_static_frame
from agentchord.solvers.obstacles import Spheres, held_spheres, object_spheres, scene_spheres


def _covered(spheres: Spheres, points: np.ndarray) -> np.ndarray:
    return (spheres.clearance(points) <= 1e-12).any(axis=1)


def _tilted_box_frame():
    quat = np.array([np.cos(0.3), 0.0, np.sin(0.3), 0.0])  # 0.6 rad about y
    axis = np.array([np.sin(0.6), 0.0, np.cos(0.6)])
    return make_static_frame({"box": {"pos": (0.1, 0.5, 0.1), "quat": quat, "axis": axis, "extent": (0.2, 0.06, 0.04)}})


def test_spheres_cover_every_point_of_a_tilted_box():
    frame = _tilted_box_frame()
    feats = frame.objects["box"]
    spheres = object_spheres("box", feats)
    rng = np.random.default_rng(0)
    local = rng.uniform(-0.5, 0.5, (2000, 3)) * feats.extent
    rot = np.column_stack([np.array([np.cos(0.6), 0.0, -np.sin(0.6)]), [0.0, 1.0, 0.0], feats.axis])
    assert _covered(spheres, feats.pos + local @ rot.T).all()
    assert set(spheres.labels) == {"box"}


def test_round_covering_of_a_cylinder_is_tight_and_complete():
    frame = make_static_frame({"bottle": {"pos": (0.0, 0.5, 0.1), "extent": (0.06, 0.06, 0.2)}})
    spheres = object_spheres("bottle", frame.objects["bottle"], round_section=True)
    rng = np.random.default_rng(1)
    radius, height = np.sqrt(rng.uniform(0, 1, 2000)) * 0.03, rng.uniform(-0.1, 0.1, 2000)
    angle = rng.uniform(0, 2 * np.pi, 2000)
    points = np.column_stack([radius * np.cos(angle), 0.5 + radius * np.sin(angle), 0.1 + height])
    assert _covered(spheres, points).all()
    # Sideways the spheres poke out by ~12% of the radius, not the 41% of the square's corners.
    assert spheres.radii.max() < 0.035
    assert spheres.radii.max() < object_spheres("bottle", frame.objects["bottle"]).radii.max()


def test_clearance_is_surface_to_surface():
    spheres = Spheres([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [0.1, 0.2])
    clearance = spheres.clearance(np.array([[0.5, 0.0, 0.0]]), 0.05)
    assert clearance == pytest.approx(np.array([[0.35, 0.25]]))


def test_scene_spheres_leave_out_excluded_and_held_objects():
    frame = make_static_frame(
        {"bottle": {"pos": (0.1, 0.5, 0.1)}, "cup": {"pos": (-0.1, 0.5, 0.05)}, "plate": {"pos": (0.0, 0.7, 0.01)}},
        arms={"right": {"ee": (0.1, 0.5, 0.12)}},
        holding={("right", "bottle")},
    )
    assert set(scene_spheres(frame).labels) == {"cup", "plate"}
    assert set(scene_spheres(frame, exclude=["plate"]).labels) == {"cup"}
    assert set(scene_spheres(frame, skip_held=False).labels) == {"bottle", "cup", "plate"}
    held = held_spheres(frame, "right")
    assert set(held.labels) == {"bottle"}
    # Offsets from the tool: the bottle's centre sits 2 cm below it.
    assert held.centres.mean(axis=0) == pytest.approx([0.0, 0.0, -0.02])


def test_malformed_spheres_are_refused():
    with pytest.raises(ValueError, match="radii"):
        Spheres([[0.0, 0.0, 0.0]], [0.1, 0.2])
    with pytest.raises(ValueError, match=">= 0"):
        Spheres([[0.0, 0.0, 0.0]], [-0.1])
    assert len(Spheres.concat(Spheres(), Spheres([[0, 0, 0]], [0.1]))) == 1


def test_a_carry_goes_straight_when_clear_and_over_an_object_in_the_way():
    from agentchord.solvers.obstacles import CARRY_CLEARANCE, Spheres, lift_over

    cup = Spheres(np.array([[0.0, 0.5, 0.02], [0.0, 0.5, 0.06]]), np.array([0.04, 0.04]))  # top at 0.10
    bottle = Spheres(np.array([[0.0, 0.0, -0.05], [0.0, 0.0, 0.05]]), np.array([0.035, 0.035]))  # hangs 8.5 cm below the tool
    start, goal = np.array([0.0, 0.7, 0.15]), np.array([0.0, 0.38, 0.15])
    # Clear path (the cup elsewhere): the goal alone.
    assert [w.tolist() for w in lift_over(start, goal, cup.translated([0.3, 0.0, 0.0]), bottle)] == [goal.tolist()]
    # Through the cup: up, across, down; the bottle's lowest point clears the cup's top.
    up, across, down = lift_over(start, goal, cup, bottle)
    assert up[2] == across[2] and up[2] - 0.085 >= 0.10 + CARRY_CLEARANCE - 1e-9
    assert np.allclose(up[:2], start[:2]) and np.allclose(across[:2], goal[:2]) and np.allclose(down, goal)
    # Nothing carried: the tool goes straight.
    assert len(lift_over(start, goal, cup, Spheres())) == 1
