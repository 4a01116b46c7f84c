"""A cheap reachability model of the ALOHA arms: a shell of radii around each shoulder.

The sub-goal solver decides tool-centre positions, not joints (paper Appendix C-E:
"reachability and IK residual"). Running the IK inside the optimiser's inner loop
would cost ~0.2 ms per QP iteration and hundreds of iterations per candidate, so
the optimiser uses this shell instead, and a solution can be checked once with the
real IK at the end (``SubgoalSolver(verify_ik=True)``).

How the constants were measured (``measure_reach``, kept so they can be re-measured):
for each arm, 800 targets drawn uniformly in shell coordinates around the shoulder
pivot (radius 0.1-0.9 m, heights of the workspace, azimuth within 90 degrees of
straight ahead), each with the house side-grasp orientation (tool level, approach
axis pointing horizontally away from the shoulder, ``actions.motion.grasp_frame``);
``BimanualIK`` from the home configuration, 250 QP iterations; reached = residual
< 3 mm. Over z in [0.05, 0.45] m every sample between 0.290 and 0.712 m from the
shoulder was reached, and 76% of all samples; nearer targets below shoulder height
and farther targets above it fail (the arms are mirror images and the draw is
mirrored, so both arms give the same figures). A first, differently drawn run gave
0.300-0.675 m. The constants keep inside both.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

#: Shoulder pivot (origin of ``upper_arm_link``, where the waist axis meets the
#: shoulder axis) of each arm in the world frame, read from ``build_robot_model()``
#: after ``mj_forward``. The arm bases sit on the table plane at (+-0.469, 0.5, 0).
SHOULDER = MappingProxyType({"left": (-0.469, 0.5, 0.12705), "right": (0.469, 0.5, 0.12705)})
#: Inner radius (m) of the reachable shell around the shoulder pivot (measured, see above).
REACH_MIN = 0.31
#: Outer radius (m) of the reachable shell around the shoulder pivot (measured, see above).
REACH_MAX = 0.67


@dataclass(frozen=True)
class ReachModel:
    """Reachable tool positions of one arm: a spherical shell around its shoulder.

    Attributes:
        shoulder: Shoulder pivot, world frame (m).
        r_min: Inner radius (m).
        r_max: Outer radius (m).
    """

    shoulder: np.ndarray = field(default_factory=lambda: np.zeros(3))
    r_min: float = REACH_MIN
    r_max: float = REACH_MAX

    def __post_init__(self) -> None:
        object.__setattr__(self, "shoulder", np.asarray(self.shoulder, dtype=float).reshape(3))
        if not 0.0 <= self.r_min < self.r_max:
            raise ValueError(f"ReachModel: need 0 <= r_min < r_max, got {self.r_min}, {self.r_max}")

    def slack(self, points: np.ndarray) -> np.ndarray:
        """Signed slack (m) of points (..., 3): the distance to the shell's nearer boundary, >= 0 inside."""
        r = np.linalg.norm(np.asarray(points, dtype=float) - self.shoulder, axis=-1)
        return np.minimum(r - self.r_min, self.r_max - r)

    def contains(self, point: np.ndarray) -> bool:
        """Whether a tool position lies inside the shell."""
        return bool(self.slack(point) >= 0.0)


#: Where each arm's base stands on the table plane (x, y), m: the waist axis, under the shoulder pivot.
BASE = MappingProxyType({arm: (shoulder[0], shoulder[1]) for arm, shoulder in SHOULDER.items()})
#: Horizontal distance (m) from an arm's base within which it reaches a point on the table from
#: above (a top grasp, or setting an object down), tool 3-10 cm above the table. Measured with
#: ``measure_table_reach``: every top-down pose from 0.10 to 0.58-0.60 m out was reached, at every
#: azimuth tried (-60 to 60 degrees from straight ahead); 2 cm kept in hand.
TOP_REACH = 0.58
#: The same for a side grasp (tool level, approaching away from the base): 0.76-0.78 m measured.
SIDE_REACH = 0.74


def table_distance(arm: str, xy: tuple[float, float] | np.ndarray) -> float:
    """Horizontal distance (m) of a table point from ``arm``'s base."""
    bx, by = BASE[arm]
    return float(np.hypot(float(xy[0]) - bx, float(xy[1]) - by))


