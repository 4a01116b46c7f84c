"""Blocks and cup: an open scene for instructions the task library has no graph for.

A red block, a blue block and a wide open cup (a compound body: a floor and four walls)
on the table. No fixed instruction: "put the red block into the cup", "stack the red
block on the blue block", ... are planned by the agents, and success is judged from the
goal they planned for (:class:`~agentchord.sim.tasks.goal_tracker.GoalTracker`).
"""

from __future__ import annotations

import numpy as np

from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.sim.tasks.base import uniform
from agentchord.sim.tasks.goal_tracker import GoalTracker

#: Floor and wall thickness of the cup (m).
CUP_FLOOR = 0.006
CUP_WALL = 0.005


def cup_parts(half_width: float, height: float) -> tuple:
    """Box parts (half-sizes, centre) of an open square cup centred on its bounding box."""
    hz = 0.5 * height
    wall_h = 0.5 * (height - CUP_FLOOR)
    wall_z = -hz + CUP_FLOOR + wall_h
    t = 0.5 * CUP_WALL
    return (
        ((half_width, half_width, 0.5 * CUP_FLOOR), (0.0, 0.0, -hz + 0.5 * CUP_FLOOR)),
        ((half_width, t, wall_h), (0.0, half_width - t, wall_z)),
        ((half_width, t, wall_h), (0.0, -(half_width - t), wall_z)),
        ((t, half_width - CUP_WALL, wall_h), (half_width - t, 0.0, wall_z)),
        ((t, half_width - CUP_WALL, wall_h), (-(half_width - t), 0.0, wall_z)),
    )


class BlocksAndCup:
    """Two blocks and a cup; the goal comes from the instruction."""

    name = "blocks_and_cup"
    description = "A red block, a blue block and an open cup: plan any pick-and-place instruction (e.g. 'put the red block into the cup')."
    #: Success is judged from the planned goal, not by a fixed check.
    goal_defined = True
    regions: dict = {}

    RED_HALF = (0.018, 0.021)
    BLUE_HALF = (0.022, 0.026)
    BLOCK_MASS = (0.03, 0.08)
    RED_XY = ((-0.14, -0.07), (0.44, 0.52))
    BLUE_XY = ((0.00, 0.05), (0.40, 0.46))
    CUP_HALF = (0.044, 0.048)
    CUP_HEIGHT = (0.05, 0.06)
    CUP_MASS = (0.15, 0.25)
    CUP_XY = ((-0.03, 0.03), (0.58, 0.63))
    YAW = (np.radians(-20.0), np.radians(20.0))
    FRICTION = (0.9, 1.2)

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: sizes, masses and poses from the stated ranges."""

        def block(name: str, half: tuple[float, float], xy, rgba) -> ObjectSpec:
            h = uniform(rng, half)
            return ObjectSpec(
                name=name, shape="box", size=(h, h, h), mass=uniform(rng, self.BLOCK_MASS),
                pos=(uniform(rng, xy[0]), uniform(rng, xy[1])), yaw=uniform(rng, self.YAW), rgba=rgba,
                friction=uniform(rng, self.FRICTION),
            )

        half, height = uniform(rng, self.CUP_HALF), uniform(rng, self.CUP_HEIGHT)
        cup = ObjectSpec(
            name="cup", shape="box", size=(half, half, 0.5 * height), mass=uniform(rng, self.CUP_MASS),
            pos=(uniform(rng, self.CUP_XY[0]), uniform(rng, self.CUP_XY[1])), yaw=uniform(rng, self.YAW),
            rgba=(0.92, 0.92, 0.9, 1.0), friction=uniform(rng, self.FRICTION), parts=cup_parts(half, height),
        )
        red = block("red_block", self.RED_HALF, self.RED_XY, (0.85, 0.12, 0.1, 1.0))
        blue = block("blue_block", self.BLUE_HALF, self.BLUE_XY, (0.12, 0.25, 0.85, 1.0))
        return SceneSpec(objects=[red, blue, cup])

    def success_tracker(self) -> GoalTracker:
        """A tracker that judges the goal it is given (:meth:`GoalTracker.expect`)."""
        return GoalTracker()


TASK = BlocksAndCup()
