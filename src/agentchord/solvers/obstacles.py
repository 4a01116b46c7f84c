"""Obstacles of the constrained solvers: sets of spheres built from the feature frame.

The paper queries a distance field fused from depth (Appendix C-E); our solvers
only need clearances of a few tool and held-object points, so every object becomes
a few spheres that cover its box (features ``pos``, ``quat``, ``axis``, ``extent``)
and a clearance is a vectorised point-to-sphere distance. The covering is
conservative: no point of the object lies outside its spheres, and the spheres poke
out by at most about half a cell.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.features.frame import FeatureFrame, ObjectFeatures

#: Most spheres one object becomes; bigger objects get coarser cells.
MAX_SPHERES_PER_OBJECT = 48
#: Smallest cell (m): thinner objects (a cloth point, a flat sheet) still get this thickness.
MIN_CELL = 0.01


@dataclass(frozen=True)
class Spheres:
    """A set of spheres (obstacles, or points carried by a tool as offsets from it).

    Attributes:
        centres: (N, 3) centres (m): world positions, or offsets from a tool.
        radii: (N,) radii (m).
        labels: The object each sphere belongs to.
    """

    centres: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    radii: np.ndarray = field(default_factory=lambda: np.zeros(0))
    labels: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        centres = np.asarray(self.centres, dtype=float).reshape(-1, 3)
        radii = np.asarray(self.radii, dtype=float).reshape(-1)
        if len(radii) != len(centres):
            raise ValueError(f"Spheres: {len(centres)} centres but {len(radii)} radii")
        if np.any(radii < 0.0):
            raise ValueError("Spheres: radii must be >= 0")
        labels = tuple(self.labels) if self.labels else ("",) * len(centres)
        if len(labels) != len(centres):
            raise ValueError(f"Spheres: {len(centres)} centres but {len(labels)} labels")
        object.__setattr__(self, "centres", centres)
        object.__setattr__(self, "radii", radii)
        object.__setattr__(self, "labels", labels)

    def __len__(self) -> int:
        return len(self.radii)

    @classmethod
    def concat(cls, *sets: Spheres) -> Spheres:
        """All spheres of several sets."""
        sets = tuple(s for s in sets if len(s))
        if not sets:
            return cls()
        return cls(
            np.concatenate([s.centres for s in sets]),
            np.concatenate([s.radii for s in sets]),
            tuple(label for s in sets for label in s.labels),
        )

    def translated(self, offset: np.ndarray) -> Spheres:
        """The same spheres moved by ``offset``."""
        return Spheres(self.centres + np.asarray(offset, dtype=float), self.radii, self.labels)

    def clearance(self, points: np.ndarray, radii: np.ndarray | float = 0.0) -> np.ndarray:
        """Signed clearances between point spheres and these spheres.

        Args:
            points: (P, 3) centres of the moving spheres.
            radii: Their radii, (P,) or one for all.

        Returns:
            (P, N) surface-to-surface distances (m), negative where they overlap.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        distances = np.linalg.norm(points[:, None, :] - self.centres[None, :, :], axis=-1)
        return distances - np.broadcast_to(np.asarray(radii, dtype=float), len(points))[:, None] - self.radii[None, :]


def object_spheres(name: str, features: ObjectFeatures, round_section: bool = False) -> Spheres:
    """Spheres that cover one object's box.

    The box has the object's ``extent`` along its own axes (``quat``; its third axis is
    ``axis``). It is cut into a grid of near-cubic cells, each covered by the sphere
    through its corners. A tall cylinder (``round_section``) is cut along its axis
    only, each slice covered by the sphere through its rim, which is much tighter
    than the box corners.

    Args:
        name: The object's name (the spheres' label).
        features: Its features.
        round_section: The object is a cylinder standing on its axis (bottle, cup).
    """
    extent = np.maximum(np.asarray(features.extent, dtype=float), 0.0)
    axes = _object_axes(features)
    if round_section and extent[2] >= extent[0]:
        # Slices half a diameter thick: each sphere pokes out sideways by ~12% of the radius.
        radius = 0.5 * max(extent[0], extent[1])
        count = _cells(extent[2], max(radius, MIN_CELL, extent[2] / MAX_SPHERES_PER_OBJECT))
        along = ((np.arange(count) + 0.5) / count - 0.5) * extent[2]
        centres = features.pos + along[:, None] * axes[:, 2]
        radii = np.full(count, np.hypot(radius, 0.5 * extent[2] / count))
        return Spheres(centres, radii, (name,) * count)
    cell = max(float(extent.min()), float(extent.max()) / 6.0, MIN_CELL)
    while True:
        counts = [_cells(e, cell) for e in extent]
        if np.prod(counts) <= MAX_SPHERES_PER_OBJECT:
            break
        cell *= 1.25
    sizes = np.maximum(extent, MIN_CELL) / counts
    grids = [((np.arange(n) + 0.5) / n - 0.5) * max(e, MIN_CELL) for n, e in zip(counts, extent)]
    local = np.stack(np.meshgrid(*grids, indexing="ij"), axis=-1).reshape(-1, 3)
    centres = features.pos + local @ axes.T
    radii = np.full(len(local), 0.5 * float(np.linalg.norm(sizes)))
    return Spheres(centres, radii, (name,) * len(local))


