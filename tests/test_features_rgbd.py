"""RGB-D feature extraction: accuracy against the simulator, camera rate, occlusion."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from agentchord.expr.templates import lost_view
from agentchord.features.oracle import OracleExtractor
from agentchord.features.rgbd import MIN_POINTS, RgbdExtractor, frame_points
from agentchord.features.segmentation import LabelSegmenter, NoisySegmenter
from agentchord.sim.world import SimWorld

SMALL = {"width": 160, "height": 120}


@pytest.fixture
def world(pour_scene):
    return SimWorld(pour_scene)


@pytest.fixture
def extractor(world):
    extractor = RgbdExtractor(world, **SMALL)
    yield extractor
    extractor.close()


def _errors(world, name, feats):
    pos, rot = world.object_pose(name)
    centre_mm = np.linalg.norm(feats.pos - pos) * 1e3
    axis_deg = np.degrees(np.arccos(np.clip(feats.axis @ rot[:, 2], -1.0, 1.0)))
    return centre_mm, axis_deg


def _set_bottle(world, pos, tilt_deg):
    """Teleport the bottle (tilted about -y, as in a pour) and recompute the kinematics."""
    adr = world.model.joint("bottle_free").qposadr[0]
    half = np.radians(tilt_deg) / 2
    world.data.qpos[adr : adr + 3] = pos
    world.data.qpos[adr + 3 : adr + 7] = (np.cos(half), 0.0, -np.sin(half), 0.0)
    mujoco.mj_forward(world.model, world.data)


def test_fused_views_locate_bottle_and_cup(world, extractor):
    frame = extractor.frame
    for name in ("bottle", "cup"):
        feats = frame.objects[name]
        centre_mm, axis_deg = _errors(world, name, feats)
        assert centre_mm <= 5.0, f"{name}: centre off by {centre_mm:.1f} mm"
        assert axis_deg <= 5.0, f"{name}: axis off by {axis_deg:.1f} deg"
        assert feats.points >= MIN_POINTS
        spec = world.object_spec(name)
        np.testing.assert_allclose(feats.extent, [2 * spec.size[0], 2 * spec.size[0], 2 * spec.size[1]], atol=0.005)
        np.testing.assert_allclose(feats.top - feats.bottom, feats.extent[2] * feats.axis, atol=1e-9)
        assert feats.top[2] > feats.bottom[2]
        assert abs(feats.bottom[2]) < 0.005  # standing on the table top (z = 0)
    # Same robot signals as oracle mode.
    oracle = OracleExtractor(world).frame
    for arm in ("left", "right"):
        np.testing.assert_allclose(frame.arms[arm].ee, oracle.arms[arm].ee)
        np.testing.assert_allclose(frame.arms[arm].q, oracle.arms[arm].q)
    assert frame.holding == oracle.holding


def test_a_centroid_would_be_centimetres_off_but_the_fit_is_not(world, extractor):
    images = extractor.capture()
    clouds = extractor.object_clouds(images)
    pos, _ = world.object_pose("bottle")
    assert np.linalg.norm(np.concatenate(clouds["bottle"]).mean(axis=0) - pos) > 0.01
    # Either camera alone already gives a good fit; the table top back-projects onto z = 0.
    for k, image in enumerate(images):
        fit = extractor.fit("bottle", [clouds["bottle"][k]], [image.pos])
        assert np.linalg.norm(fit.pos - pos) < 0.005
        _, seg = extractor.cameras[k].render()
        table = seg[..., 0] == world.model.geom("table").id
        z = frame_points(image, table)[:, 2]
        assert z.max() < 1e-4 and z.min() > -0.0401  # the table box: 4 cm thick, top at z = 0
        assert np.mean(np.abs(z) < 1e-4) > 0.8  # mostly its top


def test_held_bottle_tilting_past_horizontal_keeps_its_axis_sign(world, extractor):
    tcp, _ = world.tcp_pose("right")
    for tilt in (40.0, 80.0, 100.0, 130.0):  # a pour, one camera frame per step
        _set_bottle(world, tcp, tilt)
        extractor.perceive()
        centre_mm, axis_deg = _errors(world, "bottle", extractor.frame.objects["bottle"])
        assert centre_mm <= 5.0 and axis_deg <= 5.0, (tilt, centre_mm, axis_deg)


def test_objects_are_reperceived_every_fifth_tick_only(world, extractor):
    assert extractor.period == 5 and extractor.perceptions == 1 and extractor.last_perceived_tick == 0
    frame = extractor.frame
    refs = frame.refs
    perceived = []
    for _ in range(10):
        world.step()
        before = frame.objects["bottle"].pos
        assert extractor.update() is frame
        if extractor.last_perceived_tick == world.tick:
            perceived.append(world.tick)
        else:
            assert frame.objects["bottle"].pos is before  # kept between camera frames
        assert frame.tick == world.tick
    assert perceived == [5, 10]
    assert extractor.perceptions == 3
    assert frame.refs is refs


def test_an_object_hidden_from_every_camera_keeps_its_last_estimate(world, extractor):
    last = extractor.frame.objects["bottle"].pos.copy()
    _set_bottle(world, np.array([0.0, 0.6, -0.3]), 0.0)  # under the table: no camera sees it
    extractor.perceive()
    bottle = extractor.frame.objects["bottle"]
    assert bottle.points < MIN_POINTS
    np.testing.assert_array_equal(bottle.pos, last)
    assert lost_view(extractor.frame, "bottle", MIN_POINTS) > 0
    assert lost_view(extractor.frame, "cup", MIN_POINTS) < 0
    # Back in view: re-estimated at the new place.
    _set_bottle(world, np.array([0.1, 0.5, 0.15]), 0.0)
    extractor.perceive()
    centre_mm, _ = _errors(world, "bottle", extractor.frame.objects["bottle"])
    assert centre_mm <= 5.0


def test_degraded_segmentation_and_noisy_depth_stay_within_tolerance(world):
    segmenter = NoisySegmenter(LabelSegmenter.for_world(world), erode_px=1, drop=0.2, seed=0)
    with RgbdExtractor(world, segmenter=segmenter, depth_noise=0.002, seed=0) as extractor:
        for name in ("bottle", "cup"):
            centre_mm, axis_deg = _errors(world, name, extractor.frame.objects[name])
            assert centre_mm <= 5.0 and axis_deg <= 5.0, (name, centre_mm, axis_deg)
    assert all(camera.renderer is None for camera in extractor.cameras)
