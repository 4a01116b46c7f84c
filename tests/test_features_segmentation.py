"""Segmentation: the world's own labels, the degraded segmenter, and the Segmenter protocol."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from agentchord.features.rgbd import frame_points
from agentchord.features.segmentation import (
    LabelSegmenter,
    NoisySegmenter,
    SegmentationUnavailableError,
    Segmenter,
    erode,
)
from agentchord.sim.world import SimWorld


@pytest.fixture
def rendered(pour_scene):
    world = SimWorld(pour_scene)
    camera = world.open_camera("front", width=160, height=120)
    try:
        _, seg = camera.render()
        yield world, camera.capture(), seg
    finally:
        camera.close()


def test_label_segmenter_masks_hold_only_that_objects_pixels(rendered):
    world, image, seg = rendered
    segmenter = LabelSegmenter.for_world(world)
    assert isinstance(segmenter, Segmenter)
    masks = segmenter.masks(image)
    assert set(masks) == set(world.object_names)
    is_geom = seg[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM)
    for name, mask in masks.items():
        geom = world.model.geom(name).id
        assert mask.shape == image.depth.shape and mask.dtype == bool
        assert mask.sum() > 30, f"{name} not seen by the front camera"
        # Exactly the pixels of the object's geom: none of the table, the robot or the other object.
        np.testing.assert_array_equal(mask, is_geom & (seg[..., 0] == geom))
    bottle, cup = masks["bottle"], masks["cup"]
    assert not (bottle & cup).any()
    # The masked depth lies on the object: within its radius + half-height of its centre.
    for name, mask in masks.items():
        pos, _ = world.object_pose(name)
        spec = world.object_spec(name)
        reach = np.hypot(spec.size[0], spec.size[1]) + 1e-3
        assert np.linalg.norm(frame_points(image, mask) - pos, axis=1).max() < reach


def test_a_frame_without_labels_needs_a_segmenter(rendered):
    world, image, _ = rendered
    image.labels = None
    with pytest.raises(SegmentationUnavailableError, match="no segmentation of its own"):
        LabelSegmenter.for_world(world).masks(image)


def test_single_pass_render_matches_the_renderers_own_depth_and_segmentation(rendered):
    world, image, seg_single = rendered
    renderer = mujoco.Renderer(world.model, 120, 160)
    try:
        renderer.update_scene(world.data, camera="front", scene_option=_no_sites())
        renderer.enable_depth_rendering()
        depth = renderer.render()
        renderer.enable_segmentation_rendering()
        seg = renderer.render()
    finally:
        renderer.close()
    np.testing.assert_array_equal(seg_single, seg)
    np.testing.assert_allclose(image.depth, depth, rtol=1e-5)


def _no_sites() -> mujoco.MjvOption:
    option = mujoco.MjvOption()
    option.sitegroup[:] = 0
    return option


def test_noisy_segmenter_only_removes_pixels(rendered):
    world, image, _ = rendered
    base = LabelSegmenter.for_world(world)
    clean = base.masks(image)
    noisy = NoisySegmenter(base, erode_px=1, drop=0.3, seed=3).masks(image)
    for name in clean:
        assert not (noisy[name] & ~clean[name]).any()
        assert 0.3 * clean[name].sum() < noisy[name].sum() < 0.75 * clean[name].sum()
    missed = NoisySegmenter(base, erode_px=0, miss=1.0).masks(image)
    assert all(not m.any() for m in missed.values())


def test_erode_removes_the_border():
    mask = np.zeros((7, 7), dtype=bool)
    mask[1:6, 1:6] = True
    once = erode(mask)
    assert once.sum() == 9 and once[2:5, 2:5].all()
    assert erode(mask, 3).sum() == 0