def scene_spheres(
    frame: FeatureFrame,
    include: Iterable[str] | None = None,
    exclude: Iterable[str] = (),
    round_objects: Iterable[str] = (),
    skip_held: bool = True,
) -> Spheres:
    """Obstacle spheres of the frame's objects.

    Args:
        frame: The feature frame.
        include: Objects to turn into obstacles (default: all of the frame's).
        exclude: Objects to leave out (the one about to be grasped, the target of a place).
        round_objects: Objects that are upright cylinders (tighter covering).
        skip_held: Leave out objects any arm holds (they move with the tool: see ``held_spheres``).
    """
    names = list(frame.objects) if include is None else list(include)
    skipped = set(exclude)
    if skip_held:
        skipped |= {obj for _, obj in frame.holding}
    rounds = set(round_objects)
    return Spheres.concat(
        *(object_spheres(n, frame.objects[n], n in rounds) for n in names if n not in skipped)
    )


def held_spheres(
    frame: FeatureFrame, arm: str, objects: Iterable[str] | None = None, round_objects: Iterable[str] = ()
) -> Spheres:
    """Spheres of the objects an arm holds, as offsets from its tool centre.

    Args:
        frame: The feature frame.
        arm: The holding arm.
        objects: The held objects (default: those the frame says ``arm`` holds).
        round_objects: Objects that are upright cylinders.
    """
    names = [obj for a, obj in sorted(frame.holding) if a == arm] if objects is None else list(objects)
    ee = frame.arms[arm].ee
    rounds = set(round_objects)
    return Spheres.concat(*(object_spheres(n, frame.objects[n], n in rounds) for n in names)).translated(-ee)


def _cells(length: float, cell: float) -> int:
    return max(1, int(np.ceil(length / cell - 1e-9)))


def _object_axes(features: ObjectFeatures) -> np.ndarray:
    """Columns: the object's x, y and principal axes (``quat``, with ``axis`` as its z)."""
    quat = np.asarray(features.quat, dtype=float)
    rot = Rotation.from_quat(quat[[1, 2, 3, 0]]).as_matrix() if np.linalg.norm(quat) > 1e-9 else np.eye(3)
    z = np.asarray(features.axis, dtype=float)
    z = z / np.linalg.norm(z) if np.linalg.norm(z) > 1e-9 else rot[:, 2]
    # Static frames may give an axis without a matching quat: keep the axis, make x orthogonal to it.
    x = rot[:, 0] - np.dot(rot[:, 0], z) * z
    if np.linalg.norm(x) < 1e-6:
        x = rot[:, 1] - np.dot(rot[:, 1], z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


#: Overlap (m) beyond the covering's own slack that counts as a collision on a straight carry.
CARRY_PENETRATION = 0.01
#: Clearance (m) a lifted carry keeps over the obstacles it passes.
CARRY_CLEARANCE = 0.02
#: Obstacles this far (m) from the carried object's straight path in the plane are not passed over.
CARRY_CORRIDOR = 0.12


def lift_over(start: np.ndarray, goal: np.ndarray, obstacles: Spheres, carried: Spheres, samples: int = 24) -> list[np.ndarray]:
    """Tool waypoints that carry an object from ``start`` to ``goal`` without driving it through another.

    The straight line, where what the tool carries stays clear of every obstacle; else up over
    the obstacles near the path, across at that height, and down onto the goal.

    Args:
        start: Tool position now (m).
        goal: Tool position at the end (m).
        obstacles: Obstacle spheres (world frame).
        carried: What the tool carries, as offsets from the tool.
        samples: Points checked along the line.

    Returns:
        The waypoints after ``start``, the last one ``goal``.
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    if not len(obstacles) or not len(carried):
        return [goal]
    # The last few centimetres are the goal's own business (placed beside or above an object).
    line = start + np.linspace(0.0, 1.0, samples)[:-3, None] * (goal - start)
    points = (line[:, None, :] + carried.centres[None, :, :]).reshape(-1, 3)
    radii = np.tile(carried.radii, len(line))
    if float(obstacles.clearance(points, radii).min()) > -CARRY_PENETRATION:
        return [goal]
    # Height: the carried object's lowest point clears the tallest obstacle near the path.
    direction = (goal - start)[:2]
    length = max(float(np.linalg.norm(direction)), 1e-9)
    offsets = obstacles.centres[:, :2] - start[:2]
    along = np.clip(offsets @ direction / length, 0.0, length)
    across = np.linalg.norm(offsets - along[:, None] * direction / length, axis=1)
    near = across < CARRY_CORRIDOR + float(np.max(np.linalg.norm(carried.centres[:, :2], axis=1) + carried.radii))
    top = float(np.max((obstacles.centres[:, 2] + obstacles.radii)[near])) if near.any() else 0.0
    below = float(np.min(carried.centres[:, 2] - carried.radii))  # negative: how far the object hangs below the tool
    height = max(start[2], goal[2], top - below + CARRY_CLEARANCE)
    return [np.r_[start[:2], height], np.r_[goal[:2], height], goal]
