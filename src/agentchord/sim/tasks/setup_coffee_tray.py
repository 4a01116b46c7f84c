"""Setup coffee tray (paper Appendix B): put the coffee capsule into the tray, move the tray forward.

Grasp coffee capsule (L) -> place it into the tray (L) -> grasp the tray by its two end handles
(LR, synchronous) -> place the tray forward (LR, synchronous). Success: the capsule rests inside
the tray's rim and the tray lies flat at the designated forward position, released and at rest.

The tray is a compound body (:attr:`ObjectSpec.parts`): a flat base, four thin rim walls and a
handle tab at each short end, the tabs level with the rim top. Its ``size`` is the bounding box
(handles included), so its features (``extent``, ``top``, ``bottom``) stay meaningful.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.sim.scene import ObjectSpec, SceneSpec
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import tilt_deg, uniform
from agentchord.sim.world import SimWorld

#: Where the tray must end (x, y, m): the designated forward position, 10-16 cm ahead of its start.
TRAY_TARGET = (0.0, 0.67)
#: Tray construction (m): base and wall thickness, handle tab length (along x) and thickness.
#: A 2 cm tab gives the finger pads a tall face: with a 1.2 cm one, pad contacts flickered more.
BASE_THICKNESS = 0.005
WALL_THICKNESS = 0.006
HANDLE_LENGTH = 0.05
HANDLE_THICKNESS = 0.02


def tray_parts(half_length: float, half_width: float, height: float, handle_width: float):
    """Box parts (half-sizes, centre) of a tray centred on its bounding box.

    The base is ``2 half_length`` x ``2 half_width``; the rim walls rise to ``height``;
    a handle tab sticks out ``HANDLE_LENGTH`` from each short wall, flush with the rim top.
    """
    hz = 0.5 * height
    wall_h = 0.5 * (height - BASE_THICKNESS)
    wall_z = -hz + BASE_THICKNESS + wall_h
    t = 0.5 * WALL_THICKNESS
    handle_x = half_length + 0.5 * HANDLE_LENGTH
    handle_z = hz - 0.5 * HANDLE_THICKNESS
    return (
        ((half_length, half_width, 0.5 * BASE_THICKNESS), (0.0, 0.0, -hz + 0.5 * BASE_THICKNESS)),
        ((half_length, t, wall_h), (0.0, half_width - t, wall_z)),
        ((half_length, t, wall_h), (0.0, -(half_width - t), wall_z)),
        ((t, half_width - WALL_THICKNESS, wall_h), (half_length - t, 0.0, wall_z)),
        ((t, half_width - WALL_THICKNESS, wall_h), (-(half_length - t), 0.0, wall_z)),
        ((0.5 * HANDLE_LENGTH, 0.5 * handle_width, 0.5 * HANDLE_THICKNESS), (handle_x, 0.0, handle_z)),
        ((0.5 * HANDLE_LENGTH, 0.5 * handle_width, 0.5 * HANDLE_THICKNESS), (-handle_x, 0.0, handle_z)),
    )


def tray_inner_half(spec: ObjectSpec) -> tuple[float, float]:
    """Half-sizes (x, y) of the space inside a tray's rim, from its base part."""
    base_half = spec.parts[0][0]
    return base_half[0] - WALL_THICKNESS, base_half[1] - WALL_THICKNESS


def in_tray_frame(world: SimWorld, tray: str, point: np.ndarray) -> np.ndarray:
    """``point`` (world frame) in the tray's body frame (origin at its bounding-box centre)."""
    pos, rot = world.object_pose(tray)
    return rot.T @ (np.asarray(point, dtype=float) - pos)


def capsule_in_tray(world: SimWorld, capsule: str = "capsule", tray: str = "tray") -> tuple[bool, str]:
    """Whether the capsule rests inside the tray's rim (checked in the tray's frame), and why not."""
    spec_tray, spec_cap = world.object_spec(tray), world.object_spec(capsule)
    inner_x, inner_y = tray_inner_half(spec_tray)
    local = in_tray_frame(world, tray, world.object_pose(capsule)[0])
    # The capsule's centre within the inner footprint (it may lean on a wall, never over it).
    if abs(local[0]) > inner_x or abs(local[1]) > inner_y:
        return False, f"the capsule is outside the tray's rim (tray frame x {100 * local[0]:.1f} cm, y {100 * local[1]:.1f} cm)"
    # Resting on the tray's base, not perched on the rim or lifted above it.
    floor = -0.5 * spec_tray.height + BASE_THICKNESS
    if not floor - 0.005 <= local[2] <= floor + max(spec_cap.size) + 0.01:
        return False, f"the capsule is not resting on the tray's base (height {100 * (local[2] - floor):.1f} cm above it)"
    return True, "the capsule rests inside the tray"


