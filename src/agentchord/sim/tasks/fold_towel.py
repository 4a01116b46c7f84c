"""Fold towel (paper Appendix B): fold a towel lying flat on the table in half.

Grasp towel bottom corners (LR) -> lift towel bottom (LR) -> move to towel top corners (LR) ->
place towel (LR). Success: the two bottom corners of the towel lie within a tolerance of the
corresponding top corners (a half-folded towel), released by both grippers, the cloth at rest.

The towel is a MuJoCo flex cloth (:class:`~agentchord.sim.scene.ClothSpec`), grasped only
by friction between the finger pads: a top grasp pinches the corner vertex against nothing but the
other finger. Convention: in the towel's own frame, the *bottom* edge is the y-min edge (nearer the
front camera, ``towel_bl`` / ``towel_br``) and the *top* edge the y-max one (``towel_tl`` /
``towel_tr``); ``l`` is x-min (the left arm's side), ``r`` is x-max (the right arm's side). The
left arm folds ``towel_bl`` onto ``towel_tl``, the right arm ``towel_br`` onto ``towel_tr``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.sim.scene import ClothSpec, SceneSpec
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import uniform
from agentchord.sim.world import SimWorld
from agentchord.worlds.protocol import CONTROL_HZ

#: Bottom corner -> the top corner it is folded onto, and the arm that folds it.
FOLD_PAIRS = {"towel_bl": ("towel_tl", "left"), "towel_br": ("towel_tr", "right")}


@dataclass
class FoldTracker:
    """Success of fold towel, judged from the end state.

    Each bottom corner must lie within ``tol`` of its top corner (3-D distance between the corner
    vertices), on top of the towel's other half (not below it), the towel released by both arms and
    at rest: no vertex faster than ``max_speed``, or, where one is (a vertex of a folded towel
    jittering in place among its self-contacts), none that moved further than ``max_speed`` allows
    over the last ``rest_window`` ticks.

    Attributes:
        tol: Largest bottom-to-top corner distance (m).
        max_speed: Largest cloth vertex speed of a towel at rest (m/s).
        rest_window: Ticks over which a vertex's displacement is its speed when one jitters.
    """

    tol: float = 0.045
    max_speed: float = 0.02
    rest_window: int = 10
    # The cloth's vertices at the ticks the verdict was asked (the last ``rest_window`` of them).
    _vertices_at: dict[int, np.ndarray] = field(default_factory=dict, repr=False)

    def observe(self, frame: FeatureFrame) -> None:
        """Nothing to watch during the episode: success is a property of the end state."""

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge the end state."""
        for bottom, (top, _) in FOLD_PAIRS.items():
            gap = float(np.linalg.norm(frame.objects[bottom].pos - frame.objects[top].pos))
            if gap > self.tol:
                return Verdict(False, f"{bottom} is {100 * gap:.1f} cm from {top} (tolerance {100 * self.tol:.1f} cm)")
        for arm in ("left", "right"):
            if world.touching_cloth(arm):
                return Verdict(False, f"the {arm} gripper still touches the towel")
        speed = world.cloth_speed()
        if speed > self.max_speed:
            speed = self._displacement_speed(world)
            if speed is None or speed > self.max_speed:
                shown = world.cloth_speed() if speed is None else speed
                return Verdict(False, f"the towel is still moving ({100 * shown:.1f} cm/s)", settling=True)
        return Verdict(True, "bottom corners folded onto the top corners, towel released and at rest")

    def _displacement_speed(self, world: SimWorld) -> float | None:
        """The largest vertex displacement over the last ``rest_window`` ticks, per second; None
        before the verdict has seen that many ticks (the executor asks it every tick while the scene settles)."""
        tick = world.tick
        self._vertices_at[tick] = world.cloth_vertices()
        for old in [t for t in self._vertices_at if t < tick - self.rest_window]:
            del self._vertices_at[old]
        before = self._vertices_at.get(tick - self.rest_window)
        if before is None:
            return None
        moved = float(np.linalg.norm(self._vertices_at[tick] - before, axis=1).max())
        return moved * CONTROL_HZ / self.rest_window


class FoldTowel:
    """Both arms fold a towel in half, bottom edge onto top edge."""

    name = "fold_towel"
    description = "Left and right arms pinch the towel's bottom corners and fold them onto its top corners."

    #: Sampling ranges (m, kg, rad). A 7 x 7 vertex flex grid: see the module docstring and
    #: ClothSpec (mujoco 3.8 caps a flex/geom pair at 50 contacts).
    SIZE_X = (0.28, 0.32)
    SIZE_Y = (0.22, 0.26)
    MASS = (0.04, 0.08)
    FRICTION = (1.3, 1.7)
    CENTRE_XY = ((-0.03, 0.03), (0.53, 0.57))
    YAW = (-0.10, 0.10)
    COUNT = (7, 7)
    RADIUS = 0.004
    #: A towel has some bending stiffness (it lies flat once folded) and collides with itself.
    BENDING = 1e5
    #: The towel's physics: a 4 ms step, the conjugate-gradient solver, and the noslip pass (what
    #: holds a pinch) only while a finger touches the cloth. Against a 2 ms step with Newton and
    #: noslip always: about 3.7x real time instead of 0.86x, with the same folds, nominal and under the
    #: real protocol (``benchmarks/bench_cloth_physics.py --variants as-is,before``).
    TIMESTEP = 0.004
    SOLVER = "cg"
    NOSLIP_WHILE_TOUCHING = True

    def sample_scene(self, rng: np.random.Generator) -> SceneSpec:
        """One trial's scene: a towel instance and its pose drawn from the stated ranges."""
        towel = ClothSpec(
            name="towel",
            size=(uniform(rng, self.SIZE_X), uniform(rng, self.SIZE_Y)),
            count=self.COUNT,
            mass=uniform(rng, self.MASS),
            pos=(uniform(rng, self.CENTRE_XY[0]), uniform(rng, self.CENTRE_XY[1])),
            yaw=uniform(rng, self.YAW),
            radius=self.RADIUS,
            friction=uniform(rng, self.FRICTION),
            rgba=(*(float(c) for c in rng.uniform(0.3, 0.95, 3)), 1.0),
            bending=self.BENDING,
            self_collide=True,
        )
        return SceneSpec(objects=[], cloth=towel, timestep=self.TIMESTEP, solver=self.SOLVER, noslip_while_touching_cloth=self.NOSLIP_WHILE_TOUCHING)

    def success_tracker(self) -> FoldTracker:
        """A fresh success tracker for one episode."""
        return FoldTracker()


TASK = FoldTowel()