def measure_table_reach(arm: str, kind: str = "top", heights: tuple[float, ...] = (0.03, 0.06, 0.1),
                        azimuths_deg: tuple[float, ...] = (-60, -30, 0, 30, 60)) -> float:
    """The farthest horizontal distance (m) from ``arm``'s base at which the IK reaches a grasp pose
    of ``kind`` (``top``: straight down; ``side``: level, approaching away from the base) at every
    height and azimuth given (slow: about 10 s).
    """
    from agentchord.solvers.ik import BimanualIK, solve_from_scratch
    from agentchord.solvers.poses import grasp_frame, pose_from_matrix, top_down_rotation

    ik = BimanualIK(iterations=150, avoid_arm_collisions=False, converged_step=1e-4)
    q = ik.configuration.q.copy()
    base = np.asarray(BASE[arm])
    ahead = 1.0 if arm == "left" else -1.0
    farthest = []
    for z in heights:
        for azimuth in np.radians(azimuths_deg):
            direction = np.array([ahead * np.cos(azimuth), np.sin(azimuth)])
            if kind == "top":
                rotation = top_down_rotation(np.array([-direction[1], direction[0], 0.0]))
            else:
                rotation = grasp_frame(np.array([direction[0], direction[1], 0.0]))
            best = 0.0
            for radius in np.arange(0.30, 0.90, 0.01):
                pose = pose_from_matrix(np.array([*(base + radius * direction), z]), rotation)
                if solve_from_scratch(ik, q, arm, [pose], tolerance=0.005) is not None:
                    best = float(radius)
            farthest.append(best)
    return min(farthest)


#: The measured reach model of each arm.
REACH: MappingProxyType[str, ReachModel] = MappingProxyType(
    {arm: ReachModel(np.array(shoulder), REACH_MIN, REACH_MAX) for arm, shoulder in SHOULDER.items()}
)


def measure_reach(
    arm: str,
    samples: int = 800,
    seed: int = 1,
    iterations: int = 250,
    tolerance: float = 0.003,
    heights: tuple[float, float] = (0.05, 0.45),
) -> tuple[float, float, np.ndarray]:
    """Measure an arm's reachable shell with the IK (slow: ~45 ms per sample).

    Args:
        arm: ``left`` or ``right``.
        samples: Targets to try.
        seed: Seed of the target draw.
        iterations: IK iterations per target, from the home configuration.
        tolerance: Residual (m) under which a target counts as reached.
        heights: Range of target heights (m).

    Returns:
        ``(r_min, r_max, rows)``: the widest radius interval in which every sample was
        reached, and one row ``(radius, height above the shoulder, residual)`` per sample.
    """
    # Imported here: mink and the robot model are only needed to re-measure.
    from agentchord.solvers.poses import grasp_frame, pose_from_matrix
    from agentchord.solvers.ik import BimanualIK

    ik = BimanualIK(iterations=1, avoid_arm_collisions=False)
    home = ik.configuration.q.copy()
    shoulder = np.asarray(SHOULDER[arm])
    ahead = 1.0 if arm == "left" else -1.0  # each arm faces the other across the table
    rng = np.random.default_rng(seed)
    rows = []
    while len(rows) < samples:
        radius, z = rng.uniform(0.1, 0.9), rng.uniform(*heights)
        dz = z - shoulder[2]
        if abs(dz) >= radius or radius**2 - dz**2 < 0.05**2:
            continue  # not on this sphere, or straight above the waist axis (no approach direction)
        azimuth = rng.uniform(-0.5 * np.pi, 0.5 * np.pi)
        horizontal = np.sqrt(radius**2 - dz**2) * np.array([ahead * np.cos(azimuth), np.sin(azimuth)])
        target = np.array([shoulder[0] + horizontal[0], shoulder[1] + horizontal[1], z])
        pose = pose_from_matrix(target, grasp_frame(target - shoulder))
        ik.reset(home)
        for _ in range(iterations):
            ik.solve({arm: pose})
        rows.append((radius, dz, ik.residual(arm, pose)))
    table = np.array(rows)
    return (*_widest_reached_interval(table[:, 0], table[:, 2] < tolerance), table)


def _widest_reached_interval(radii: np.ndarray, reached: np.ndarray) -> tuple[float, float]:
    """The widest interval of radii that holds only reached samples."""
    order = np.argsort(radii)
    radii, reached = radii[order], reached[order]
    best, start = (0.0, 0.0), None
    for k, ok in enumerate(np.append(reached, False)):
        if ok and start is None:
            start = k
        elif not ok and start is not None:
            if radii[k - 1] - radii[start] > best[1] - best[0]:
                best = (float(radii[start]), float(radii[k - 1]))
            start = None
    return best
