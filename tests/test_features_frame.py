"""Feature frames: what counts as a point feature."""

import numpy as np

from agentchord.features.extractors import make_extractor
from agentchord.worlds.sim.tasks import SIM_TASKS
from agentchord.worlds.sim.world import SimWorld


def _frame(task: str):
    world = SimWorld(SIM_TASKS[task].sample_scene(np.random.default_rng([0, 0x5CE7E])))
    return make_extractor("oracle", world, lambda arm: False).update()


def test_a_cloths_corners_are_point_features_and_rigid_objects_are_not():
    towel = _frame("fold_towel")
    corners = [name for name in towel.objects if name.startswith("towel_")]
    assert corners and all(towel.objects[name].is_point for name in corners)
    pour = _frame("single_arm_pour_water")
    assert not any(feats.is_point for feats in pour.objects.values())
