"""Single-arm pour water (paper Appendix B): grasp bottle, move to cup, pour, place bottle."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import pouring, resting_on_table, tilt_deg, uniform
from agentchord.sim.world import SimWorld


@dataclass
class PourTracker:
    """Success of single-arm pour water, judged from the episode's frames.

    The bottle must reach a pouring orientation with its mouth above the cup
    (an event during the episode), and at the end stand upright on the table,
    released and at rest.

    Attributes:
        pour_tilt_deg: Tilt that counts as pouring.
        poured: Whether the pouring event happened.
        poured_tick: Tick of the first pouring event.
    """

    pour_tilt_deg: float = 70.0
    poured: bool = False
    poured_tick: int | None = None

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick for the pouring event."""
        if self.poured:
            return
        if frame.is_holding("right", "bottle") and pouring(frame.objects["bottle"], frame.objects["cup"], self.pour_tilt_deg):
            self.poured = True
            self.poured_tick = frame.tick

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge the end state."""
        bottle = frame.objects["bottle"]
        tilt = tilt_deg(bottle.axis)
        if not self.poured:
            return Verdict(False, "the bottle never reached a pouring orientation above the cup")
        if tilt > 10.0:
            return Verdict(False, f"the bottle is not upright (tilt {tilt:.0f} deg)")
        if bottle.bottom[2] > 0.01 or not resting_on_table(world, "bottle", frame):
            return Verdict(False, "the bottle is not standing on the table, released and at rest")
        return Verdict(True, "poured, then placed upright and released")


class SingleArmPourWater:
    """Pour from a bottle into a cup with the right arm, then put the bottle down."""

    name = "single_arm_pour_water"
    description = "Right arm grasps a bottle, pours into a cup, places the bottle upright."

    #: Sampling ranges (m, kg): bottle and cup instances and their table positions.
    BOTTLE_RADIUS = (0.024, 0.030)
    BOTTLE_HALF_HEIGHT = (0.08, 0.10)
    BOTTLE_MASS = (0.15, 0.35)
    BOTTLE_XY = ((0.04, 0.12), (0.48, 0.60))
    # Narrow enough for the other gripper (6.9 cm) to set a knocked-over cup upright.
    CUP_RADIUS = (0.026, 0.030)
    CUP_HALF_HEIGHT = (0.04, 0.055)
    CUP_MASS = (0.15, 0.30)
    CUP_XY = ((-0.14, -0.06), (0.52, 0.64))

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: object instances and poses drawn from the stated ranges."""

        bottle = ObjectSpec(
            name="bottle",
            shape="cylinder",
            size=(uniform(rng, self.BOTTLE_RADIUS), uniform(rng, self.BOTTLE_HALF_HEIGHT)),
            mass=uniform(rng, self.BOTTLE_MASS),
            pos=(uniform(rng, self.BOTTLE_XY[0]), uniform(rng, self.BOTTLE_XY[1])),
            rgba=(*rng.uniform(0.1, 0.6, 2), rng.uniform(0.6, 1.0), 1.0),
            friction=uniform(rng, (0.8, 1.2)),
        )
        cup = ObjectSpec(
            name="cup",
            shape="cylinder",
            size=(uniform(rng, self.CUP_RADIUS), uniform(rng, self.CUP_HALF_HEIGHT)),
            mass=uniform(rng, self.CUP_MASS),
            pos=(uniform(rng, self.CUP_XY[0]), uniform(rng, self.CUP_XY[1])),
            rgba=(rng.uniform(0.7, 1.0), *rng.uniform(0.1, 0.5, 2), 1.0),
            friction=uniform(rng, (0.8, 1.2)),
        )
        return SceneSpec(objects=[bottle, cup])

    def success_tracker(self) -> PourTracker:
        """A fresh success tracker for one episode."""
        return PourTracker()


TASK = SingleArmPourWater()
