"""Shared fixtures: one small pour-water scene, built once per test that needs it."""

from __future__ import annotations

import numpy as np
import pytest

from agentchord.worlds.sim.tasks import SIM_TASKS


@pytest.fixture
def pour_scene():
    """A seeded single-arm pour-water scene."""
    return SIM_TASKS["single_arm_pour_water"].sample_scene(np.random.default_rng(7))
