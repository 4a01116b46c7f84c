"""Fruit and bowl: a worked example of a scene added from outside the package (docs/scenes.md).

An apple, a lime and a stepped bowl on the table, and a "board" region (a cutting board drawn on
the table's left). No fixed instruction: "put the apple into the bowl", "put the lime on the
board", ... are planned by the agents, and success is judged from the goal they planned for.

Register it without editing AgentChord, then check and run it::

    export AGENTCHORD_TASKS=examples/scenes/fruit_and_bowl.py
    agentchord tasks --details fruit_and_bowl
    agentchord run fruit_and_bowl --instruction "put the apple into the bowl" --seed 0
"""

from __future__ import annotations

import numpy as np

from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.sim.tasks.base import uniform
from agentchord.sim.tasks.goal_tracker import GoalTracker

#: Bowl construction (m): floor thickness, the lower tier's wall thickness (its top is the ledge
#: where the bowl widens) and height, and the upper tier's wall thickness.
BOWL_FLOOR = 0.006
BOWL_LOWER_WALL = 0.012
BOWL_LEDGE = 0.022
BOWL_UPPER_WALL = 0.005

#: The cutting board: a named region of the table (centre (x, y) and radius, m).
BOARD_XY = (-0.17, 0.62)
BOARD_RADIUS = 0.04


def bowl_parts(half_width: float, height: float) -> tuple:
    """Box parts (half-sizes, centre) of a two-tier bowl centred on its bounding box.

    MuJoCo boxes in a compound body cannot be rotated here, so a round bowl is approximated by
    two square tiers: thick low walls around a small floor, and thin walls above them. The
    cavity widens at the ledge between the tiers, as a bowl widens towards its rim.

    Args:
        half_width: Half the bowl's outer width (m), the same along x and y.
        height: The bowl's full height (m).

    Returns:
        The parts, as :attr:`ObjectSpec.parts` takes them: a floor, four lower walls, four upper walls.
    """
    hz = 0.5 * height
    floor_z = -hz + 0.5 * BOWL_FLOOR

    def ring(thickness: float, z_low: float, z_high: float) -> tuple:
        # Four walls flush with the outer edge; the x walls stop short of the y walls' ends.
        t, h, zc = 0.5 * thickness, 0.5 * (z_high - z_low), 0.5 * (z_low + z_high)
        return (
            ((half_width, t, h), (0.0, half_width - t, zc)),
            ((half_width, t, h), (0.0, -(half_width - t), zc)),
            ((t, half_width - thickness, h), (half_width - t, 0.0, zc)),
            ((t, half_width - thickness, h), (-(half_width - t), 0.0, zc)),
        )

    floor = ((half_width, half_width, 0.5 * BOWL_FLOOR), (0.0, 0.0, floor_z))
    lower = ring(BOWL_LOWER_WALL, -hz + BOWL_FLOOR, -hz + BOWL_LEDGE)
    upper = ring(BOWL_UPPER_WALL, -hz + BOWL_LEDGE, hz)
    return (floor, *lower, *upper)


class FruitAndBowl:
    """An apple, a lime and a bowl; the goal comes from the instruction (or a goal file)."""

    name = "fruit_and_bowl"
    description = "An apple, a lime and a bowl, a cutting board region on the left: plan any pick-and-place instruction."
    #: No fixed check: ``run`` gives the tracker the goal that was planned (GoalTracker.expect).
    goal_defined = True
    #: Named regions the agents see: name -> (centre, radius, words that also name it).
    regions = {"board": (BOARD_XY, BOARD_RADIUS, "cutting board area on the left of the table")}

    #: Sampling ranges (m, kg, rad). Each object lies within reach of the arm on its side (the
    #: planner picks that arm); the bowl sits between the arms, where either can reach into it.
    APPLE_RADIUS = (0.023, 0.026)
    APPLE_HALF_HEIGHT = (0.021, 0.024)
    APPLE_MASS = (0.08, 0.15)
    APPLE_XY = ((0.08, 0.14), (0.44, 0.52))
    LIME_RADIUS = (0.018, 0.021)
    LIME_HALF_HEIGHT = (0.017, 0.020)
    LIME_MASS = (0.04, 0.08)
    LIME_XY = ((-0.15, -0.10), (0.42, 0.50))
    # Under 10 cm wide (knowledge.ONE_HAND_WIDTH): wider, the planner would lift it with both arms.
    BOWL_HALF = (0.045, 0.048)
    BOWL_HEIGHT = (0.045, 0.052)
    BOWL_MASS = (0.25, 0.40)
    BOWL_XY = ((-0.02, 0.02), (0.58, 0.62))
    FRICTION = (0.9, 1.2)

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: sizes, masses and poses drawn from the stated ranges.

        Args:
            rng: The trial's seeded generator: the same seed gives the same scene.

        Returns:
            The objects to build on the table.
        """

        def fruit(name: str, radius, half_height, mass, xy, rgba) -> ObjectSpec:
            # A squat cylinder: the simulator has boxes and cylinders only, no spheres.
            return ObjectSpec(
                name=name, shape="cylinder", size=(uniform(rng, radius), uniform(rng, half_height)),
                mass=uniform(rng, mass), pos=(uniform(rng, xy[0]), uniform(rng, xy[1])), rgba=rgba,
                friction=uniform(rng, self.FRICTION),
            )

        # Draw in a fixed order: a new draw inserted earlier would change every later object of a seed.
        apple = fruit("apple", self.APPLE_RADIUS, self.APPLE_HALF_HEIGHT, self.APPLE_MASS, self.APPLE_XY, (0.85, 0.1, 0.1, 1.0))
        lime = fruit("lime", self.LIME_RADIUS, self.LIME_HALF_HEIGHT, self.LIME_MASS, self.LIME_XY, (0.2, 0.7, 0.15, 1.0))
        half, height = uniform(rng, self.BOWL_HALF), uniform(rng, self.BOWL_HEIGHT)
        bowl = ObjectSpec(
            # A compound body: ``size`` is the bounding box, what features (extent, top) describe.
            name="bowl", shape="box", size=(half, half, 0.5 * height), mass=uniform(rng, self.BOWL_MASS),
            pos=(uniform(rng, self.BOWL_XY[0]), uniform(rng, self.BOWL_XY[1])), rgba=(0.92, 0.92, 0.9, 1.0),
            friction=uniform(rng, self.FRICTION), parts=bowl_parts(half, height),
        )
        return SceneSpec(objects=[apple, lime, bowl])

    def success_tracker(self) -> GoalTracker:
        """A fresh tracker for one episode; it judges whichever goal it is given."""
        return GoalTracker()


TASK = FruitAndBowl()
