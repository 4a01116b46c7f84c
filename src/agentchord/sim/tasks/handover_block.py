"""Handover block (paper Appendix B): hand a block from the left arm to the right, then place it.

Grasp block (L) -> move block to the handover pose (L) -> hand over from left to right (LR) ->
place block (R). Success: the block was transferred between the arms (both held it, then the
right arm alone) and ends upright in the target region on the right half of the table, released
and at rest, without ever having been left on the floor.

The block is a tall square bar. Two side grasps on one upright bar, approaching from opposite
sides, need their tool centres about 11 cm apart in height: each gripper's fingers are 6 cm tall
and the IK keeps the two grippers' collision capsules (4.5 cm radius) 2 cm apart. So the left arm
holds the bar high (85% of its height) and the right arm takes it low (20%), which a bar 18-20 cm
tall allows with a margin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import resting_on_table, tilt_deg, uniform
from agentchord.sim.world import SimWorld

#: Centre (x, y) of the target region on the right half of the table (m); the library
#: graph's place action and its sub-goal constraint use the same numbers.
TARGET_XY = (0.12, 0.45)
#: Radius of the target region (m).
TARGET_RADIUS = 0.04
#: Below this height (m) the block has left the table: it lies on the floor.
FLOOR_Z = -0.1


@dataclass
class HandoverTracker:
    """Success of handover block, judged from the episode's frames.

    Events during the episode: the handover (a tick where both arms hold the block,
    then a later tick where the right arm alone holds it off the table) and any visit
    of the block to the floor. End state: upright in the target region, released, at rest.

    Attributes:
        target_xy: Centre of the target region (m).
        radius: Radius of the target region (m).
        upright_tol_deg: Largest tilt of the placed block (deg).
        both_held: Whether both arms ever held the block at once.
        transferred: Whether the right arm held it alone, off the table, after both held it.
        transferred_tick: Tick of the first such frame.
        on_floor: Whether the block ever fell below the table (to the floor).
    """

    target_xy: tuple[float, float] = TARGET_XY
    radius: float = TARGET_RADIUS
    upright_tol_deg: float = 10.0
    both_held: bool = False
    transferred: bool = False
    transferred_tick: int | None = None
    on_floor: bool = False

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick for the handover and for a fall to the floor."""
        block = frame.objects["block"]
        if block.pos[2] < FLOOR_Z:
            self.on_floor = True
        left, right = frame.is_holding("left", "block"), frame.is_holding("right", "block")
        if left and right:
            self.both_held = True
        elif right and self.both_held and not self.transferred and min(block.bottom[2], block.top[2]) > 0.02:
            self.transferred = True
            self.transferred_tick = frame.tick

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge the end state."""
        block = frame.objects["block"]
        if self.on_floor:
            return Verdict(False, "the block fell to the floor")
        if not self.transferred:
            return Verdict(False, "the block was never handed over from the left arm to the right arm")
        tilt = tilt_deg(block.axis)
        if tilt > self.upright_tol_deg:
            return Verdict(False, f"the block is not upright (tilt {tilt:.0f} deg)")
        error = float(np.linalg.norm(block.pos[:2] - np.asarray(self.target_xy)))
        if error > self.radius:
            return Verdict(False, f"the block is {100 * error:.1f} cm from the target (region radius {100 * self.radius:.0f} cm)")
        if block.bottom[2] > 0.01 or not resting_on_table(world, "block", frame):
            return Verdict(False, "the block is not standing on the table, released and at rest")
        return Verdict(True, "handed over from left to right, then placed upright in the target region")


class HandoverBlock:
    """The left arm picks up a block and hands it to the right arm, which places it in a target region."""

    name = "handover_block"
    description = "Left arm grasps a block, hands it over to the right arm, which places it in the target region."

    #: Sampling ranges (m, kg, rad): a tall square bar standing on the left half of the table.
    BLOCK_HALF_WIDTH = (0.018, 0.022)
    BLOCK_HALF_HEIGHT = (0.09, 0.10)
    BLOCK_MASS = (0.05, 0.15)
    BLOCK_XY = ((-0.20, -0.12), (0.42, 0.58))
    BLOCK_YAW = (np.radians(-30.0), np.radians(30.0))
    FRICTION = (0.8, 1.2)
    #: The target region (fixed: the library graph names it).
    TARGET_XY = TARGET_XY
    TARGET_RADIUS = TARGET_RADIUS
    #: Named regions the agents see: name -> (centre, radius, words).
    regions = {"target": (TARGET_XY, TARGET_RADIUS, "target region on the right half of the table")}

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: the block's size, mass, colour, friction and pose from the stated ranges."""
        block = ObjectSpec(
            name="block",
            shape="box",
            size=(uniform(rng, self.BLOCK_HALF_WIDTH), uniform(rng, self.BLOCK_HALF_WIDTH), uniform(rng, self.BLOCK_HALF_HEIGHT)),
            mass=uniform(rng, self.BLOCK_MASS),
            pos=(uniform(rng, self.BLOCK_XY[0]), uniform(rng, self.BLOCK_XY[1])),
            yaw=uniform(rng, self.BLOCK_YAW),
            rgba=(rng.uniform(0.7, 1.0), rng.uniform(0.4, 0.7), rng.uniform(0.0, 0.3), 1.0),
            friction=uniform(rng, self.FRICTION),
        )
        return SceneSpec(objects=[block])

    def success_tracker(self) -> HandoverTracker:
        """A fresh success tracker for one episode."""
        return HandoverTracker(target_xy=self.TARGET_XY, radius=self.TARGET_RADIUS)


TASK = HandoverBlock()
