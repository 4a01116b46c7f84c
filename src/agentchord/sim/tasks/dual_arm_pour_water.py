"""Dual-arm pour water (paper Appendix B).

Grasp cup and bottle (LR, synchronous) -> move the cup to a receiving pose (L) -> move the
bottle to the cup (R) -> pour (R) -> return cup and bottle (LR). The left arm holds the cup
steady in the air while the right arm pours into it.

Scene (ranges are the class constants below): a bottle on the right half of the table and a
cup on the left half, both cylinders; the cup is narrow enough for a side grasp (diameter
<= 5.6 cm in a 6.9 cm finger gap). The library graph (``library/graphs/dual_arm_pour_water.yaml``)
holds the cup at a receiving pose (tool at x 0.0, y 0.62, z 0.15) and pours from 9 cm beside it,
8 cm above its rim, rolling the bottle 95 degrees, as single-arm pour water does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import pouring, resting_on_table, tilt_deg, uniform
from agentchord.sim.world import SimWorld


@dataclass
class DualPourTracker:
    """Success of dual-arm pour water, judged from the episode's frames.

    Event (during the episode): the bottle, held by the right arm, is tilted to a pouring
    orientation with its top within the cup's radius + 1 cm of the cup's axis (in xy) and above
    the cup's rim, while the left arm holds the cup. End state: cup and bottle both upright on the
    table, released by both arms and at rest.

    Attributes:
        pour_tilt_deg: Tilt that counts as pouring.
        upright_deg: Largest tilt of an upright object at the end.
        lateral_margin: Allowed lateral offset of the bottle's top beyond the cup's radius (m).
        poured: Whether the pouring event happened.
        poured_tick: Tick of the first pouring event.
    """

    pour_tilt_deg: float = 70.0
    upright_deg: float = 10.0
    lateral_margin: float = 0.01
    poured: bool = False
    poured_tick: int | None = None

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick for the pouring event."""
        if self.poured:
            return
        if not (frame.is_holding("right", "bottle") and frame.is_holding("left", "cup")):
            return
        if pouring(frame.objects["bottle"], frame.objects["cup"], self.pour_tilt_deg, self.lateral_margin):
            self.poured = True
            self.poured_tick = frame.tick

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge the end state."""
        if not self.poured:
            return Verdict(False, "the bottle never reached a pouring orientation above the held cup")
        for name in ("cup", "bottle"):
            obj = frame.objects[name]
            tilt = tilt_deg(obj.axis)
            if tilt > self.upright_deg:
                return Verdict(False, f"the {name} is not upright (tilt {tilt:.0f} deg)")
            if obj.bottom[2] > 0.01 or not resting_on_table(world, name, frame):
                return Verdict(False, f"the {name} is not standing on the table, released and at rest")
        return Verdict(True, "poured into the held cup, then both placed upright and released")


class DualArmPourWater:
    """The left arm holds a cup up, the right arm pours into it; both are put back."""

    name = "dual_arm_pour_water"
    description = "Left arm lifts a cup to a receiving pose, right arm pours from a bottle into it, both are placed upright."

    #: Sampling ranges (m, kg): bottle and cup instances and their table positions. The cup is
    #: grasped from the side: its diameter must fit the 6.9 cm finger gap with room to spare.
    BOTTLE_RADIUS = (0.024, 0.030)
    BOTTLE_HALF_HEIGHT = (0.08, 0.10)
    BOTTLE_MASS = (0.15, 0.35)
    BOTTLE_XY = ((0.05, 0.13), (0.42, 0.52))
    CUP_RADIUS = (0.024, 0.028)
    CUP_HALF_HEIGHT = (0.042, 0.055)
    CUP_MASS = (0.10, 0.25)
    #: Cup x stays >= -0.11: a cup dropped closer to the left arm's base is regrasped after a
    #: back-off that folds the arm against itself (elbow at its limit), and the grasp fails.
    CUP_XY = ((-0.11, -0.05), (0.50, 0.62))
    FRICTION = (0.8, 1.2)

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: object instances and poses drawn from the stated ranges."""
        bottle = ObjectSpec(
            name="bottle",
            shape="cylinder",
            size=(uniform(rng, self.BOTTLE_RADIUS), uniform(rng, self.BOTTLE_HALF_HEIGHT)),
            mass=uniform(rng, self.BOTTLE_MASS),
            pos=(uniform(rng, self.BOTTLE_XY[0]), uniform(rng, self.BOTTLE_XY[1])),
            rgba=(*rng.uniform(0.1, 0.6, 2), rng.uniform(0.6, 1.0), 1.0),
            friction=uniform(rng, self.FRICTION),
        )
        cup = ObjectSpec(
            name="cup",
            shape="cylinder",
            size=(uniform(rng, self.CUP_RADIUS), uniform(rng, self.CUP_HALF_HEIGHT)),
            mass=uniform(rng, self.CUP_MASS),
            pos=(uniform(rng, self.CUP_XY[0]), uniform(rng, self.CUP_XY[1])),
            rgba=(rng.uniform(0.7, 1.0), *rng.uniform(0.1, 0.5, 2), 1.0),
            friction=uniform(rng, self.FRICTION),
        )
        return SceneSpec(objects=[bottle, cup])

    def success_tracker(self) -> DualPourTracker:
        """A fresh success tracker for one episode."""
        return DualPourTracker()


TASK = DualArmPourWater()
