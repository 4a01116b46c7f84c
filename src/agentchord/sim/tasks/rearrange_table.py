"""Rearrange table (paper Appendix B): put the fork and the spoon beside the plate.

Grasp fork and spoon (LR, synchronous) -> lift them (LR) -> place them beside the plate (LR).
Success: both lie in their target regions beside the plate (fork left, spoon right) with the
correct orientation (long axis parallel to the table's y axis).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import FeatureFrame, level_tilt_deg
from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import resting_on_table, uniform
from agentchord.sim.world import SimWorld

#: Target of each utensil's centre, relative to the plate's centre (m), and the arm that moves it.
TARGET_OFFSET = {"fork": (-0.17, 0.0), "spoon": (0.17, 0.0)}


def long_axis_yaw_deg(quat: np.ndarray) -> float:
    """World yaw (deg, in [0, 180)) of a lying box's long axis, its local x, from its quat (w, x, y, z).

    A box is symmetric under a half turn, so yaws are taken modulo 180 degrees.
    """
    w, x, y, z = (float(v) for v in quat)
    axis_x = 1.0 - 2.0 * (y * y + z * z)
    axis_y = 2.0 * (x * y + w * z)
    return float(np.degrees(np.arctan2(axis_y, axis_x))) % 180.0


def yaw_error_deg(quat: np.ndarray, target_deg: float) -> float:
    """Smallest angle (deg, in [0, 90]) between a box's long axis and a target yaw, modulo 180."""
    diff = (long_axis_yaw_deg(quat) - target_deg) % 180.0
    return float(min(diff, 180.0 - diff))


@dataclass
class RearrangeTracker:
    """Success of rearrange table, judged from the end state.

    Each utensil must lie flat on the table, released and at rest, its centre within
    ``pos_tol`` of its target beside the plate (where the plate is at the end) and its
    long axis within ``yaw_tol_deg`` of the table's y axis.

    Attributes:
        pos_tol: Lateral tolerance of a utensil's centre (m).
        yaw_tol_deg: Tolerance of a utensil's long axis to the y axis (deg).
        flat_tol_deg: Largest tilt of a utensil's thin axis from vertical (deg).
    """

    pos_tol: float = 0.03
    yaw_tol_deg: float = 20.0
    flat_tol_deg: float = 15.0
    target_yaw_deg: float = 90.0

    def observe(self, frame: FeatureFrame) -> None:
        """Nothing to watch during the episode: success is a property of the end state."""

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge the end state."""
        plate = frame.objects["plate"]
        for name, (dx, dy) in TARGET_OFFSET.items():
            obj = frame.objects[name]
            target = plate.pos[:2] + np.array([dx, dy])
            error = float(np.linalg.norm(obj.pos[:2] - target))
            if error > self.pos_tol:
                return Verdict(False, f"the {name} is {100 * error:.1f} cm from its target beside the plate")
            yaw_err = yaw_error_deg(obj.quat, self.target_yaw_deg)
            if yaw_err > self.yaw_tol_deg:
                return Verdict(False, f"the {name} is {yaw_err:.0f} deg off the y axis")
            tilt = level_tilt_deg(obj.axis)
            if tilt > self.flat_tol_deg:
                return Verdict(False, f"the {name} is not lying flat (tilt {tilt:.0f} deg)")
            if not resting_on_table(world, name, frame):
                return Verdict(False, f"the {name} is not lying on the table, released and at rest")
        return Verdict(True, "fork and spoon placed beside the plate, parallel to the y axis")


class RearrangeTable:
    """Both arms move a fork and a spoon to their places beside a plate."""

    name = "rearrange_table"
    description = "Left arm moves the fork, right arm the spoon, beside the plate, parallel to the y axis."

    #: Sampling ranges (m, kg, rad). Plate: a heavy flat cylinder near the table centre.
    PLATE_RADIUS = (0.08, 0.10)
    PLATE_HALF_HEIGHT = (0.008, 0.012)
    PLATE_MASS = (0.3, 0.5)
    PLATE_XY = ((-0.03, 0.03), (0.56, 0.64))
    #: Utensils: thin boxes lying flat (half-sizes: length, width, thickness).
    UTENSIL_HALF_LENGTH = (0.07, 0.09)
    UTENSIL_HALF_WIDTH = (0.0075, 0.0125)
    UTENSIL_HALF_THICKNESS = (0.004, 0.006)
    UTENSIL_MASS = (0.03, 0.07)
    #: Fork on the left half, spoon on the right half (mirrored in x). Nearer than ~15 cm to an
    #: arm's base (x = -/+0.469) a top-down tool cannot reach the table.
    FORK_XY = ((-0.32, -0.22), (0.46, 0.74))
    SPOON_XY = ((0.22, 0.32), (0.46, 0.74))
    #: Yaw of the long axis from the x axis (the arms' reach direction).
    UTENSIL_YAW = (np.radians(-60.0), np.radians(60.0))
    FRICTION = (0.8, 1.2)

    def _utensil(self, rng: np.random.Generator, name: str, xy: tuple, rgba: tuple) -> ObjectSpec:
        return ObjectSpec(
            name=name,
            shape="box",
            size=(
                uniform(rng, self.UTENSIL_HALF_LENGTH),
                uniform(rng, self.UTENSIL_HALF_WIDTH),
                uniform(rng, self.UTENSIL_HALF_THICKNESS),
            ),
            mass=uniform(rng, self.UTENSIL_MASS),
            pos=(uniform(rng, xy[0]), uniform(rng, xy[1])),
            yaw=uniform(rng, self.UTENSIL_YAW),
            rgba=rgba,
            friction=uniform(rng, self.FRICTION),
        )

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: object instances and poses drawn from the stated ranges."""
        plate = ObjectSpec(
            name="plate",
            shape="cylinder",
            size=(uniform(rng, self.PLATE_RADIUS), uniform(rng, self.PLATE_HALF_HEIGHT)),
            mass=uniform(rng, self.PLATE_MASS),
            pos=(uniform(rng, self.PLATE_XY[0]), uniform(rng, self.PLATE_XY[1])),
            rgba=(*rng.uniform(0.85, 1.0, 3), 1.0),
            friction=uniform(rng, self.FRICTION),
        )
        metal = tuple(rng.uniform(0.55, 0.8, 3))
        fork = self._utensil(rng, "fork", self.FORK_XY, (*metal, 1.0))
        spoon = self._utensil(rng, "spoon", self.SPOON_XY, (metal[0] * 0.6, metal[1] * 0.6, min(1.0, metal[2] * 1.2), 1.0))
        return SceneSpec(objects=[plate, fork, spoon])

    def success_tracker(self) -> RearrangeTracker:
        """A fresh success tracker for one episode."""
        return RearrangeTracker()


TASK = RearrangeTable()
