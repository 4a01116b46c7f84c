"""What every simulated task provides: a seeded scene sampler and a success check.

A task knows how to sample one trial's scene from a seeded generator (object
instances within a category, table poses) and how to judge success from the
feature frames of the episode. The task *graph* lives in the task library
(:mod:`agentchord.library`); this package is the world side only.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from agentchord.features.frame import FeatureFrame, ObjectFeatures, tilt_deg  # re-exported for the task modules
from agentchord.harness import SuccessTracker
from agentchord.sim.scene import SceneSpec
from agentchord.sim.world import SimWorld


class SimTask(Protocol):
    """A simulated task."""

    name: str
    description: str
    #: Named regions of the table the agents may use (optional): name -> (centre, radius, words).
    regions: dict[str, tuple[tuple[float, float], float, str]]

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene, drawn from the task's stated ranges."""

    def success_tracker(self) -> SuccessTracker:
        """A fresh success tracker for one episode."""


def uniform(rng: np.random.Generator, bounds: tuple[float, float]) -> float:
    """A float drawn uniformly from ``bounds``."""
    return float(rng.uniform(*bounds))


def pouring(bottle: ObjectFeatures, cup: ObjectFeatures, min_tilt_deg: float = 70.0, lateral_margin: float = 0.01) -> bool:
    """Whether a vessel pours into a cup now: tilted at least ``min_tilt_deg``, its mouth (top
    point) above the cup's rim and within the cup's radius + ``lateral_margin`` of its axis in xy."""
    if tilt_deg(bottle.axis) < min_tilt_deg:
        return False
    lateral = float(np.linalg.norm((bottle.top - cup.top)[:2]))
    return lateral <= 0.5 * float(cup.extent[0]) + lateral_margin and bottle.top[2] > cup.top[2]


def resting_on_table(world: SimWorld, name: str, frame: FeatureFrame, max_speed: float = 0.02) -> bool:
    """Whether an object stands on the table, released by both arms and at rest."""
    held = any(obj == name for _, obj in frame.holding)
    return not held and world.on_table(name) and world.object_velocity(name) <= max_speed
