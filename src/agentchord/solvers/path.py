"""The receding-horizon path solver: edge synthesis, paper Eq. 10 and Appendix C-F.

Each control step the solver plans the next ``horizon`` tool positions of one arm
(one per control tick) from where the tool is now, executes the first ``execute``
of them, and re-plans from the new state with the previous plan shifted as warm
start. Objective: smoothness (squared second differences, velocity continuity with
the last executed tick), distance to the goal at the horizon's end, and a progress
term over the whole horizon (so the tool moves at once, not only at the end).
Constraints (SLSQP inequalities): a step length per tick, clearance of the tool and
of what it holds from obstacle spheres plus a margin, the workspace box, and hard
user path constraints at every waypoint. All built-in terms have analytic
derivatives; user constraints get forward differences per waypoint. SLSQP works in
preconditioned variables (the quadratic objective's Hessian becomes the identity),
and only constraints a waypoint can reach within the horizon enter the QP.

Speed: SLSQP's small dense algebra runs 20-40x slower when OpenBLAS spreads it over
several threads on a busy machine; run with ``OMP_NUM_THREADS=1`` (as the benchmarks do).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from agentchord.solvers.constraints import UserCost
from agentchord.solvers.exceptions import PathNotReachedError, SolverProblemError
from agentchord.solvers.obstacles import Spheres

#: Default box of path waypoints (m): the executor's workspace (``actions/motion.py``):
#: above the table, inside its edges, within the arms' reach envelope.
PATH_WORKSPACE_LOW = np.array([-0.56, 0.22, 0.015])
PATH_WORKSPACE_HIGH = np.array([0.56, 0.95, 0.55])
#: Step length per 50 Hz tick (m): the executor's linear speed limit, 0.30 m/s.
DEFAULT_STEP = 0.006
#: Forward-difference step of user-constraint gradients (m).
FD_STEP = 1e-7


@dataclass(frozen=True)
class PathWeights:
    """Weights of the path objective, in units of squared step lengths.

    Attributes:
        smoothness: Squared second differences (accelerations) of the waypoints.
        goal: Squared distance of the last waypoint to the goal.
        progress: Mean squared distance of all waypoints to the goal.
    """

    smoothness: float = 1.0
    goal: float = 1.0
    progress: float = 1.0


@dataclass
class PathSolution:
    """One receding-horizon plan.

    Attributes:
        waypoints: (H, 3) planned tool positions, one per tick after the current one.
        cost: The objective at the plan (in squared steps, divided by the squared distance to go).
        seconds: Wall time of the solve.
        iterations: SLSQP iterations.
        feasible: Every constraint met within the tolerance.
        violations: Largest violation per constraint group (m, or the user units).
    """

    waypoints: np.ndarray
    cost: float
    seconds: float
    iterations: int = 0
    feasible: bool = True
    violations: dict[str, float] = field(default_factory=dict)


@dataclass
class ExecutedPath:
    """What ``plan_path`` executed.

    Attributes:
        points: (M + 1, 3) tool positions tick by tick, the start included.
        reached: The tool ended within the tolerance of the goal.
        solves: Receding-horizon solves run.
        solve_seconds: Wall time of each solve.
        feasible: Every solve met its constraints.
    """

    points: np.ndarray
    reached: bool
    solves: int
    solve_seconds: np.ndarray
    feasible: bool


class RecedingHorizonPathSolver:
    """Plan a tool's next ``horizon`` ticks toward a goal, re-planned every ``execute`` ticks.

    Args:
        horizon: Waypoints planned per solve (H).
        execute: Waypoints executed before the next solve (k <= H).
        step: Longest move of the tool per tick (m).
        arm: The arm whose tool moves (the key user constraints see).
        margin: Clearance (m) kept from obstacle spheres.
        tool_radius: Radius (m) of the sphere around the tool centre.
        held: Spheres of what the tool holds, as offsets from it (``held_spheres``).
        costs: User path constraints ``f({arm: waypoint}) <= 0``, checked at every waypoint.
        low: Lower corner of the waypoint box (m).
        high: Upper corner.
        weights: Objective weights.
        maxiter: SLSQP iterations per solve.
        tolerance: Largest violation still counted as met.
    """

    def __init__(
        self,
        horizon: int = 20,
        execute: int = 5,
        step: float = DEFAULT_STEP,
        arm: str = "right",
        margin: float = 0.02,
        tool_radius: float = 0.02,
        held: Spheres | None = None,
        costs: Sequence[UserCost] = (),
        low: np.ndarray = PATH_WORKSPACE_LOW,
        high: np.ndarray = PATH_WORKSPACE_HIGH,
        weights: PathWeights | None = None,
        maxiter: int = 50,
        tolerance: float = 1e-3,
    ) -> None:
        if horizon < 1 or not 1 <= execute <= horizon:
            raise SolverProblemError(f"need horizon >= 1 and 1 <= execute <= horizon, got {horizon}, {execute}")
        if step <= 0.0:
            raise SolverProblemError(f"step must be > 0, got {step}")
        self.horizon = horizon
        self.execute = execute
        self.step_length = step
        self.arm = arm
        self.margin = margin
        self.tool_radius = tool_radius
        self.held = held if held is not None else Spheres()
        self.hard = [c for c in costs if c.hard]
        self.soft = [c for c in costs if not c.hard]
        self.low = np.asarray(low, dtype=float).reshape(3)
        self.high = np.asarray(high, dtype=float).reshape(3)
        if not np.all(self.low < self.high):
            raise SolverProblemError(f"empty waypoint box low={self.low.tolist()} high={self.high.tolist()}")
        self.weights = weights or PathWeights()
        self.maxiter = maxiter
        self.tolerance = tolerance
        # The moving spheres: the tool, then what it holds.
        self._offsets = np.vstack([np.zeros((1, 3)), self.held.centres])
        self._radii = np.r_[tool_radius, self.held.radii]
        # Second differences of [previous, current, w_1 .. w_H]: rows i = e_i - 2 e_(i+1) + e_(i+2).
        h = horizon
        d2 = np.zeros((h, h + 2))
        for i in range(h):
            d2[i, i:i + 3] = (1.0, -2.0, 1.0)
        self._d2 = d2
        self._d2w = d2[:, 2:]
        self._low = np.tile(self.low, h)
        self._high = np.tile(self.high, h)
        # Preconditioner: the objective is quadratic with Hessian kron(A, I3) (before its scale);
        # with A = L L^T and w = guess + L^-T z, its Hessian in z is the identity, which is SLSQP's
        # initial BFGS guess: 4-10x fewer iterations than in metres, where A spans 3 decades.
        w = self.weights
        hessian = 2.0 * (w.smoothness * self._d2w.T @ self._d2w + w.progress / h * np.eye(h))
        hessian[-1, -1] += 2.0 * w.goal
        self._precondition = np.kron(np.linalg.inv(np.linalg.cholesky(hessian).T), np.eye(3))

    # -- public API -------------------------------------------------------------------------------

    def shift(self, solution: PathSolution) -> np.ndarray:
        """A previous plan advanced by ``execute`` ticks, its last waypoint held.

        ``step`` starts from this, with the held tail replaced by a continuation toward the goal.
        """
        w = solution.waypoints[self.execute:]
        pad = np.repeat(solution.waypoints[-1:], self.execute, axis=0)
        return np.vstack([w, pad])

    def step(
        self,
        current: np.ndarray,
        goal: np.ndarray,
        obstacles: Spheres | None = None,
        warm: PathSolution | None = None,
        previous: np.ndarray | None = None,
    ) -> PathSolution:
        """Plan the next ``horizon`` waypoints.

        Args:
            current: The tool's position now (m).
            goal: The edge's goal position (m).
            obstacles: Obstacle spheres, from the latest frame.
            warm: The previous plan: shifted by ``execute``, its new tail continued toward the
                goal, it is the initial guess (without it: the straight line to the goal).
            previous: The tool's position one tick ago (velocity continuity); default: at rest.
        """
        t0 = time.perf_counter()
        current = np.asarray(current, dtype=float).reshape(3)
        goal = np.asarray(goal, dtype=float).reshape(3)
        previous = current if previous is None else np.asarray(previous, dtype=float).reshape(3)
        problem = _Horizon(self, current, goal, previous, obstacles if obstacles is not None else Spheres())
        guess = np.clip(self._guess(problem, warm).ravel(), self._low, self._high)
        # Solve in preconditioned variables z (w = guess + M z); box sides within the horizon's
        # reach become linear rows (the others cannot bind: fewer rows, faster QPs).
        m = self._precondition / np.sqrt(problem.objective_scale)
        reach = self.horizon * self.step_length
        low_rows = np.flatnonzero(np.tile(current - self.low < reach, self.horizon))
        high_rows = np.flatnonzero(np.tile(self.high - current < reach, self.horizon))
        box_jac = np.vstack([m[low_rows], -m[high_rows]])

        def to_x(z: np.ndarray) -> np.ndarray:
            return guess + m @ z

        def cons(z: np.ndarray) -> np.ndarray:
            x = to_x(z)
            box = [x[low_rows] - self._low[low_rows], self._high[high_rows] - x[high_rows]]
            return np.concatenate([problem.cons(x), *box])

        def cons_jac(z: np.ndarray) -> np.ndarray:
            return np.vstack([problem.cons_jac(to_x(z)) @ m, box_jac])

        result = minimize(
            lambda z: problem.fun(to_x(z)),
            np.zeros(len(guess)),
            jac=lambda z: m.T @ problem.grad(to_x(z)),
            method="SLSQP",
            constraints=[{"type": "ineq", "fun": cons, "jac": cons_jac}],
            options={"maxiter": self.maxiter, "ftol": 1e-8},
        )
        x = np.clip(to_x(result.x), self._low, self._high)
        violations = problem.violations(x)
        if max(violations.values(), default=0.0) > self.tolerance:
            # The plan breaks a constraint: keep the guess if it breaks it less (or not at all).
            guess_violations = problem.violations(guess)
            if max(guess_violations.values(), default=0.0) < max(violations.values()):
                x, violations = guess, guess_violations
        return PathSolution(
            waypoints=x.reshape(self.horizon, 3),
            cost=problem.fun(x),
            seconds=time.perf_counter() - t0,
            iterations=int(result.nit),
            feasible=max(violations.values(), default=0.0) <= self.tolerance,
            violations=violations,
        )

    # -- helpers ----------------------------------------------------------------------------------

    def _guess(self, problem: _Horizon, warm: PathSolution | None) -> np.ndarray:
        """Initial guess: the warm plan shifted (or the current position), continued toward the goal
        at full speed, with every point lifted out of the obstacles."""
        current, goal = problem.current, problem.goal
        if warm is not None and warm.waypoints.shape == (self.horizon, 3):
            kept = warm.waypoints[self.execute:]
        else:
            kept = np.zeros((0, 3))
        last = kept[-1] if len(kept) else current
        direction = goal - last
        distance = float(np.linalg.norm(direction))
        unit = direction / distance if distance > 1e-9 else np.zeros(3)
        travel = np.minimum(np.arange(1, self.horizon - len(kept) + 1) * self.step_length, distance)
        points = np.vstack([kept, last + travel[:, None] * unit])
        if problem.pairs:
            heading = goal - current
            norm = float(np.linalg.norm(heading))
            self._lift(points, heading / norm if norm > 1e-9 else unit, problem)
        return points

    def _lift(self, points: np.ndarray, unit: np.ndarray, problem: _Horizon) -> None:
        """Push guess points whose tool (or held object) lies inside an obstacle out across the
        line of motion (in place).

        Upward when the line runs through the sphere's centre: a guess pushed back along the
        line would leave SLSQP facing the obstacle head-on, where the path stalls.
        """
        up = np.array([0.0, 0.0, 1.0])
        slack = 2.0 * self.tolerance
        inside = problem.clearance(points) < 0.0
        for i in np.flatnonzero(inside.any(axis=1)):
            point = points[i]
            for k in np.flatnonzero(inside[i]):
                offset, centre, radius = problem.pair_offsets[k], problem.pair_centres[k], problem.pair_radii[k]
                relative = point + offset - centre
                if np.linalg.norm(relative) >= radius:
                    continue  # an earlier push already cleared this pair
                along = float(np.dot(relative, unit))
                across = relative - along * unit
                if np.linalg.norm(across) < 1e-6:
                    across = up - np.dot(up, unit) * unit
                    if np.linalg.norm(across) < 1e-6:
                        across = np.array([1.0, 0.0, 0.0])
                along = float(np.clip(along, -radius, radius))
                lift = np.sqrt(max((radius + slack) ** 2 - along**2, 0.0))
                point = centre + along * unit + lift * across / np.linalg.norm(across) - offset
            points[i] = point


class _Horizon:
    """One solve's objective and constraints with their derivatives (scaled by the step length).

    Obstacle constraints are kept per pair (moving sphere, obstacle sphere) that a waypoint
    of this horizon can bring within the margin; the others cannot bind.
    """

    def __init__(
        self,
        solver: RecedingHorizonPathSolver,
        current: np.ndarray,
        goal: np.ndarray,
        previous: np.ndarray,
        obstacles: Spheres,
    ) -> None:
        self.s = solver
        self.h = solver.horizon
        self.current, self.goal = current, goal
        self.fixed = np.vstack([previous, current])  # the two points before w_1
        self.scale = 1.0 / solver.step_length**2
        # The objective in units of squared steps grows with the distance to go: divide it by
        # that (at least one step) so that SLSQP's absolute tolerance means the same near and far.
        self.objective_scale = self.scale / max(1.0, float(np.sum((goal - current) ** 2)) * self.scale)
        gaps = obstacles.clearance(current + solver._offsets, solver._radii) - solver.margin  # (M, N)
        moving, obstacle = np.nonzero(gaps < self.h * solver.step_length + solver.tolerance)
        self.pairs = len(moving)
        self.pair_offsets = solver._offsets[moving]
        self.pair_centres = obstacles.centres[obstacle]
        self.pair_radii = solver._radii[moving] + obstacles.radii[obstacle] + solver.margin
        # Waypoint i lies within i steps of the tool: a pair farther than that cannot bind there.
        reachable = np.arange(1, self.h + 1)[:, None] * solver.step_length + solver.tolerance
        self.rows = (gaps[moving, obstacle][None, :] < reachable).ravel()  # over (H, K), row-major

    # -- objective --------------------------------------------------------------------------------

    def fun(self, x: np.ndarray) -> float:
        w = x.reshape(self.h, 3)
        s, weights = self.s, self.s.weights
        accel = self._accel(w)
        to_goal = w - self.goal
        value = weights.smoothness * np.sum(accel**2) + weights.goal * np.sum(to_goal[-1] ** 2)
        value += weights.progress * np.sum(to_goal**2) / self.h
        for c in s.soft:
            value += c.weight * sum(max(float(c.fn({s.arm: p})), 0.0) ** 2 for p in w)
        return float(self.objective_scale * value)

    def grad(self, x: np.ndarray) -> np.ndarray:
        w = x.reshape(self.h, 3)
        s, weights = self.s, self.s.weights
        g = 2.0 * weights.smoothness * (self.s._d2w.T @ self._accel(w))
        to_goal = w - self.goal
        g += 2.0 * weights.progress * to_goal / self.h
        g[-1] += 2.0 * weights.goal * to_goal[-1]
        for c in s.soft:
            for i, p in enumerate(w):
                value = float(c.fn({s.arm: p}))
                if value > 0.0:
                    g[i] += c.weight * 2.0 * value * self._fd(c, p, value)
        return self.objective_scale * g.ravel()

    def _accel(self, w: np.ndarray) -> np.ndarray:
        return self.s._d2 @ np.vstack([self.fixed, w])

    # -- constraints (>= 0 when met), in units of step lengths ------------------------------------

    def _diff(self, w: np.ndarray) -> np.ndarray:
        return w[:, None, :] + self.pair_offsets[None, :, :] - self.pair_centres[None, :, :]  # (H, K, 3)

    def clearance(self, w: np.ndarray) -> np.ndarray:
        """(H, K) clearance (m) beyond the margin of every kept pair at every waypoint."""
        return np.linalg.norm(self._diff(w), axis=-1) - self.pair_radii

    def cons(self, x: np.ndarray) -> np.ndarray:
        w = x.reshape(self.h, 3)
        s = self.s
        steps = np.diff(np.vstack([self.current, w]), axis=0)
        parts = [1.0 - np.sum(steps**2, axis=1) * self.scale]
        if self.pairs:
            parts.append(self.clearance(w).ravel()[self.rows] / s.step_length)
        if s.hard:
            parts.append(-np.array([float(c.fn({s.arm: p})) for p in w for c in s.hard]))
        return np.concatenate(parts)

    def cons_jac(self, x: np.ndarray) -> np.ndarray:
        w = x.reshape(self.h, 3)
        s, h = self.s, self.h
        rows = []
        # Steps: g_i = 1 - |w_i - w_(i-1)|^2 / step^2.
        steps = np.diff(np.vstack([self.current, w]), axis=0)
        jac = np.zeros((h, h, 3))
        idx = np.arange(h)
        jac[idx, idx] = -2.0 * steps * self.scale
        jac[idx[1:], idx[1:] - 1] = 2.0 * steps[1:] * self.scale
        rows.append(jac.reshape(h, 3 * h))
        if self.pairs:
            diff = self._diff(w)
            unit = diff / np.maximum(np.linalg.norm(diff, axis=-1, keepdims=True), 1e-12)
            jac = np.zeros((h, self.pairs, h, 3))
            jac[idx, :, idx, :] = unit / s.step_length
            rows.append(jac.reshape(h * self.pairs, 3 * h)[self.rows])
        if s.hard:
            jac = np.zeros((h, len(s.hard), h, 3))
            for i, p in enumerate(w):
                for j, c in enumerate(s.hard):
                    jac[i, j, i] = -self._fd(c, p, float(c.fn({s.arm: p})))
            rows.append(jac.reshape(h * len(s.hard), 3 * h))
        return np.vstack(rows)

    def _fd(self, cost: UserCost, p: np.ndarray, value: float) -> np.ndarray:
        """Forward-difference gradient of a user constraint at one waypoint."""
        out = np.empty(3)
        for axis in range(3):
            q = p.copy()
            q[axis] += FD_STEP
            out[axis] = (float(cost.fn({self.s.arm: q})) - value) / FD_STEP
        return out

    def violations(self, x: np.ndarray) -> dict[str, float]:
        """Largest violation per group: step (m beyond the limit), collision (m), user constraints."""
        w = x.reshape(self.h, 3)
        s = self.s
        steps = np.linalg.norm(np.diff(np.vstack([self.current, w]), axis=0), axis=1)
        out = {"step": max(0.0, float(steps.max() - s.step_length))}
        if self.pairs:
            out["collision"] = max(0.0, float(-self.clearance(w).min()))
        for j, c in enumerate(s.hard):
            out[f"user:{c.name or j}"] = max(0.0, max(float(c.fn({s.arm: p})) for p in w))
        return out


def plan_path(
    start: np.ndarray,
    goal: np.ndarray,
    obstacles: Spheres | None = None,
    solver: RecedingHorizonPathSolver | None = None,
    tolerance: float = 0.002,
    max_solves: int = 200,
    require_reached: bool = False,
) -> ExecutedPath:
    """Run the receding-horizon loop from ``start`` until the tool is at ``goal``.

    The tool is taken to follow each plan exactly (no perception in between): this is
    the open-loop rehearsal of an edge, for tests and for pre-compiling edge programs.

    Args:
        start: Tool position at the start (m).
        goal: Goal position (m).
        obstacles: Obstacle spheres (static over the run).
        solver: The solver (default: ``RecedingHorizonPathSolver()``).
        tolerance: Distance (m) to the goal that counts as reached.
        max_solves: Solves before giving up.
        require_reached: Raise instead of returning a path that did not reach the goal.

    Raises:
        PathNotReachedError: ``require_reached`` and the goal was not reached.
    """
    solver = solver or RecedingHorizonPathSolver()
    goal = np.asarray(goal, dtype=float).reshape(3)
    current = np.asarray(start, dtype=float).reshape(3)
    previous = current
    points, seconds = [current], []
    warm: PathSolution | None = None
    feasible = True
    while np.linalg.norm(current - goal) > tolerance and len(seconds) < max_solves:
        solution = solver.step(current, goal, obstacles, warm=warm, previous=previous)
        seconds.append(solution.seconds)
        feasible = feasible and solution.feasible
        executed = solution.waypoints[: solver.execute]
        points.extend(executed)
        previous = points[-2]
        current = points[-1].copy()
        warm = solution
    path = ExecutedPath(
        points=np.array(points),
        reached=bool(np.linalg.norm(current - goal) <= tolerance),
        solves=len(seconds),
        solve_seconds=np.array(seconds),
        feasible=feasible,
    )
    if require_reached and not path.reached:
        raise PathNotReachedError(
            f"the tool ended {np.linalg.norm(current - goal):.3f} m from the goal after {path.solves} solves", path
        )
    return path
