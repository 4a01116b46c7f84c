"""A sub-goal (keyframe) problem as the conductor poses it, and the solution the solver returns.

What is decided (the tool-centre positions of one or two arms, on request a yaw per arm), what
bounds it (a box, obstacle spheres, each arm's reach, the tools' spacing, the user's hard
constraints) and what is preferred (a position and yaw per arm, the previous solution, soft user
costs): paper Eq. 9. :class:`~agentchord.solvers.subgoal.SubgoalSolver` solves it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from agentchord.features.frame import ARMS
from agentchord.solvers.constraints import UserCost
from agentchord.solvers.exceptions import SolverProblemError
from agentchord.solvers.obstacles import Spheres
from agentchord.solvers.reach import REACH, ReachModel

#: Default box of sub-goal tool positions (m): above the table (top at z = 0), in
#: front of both arms (bases at x = -+0.469, y = 0.5).
WORKSPACE_LOW = np.array([-0.35, 0.25, 0.05])
WORKSPACE_HIGH = np.array([0.35, 0.75, 0.45])


@dataclass(frozen=True)
class SubgoalWeights:
    """Weights of the objective's terms.

    Attributes:
        penalty: Hard terms in the global search and in the fallback, per squared
            violation (1 cm of violation costs 0.1).
        preferred: Pull toward the preferred position, per m^2.
        consistency: Pull toward the previous solution, per m^2 (and per rad^2 of yaw).
        yaw: Pull toward the preferred yaw, per rad^2.
    """

    penalty: float = 1e3
    preferred: float = 1.0
    consistency: float = 1.0
    yaw: float = 0.01


@dataclass
class SubgoalProblem:
    """One keyframe to synthesise.

    Attributes:
        arms: The arms whose tool positions are decided.
        low: Lower corner of the box of positions (m).
        high: Upper corner.
        costs: User constraints over the decided positions (hard or soft).
        obstacles: Obstacle spheres (world frame).
        held: Per arm, spheres of what it holds as offsets from its tool (``held_spheres``),
            measured with the tool at yaw ``held_yaw[arm]``: they move (and turn) with it.
        held_yaw: Tool yaw when ``held`` was measured (default 0; from a frame:
            ``tool_yaw(frame.arms[arm].ee_quat)``).
        fixed: Tool positions of arms that are not decided (the spacing applies to them too).
        preferred: Preferred position per arm (pose regularisation; none for an arm not named).
        decide_yaw: Also decide a yaw per arm.
        preferred_yaw: Preferred yaw per arm (default 0 when yaw is decided).
        tool_radius: Radius (m) of the sphere around each tool centre.
        margin: Clearance (m) kept from obstacles, beyond the spheres.
        spacing: Smallest distance (m) between two tool centres.
        reach: Reach model per arm.
        weights: Weights of the objective.
        tolerance: Largest violation of a hard term still counted as met (m, or the user units).
    """

    arms: tuple[str, ...] = ("right",)
    low: np.ndarray = field(default_factory=lambda: WORKSPACE_LOW.copy())
    high: np.ndarray = field(default_factory=lambda: WORKSPACE_HIGH.copy())
    costs: Sequence[UserCost] = ()
    obstacles: Spheres = field(default_factory=Spheres)
    held: Mapping[str, Spheres] = field(default_factory=dict)
    held_yaw: Mapping[str, float] = field(default_factory=dict)
    fixed: Mapping[str, np.ndarray] = field(default_factory=dict)
    preferred: Mapping[str, np.ndarray] = field(default_factory=dict)
    decide_yaw: bool = False
    preferred_yaw: Mapping[str, float] = field(default_factory=dict)
    tool_radius: float = 0.02
    margin: float = 0.02
    spacing: float = 0.12
    reach: Mapping[str, ReachModel] = field(default_factory=lambda: dict(REACH))
    weights: SubgoalWeights = field(default_factory=SubgoalWeights)
    tolerance: float = 1e-3

    def __post_init__(self) -> None:
        self.arms = tuple(self.arms)
        if not self.arms or len(set(self.arms)) != len(self.arms):
            raise SolverProblemError(f"SubgoalProblem: arms must be one or two distinct arms, got {self.arms}")
        for arm in (*self.arms, *self.fixed, *self.held, *self.preferred):
            if arm not in ARMS:
                raise SolverProblemError(f"SubgoalProblem: unknown arm {arm!r} (arms: {', '.join(ARMS)})")
        if overlap := set(self.arms) & set(self.fixed):
            raise SolverProblemError(f"SubgoalProblem: {', '.join(sorted(overlap))} both decided and fixed")
        if missing := [arm for arm in self.arms if arm not in self.reach]:
            raise SolverProblemError(f"SubgoalProblem: no reach model for {', '.join(missing)}")
        self.low = np.asarray(self.low, dtype=float).reshape(3)
        self.high = np.asarray(self.high, dtype=float).reshape(3)
        if not np.all(self.low < self.high):
            raise SolverProblemError(f"SubgoalProblem: empty box low={self.low.tolist()} high={self.high.tolist()}")
        for arm in self.held:
            if arm not in self.arms:
                raise SolverProblemError(f"SubgoalProblem: held spheres for {arm!r}, which is not decided")


@dataclass
class SubgoalSolution:
    """A synthesised keyframe.

    Attributes:
        positions: Tool-centre position per decided arm (m).
        yaw: Tool yaw per decided arm (rad); empty unless the problem decides yaw.
        cost: The penalised objective (soft terms + penalty on violated hard terms).
        terms: The objective split per term (they sum to ``cost``).
        violations: Largest violation per hard term (m, or the user units), 0 when met.
        feasible: Every hard term met within the tolerance (and the IK check, when run).
        iterations: Annealing iterations plus SLSQP iterations.
        evaluations: Objective evaluations (finite differences included).
        seconds: Wall time of the solve.
        method: ``dual_annealing+slsqp``, ``slsqp``, or ``slsqp+dual_annealing+slsqp`` (a warm
            solve that fell back to a cold one).
        ik_residual: Per arm, the IK's position error (m) at the solution, when checked.
        x: The decision vector (positions, then yaws).
    """

    positions: dict[str, np.ndarray]
    yaw: dict[str, float]
    cost: float
    terms: dict[str, float]
    violations: dict[str, float]
    feasible: bool
    iterations: int
    evaluations: int
    seconds: float
    method: str
    ik_residual: dict[str, float] = field(default_factory=dict)
    x: np.ndarray = field(default_factory=lambda: np.zeros(0))


def tool_yaw(quat: np.ndarray) -> float:
    """Heading (rad) of a tool's approach axis (its x axis) from its quaternion (w, x, y, z)."""
    w, x, y, z = np.asarray(quat, dtype=float)
    # First column of the rotation matrix.
    return float(np.arctan2(2.0 * (x * y + w * z), 1.0 - 2.0 * (y * y + z * z)))
