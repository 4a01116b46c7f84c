"""Feature frames: what counts as a point feature, and how far an object is from level."""

import numpy as np
import pytest

from agentchord.features.extractors import make_extractor
from agentchord.features.frame import level_tilt_deg, tilt_deg
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


def _frame(task: str):
    world = SimWorld(SIM_TASKS[task].sample_scene(np.random.default_rng([0, 0x5CE7E])))
    return make_extractor("oracle", world, lambda arm: False).update()


def test_a_cloths_corners_are_point_features_and_rigid_objects_are_not():
    towel = _frame("fold_towel")
    corners = [name for name in towel.objects if name.startswith("towel_")]
    assert corners and all(towel.objects[name].is_point for name in corners)
    pour = _frame("single_arm_pour_water")
    assert not any(feats.is_point for feats in pour.objects.values())


@pytest.mark.parametrize(("axis", "tilt", "level"), [
    ((0.0, 0.0, 1.0), 0.0, 0.0),
    ((0.0, 0.0, -1.0), 180.0, 0.0),  # upside down: as level as the right way up
    ((1.0, 0.0, 0.0), 90.0, 90.0),
    ((0.0, -np.sqrt(0.5), -np.sqrt(0.5)), 135.0, 45.0),
])
def test_the_tilt_tells_upside_down_from_upright_and_the_level_tilt_does_not(axis, tilt, level):
    assert tilt_deg(axis) == pytest.approx(tilt)
    assert level_tilt_deg(axis) == pytest.approx(level)