@dataclass
class CoffeeTrayTracker:
    """Success of setup coffee tray, judged from the end state.

    The capsule must rest inside the tray's rim (in the tray's frame), the tray must lie
    flat on the table within ``pos_tol`` of :data:`TRAY_TARGET`, and neither may be held
    or moving.

    Attributes:
        pos_tol: Lateral tolerance of the tray's centre to its forward target (m).
        flat_tol_deg: Largest tilt of the tray (deg).
        max_speed: Largest speed of the tray or the capsule at the end (m/s).
    """

    pos_tol: float = 0.03
    flat_tol_deg: float = 10.0
    max_speed: float = 0.02

    def observe(self, frame: FeatureFrame) -> None:
        """Nothing to watch during the episode: success is a property of the end state."""

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge the end state."""
        held = sorted(f"{arm} holds the {obj}" for arm, obj in frame.holding)
        if held:
            return Verdict(False, f"not released: {', '.join(held)}")
        inside, why = capsule_in_tray(world)
        if not inside:
            return Verdict(False, why)
        tray = frame.objects["tray"]
        error = float(np.linalg.norm(tray.pos[:2] - np.asarray(TRAY_TARGET)))
        if error > self.pos_tol:
            return Verdict(False, f"the tray is {100 * error:.1f} cm from its forward target")
        tilt = tilt_deg(tray.axis)
        if tilt > self.flat_tol_deg:
            return Verdict(False, f"the tray is not flat (tilt {tilt:.0f} deg)")
        if not world.on_table("tray"):
            return Verdict(False, "the tray is not on the table")
        for name in ("tray", "capsule"):
            if world.object_velocity(name) > self.max_speed:
                return Verdict(False, f"the {name} is still moving", settling=True)
        return Verdict(True, "capsule inside the tray, tray placed flat at the forward position")


class SetupCoffeeTray:
    """Put a coffee capsule into a tray with the left arm, then carry the tray forward with both arms."""

    name = "setup_coffee_tray"
    description = "Left arm puts a coffee capsule into a tray; both arms carry the tray forward by its handles."

    #: Sampling ranges (m, kg, rad). The tray: inner length and width, rim height, handle tab
    #: width, mass, and its pose near the table centre (small yaw: its handles face the arms).
    TRAY_HALF_LENGTH = (0.115, 0.125)
    TRAY_HALF_WIDTH = (0.065, 0.075)
    TRAY_HEIGHT = (0.022, 0.030)
    TRAY_HANDLE_WIDTH = (0.025, 0.035)
    TRAY_MASS = (0.15, 0.30)
    TRAY_XY = ((-0.02, 0.02), (0.50, 0.56))
    TRAY_YAW = (-0.07, 0.07)
    #: The coffee capsule: a short cylinder on the left of the table.
    CAPSULE_RADIUS = (0.015, 0.020)
    CAPSULE_HALF_HEIGHT = (0.013, 0.017)
    CAPSULE_MASS = (0.010, 0.020)
    CAPSULE_XY = ((-0.32, -0.25), (0.42, 0.58))
    FRICTION = (0.8, 1.2)

    #: Named regions the agents see: name -> (centre, radius, words).
    regions = {"forward": (TRAY_TARGET, 0.03, "forward front position where the tray goes")}

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: object instances and poses drawn from the stated ranges."""
        half_length = uniform(rng, self.TRAY_HALF_LENGTH)
        half_width = uniform(rng, self.TRAY_HALF_WIDTH)
        height = uniform(rng, self.TRAY_HEIGHT)
        parts = tray_parts(half_length, half_width, height, uniform(rng, self.TRAY_HANDLE_WIDTH))
        tray = ObjectSpec(
            name="tray",
            shape="box",
            size=(half_length + HANDLE_LENGTH, half_width, 0.5 * height),
            mass=uniform(rng, self.TRAY_MASS),
            pos=(uniform(rng, self.TRAY_XY[0]), uniform(rng, self.TRAY_XY[1])),
            yaw=uniform(rng, self.TRAY_YAW),
            rgba=(rng.uniform(0.25, 0.45), rng.uniform(0.35, 0.55), rng.uniform(0.55, 0.75), 1.0),
            friction=uniform(rng, self.FRICTION),
            parts=parts,
        )
        capsule = ObjectSpec(
            name="capsule",
            shape="cylinder",
            size=(uniform(rng, self.CAPSULE_RADIUS), uniform(rng, self.CAPSULE_HALF_HEIGHT)),
            mass=uniform(rng, self.CAPSULE_MASS),
            pos=(uniform(rng, self.CAPSULE_XY[0]), uniform(rng, self.CAPSULE_XY[1])),
            yaw=uniform(rng, (-np.pi, np.pi)),
            rgba=(rng.uniform(0.3, 0.6), rng.uniform(0.1, 0.3), rng.uniform(0.05, 0.15), 1.0),
            friction=uniform(rng, self.FRICTION),
        )
        return SceneSpec(objects=[tray, capsule])

    def success_tracker(self) -> CoffeeTrayTracker:
        """A fresh success tracker for one episode."""
        return CoffeeTrayTracker()


TASK = SetupCoffeeTray()
