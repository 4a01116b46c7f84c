"""The sub-goal (keyframe) solver: node synthesis, paper Eq. 9 and Appendix C-E.

The problem it solves and the solution it returns are in :mod:`~agentchord.solvers.subgoal_problem`.

Decision variables are the tool-centre positions of one or two arms and, on
request, a yaw per arm (the heading of the tool's approach axis). Following ReKep,
a cold solve is a coarse global search (``scipy.optimize.dual_annealing``, seeded,
few iterations) on a penalised objective, polished by SLSQP with the hard terms as
inequality constraints; a warm solve (a previous solution given) runs SLSQP alone
from it, which is what a keyframe re-solved after a small scene change needs.

Objective (soft): pose regularisation toward a preferred position per arm,
consistency with the previous solution, yaw regularisation, soft user costs.
Hard constraints (``g >= 0``): clearance of the tools and of held objects from
obstacle spheres (minus a margin), the reach shell of each arm, the spacing of the
two tools, and hard user constraints (``f <= 0``, e.g. compiled node constraints).
Gradients are forward differences (user constraints are black boxes), one set of
n + 1 evaluations serving the objective and all constraints.

A solution can be checked once with the arms' real IK (``verify_ik``). Like every
SLSQP user, it is much slower with multi-threaded OpenBLAS on a busy machine: run
with ``OMP_NUM_THREADS=1``.
"""

from __future__ import annotations

import inspect
import time
from typing import Any

import numpy as np
from scipy.optimize import Bounds, dual_annealing, minimize

from agentchord.solvers.exceptions import InfeasibleSubgoalError, SolverProblemError
from agentchord.solvers.obstacles import Spheres
from agentchord.solvers.reach import REACH
from agentchord.solvers.subgoal_problem import SubgoalProblem, SubgoalSolution

#: Forward-difference step of the gradients (m or rad).
FD_STEP = 1e-7
# SciPy >= 1.15 names the generator ``rng``; older versions ``seed``.
_RNG_KEYWORD = "rng" if "rng" in inspect.signature(dual_annealing).parameters else "seed"


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


class _Compiled:
    """A problem as arrays, with a vectorised evaluation of its terms."""

    def __init__(self, problem: SubgoalProblem, anchor: SubgoalSolution | None) -> None:
        self.problem = problem
        arms = problem.arms
        self.k = len(arms)
        self.n = 3 * self.k + (self.k if problem.decide_yaw else 0)
        w = problem.weights
        low = np.tile(problem.low, self.k)
        high = np.tile(problem.high, self.k)
        self.pref_yaw = np.array([problem.preferred_yaw.get(a, 0.0) for a in arms])
        if problem.decide_yaw:
            low = np.concatenate([low, self.pref_yaw - np.pi])
            high = np.concatenate([high, self.pref_yaw + np.pi])
        self.low, self.high = low, high
        # Pose regularisation: a weight per arm (0 where no preference).
        self.pref = np.array([problem.preferred.get(a, np.zeros(3)) for a in arms], dtype=float)
        self.pref_w = np.array([w.preferred if a in problem.preferred else 0.0 for a in arms])
        self.anchor = None if anchor is None else np.array([anchor.positions[a] for a in arms])
        self.anchor_yaw = None if anchor is None or not problem.decide_yaw else np.array([anchor.yaw[a] for a in arms])
        # Collision points: the tool plus what it holds; offsets turn with the yaw.
        self.offsets = [problem.held.get(a, Spheres()) for a in arms]
        self.held_yaw = np.array([problem.held_yaw.get(a, 0.0) for a in arms])
        self.point_radii = np.concatenate([np.r_[problem.tool_radius, s.radii] for s in self.offsets])
        self.point_arm = np.concatenate([np.full(1 + len(s), i) for i, s in enumerate(self.offsets)])
        self.obstacles = problem.obstacles
        self.reach = [problem.reach[a] for a in arms]
        self.shoulders = np.array([r.shoulder for r in self.reach])
        self.r_min = np.array([r.r_min for r in self.reach])
        self.r_max = np.array([r.r_max for r in self.reach])
        self.fixed = np.array(list(problem.fixed.values()), dtype=float).reshape(-1, 3)
        self.pairs = [(i, j) for i in range(self.k) for j in range(i + 1, self.k)]
        self.hard = [c for c in problem.costs if c.hard]
        self.soft = [c for c in problem.costs if not c.hard]
        # Report labels: the cost's name (else its index), made unique.
        labels: list[str] = []
        for i, c in enumerate(problem.costs):
            label = f"user:{c.name or i}"
            while label in labels:
                label += f"#{i}"
            labels.append(label)
        self.hard_labels = [label for label, c in zip(labels, problem.costs) if c.hard]
        self.soft_labels = [label for label, c in zip(labels, problem.costs) if not c.hard]
        # Hard-term layout: name -> slice of g, and per-entry penalty weights.
        sizes = {
            "collision": len(self.point_radii) * len(self.obstacles),
            "reach": 2 * self.k,
            "spacing": len(self.pairs) + self.k * len(self.fixed),
        }
        sizes.update({label: 1 for label in self.hard_labels})
        self.slices: dict[str, slice] = {}
        start = 0
        for name, size in sizes.items():
            self.slices[name] = slice(start, start + size)
            start += size
        self.g_weights = np.ones(start)
        for label, c in zip(self.hard_labels, self.hard):
            self.g_weights[self.slices[label]] = c.weight
        self.evaluations = 0

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        positions = x[: 3 * self.k].reshape(self.k, 3)
        yaws = x[3 * self.k:] if self.problem.decide_yaw else None
        return positions, yaws

    def positions(self, x: np.ndarray) -> dict[str, np.ndarray]:
        p, _ = self.split(x)
        return {arm: p[i] for i, arm in enumerate(self.problem.arms)}

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Soft terms (preferred, consistency, yaw, soft users...) and the hard vector ``g`` (>= 0 met)."""
        self.evaluations += 1
        p, yaws = self.split(x)
        problem, w = self.problem, self.problem.weights
        soft = [float(self.pref_w @ np.sum((p - self.pref) ** 2, axis=1))]
        consistency = 0.0
        if self.anchor is not None:
            consistency = w.consistency * float(np.sum((p - self.anchor) ** 2))
            if self.anchor_yaw is not None:
                consistency += w.consistency * float(np.sum(_wrap(yaws - self.anchor_yaw) ** 2))
        soft.append(consistency)
        soft.append(w.yaw * float(np.sum(_wrap(yaws - self.pref_yaw) ** 2)) if yaws is not None else 0.0)
        named = self.positions(x)
        values = [float(c.fn(named)) for c in self.soft]
        soft.extend(c.weight * max(v, 0.0) ** 2 for c, v in zip(self.soft, values))
        # Hard terms, in the order of self.slices.
        parts = []
        if len(self.obstacles):
            points = []
            for i, offsets in enumerate(self.offsets):
                points.append(p[i][None, :])
                if len(offsets):
                    local = offsets.centres
                    if yaws is not None:
                        turn = yaws[i] - self.held_yaw[i]
                        c, s = np.cos(turn), np.sin(turn)
                        local = local @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
                    points.append(p[i] + local)
            clearance = self.obstacles.clearance(np.concatenate(points), self.point_radii)
            parts.append((clearance - problem.margin).ravel())
        r = np.linalg.norm(p - self.shoulders, axis=1)
        parts.append(np.concatenate([r - self.r_min, self.r_max - r]))
        spacing = [np.linalg.norm(p[i] - p[j]) for i, j in self.pairs]
        if len(self.fixed):
            spacing.extend(np.linalg.norm(p[:, None, :] - self.fixed[None, :, :], axis=-1).ravel())
        parts.append(np.asarray(spacing, dtype=float) - problem.spacing)
        parts.append(-np.array([float(c.fn(named)) for c in self.hard]))
        return np.array(soft), np.concatenate(parts)

    def penalised(self, x: np.ndarray) -> float:
        """Soft terms plus the penalty on violated hard terms (the global search's objective)."""
        soft, g = self.evaluate(x)
        return float(soft.sum()) + self.problem.weights.penalty * float(self.g_weights @ np.minimum(g, 0.0) ** 2)

    def report(self, x: np.ndarray) -> tuple[float, dict[str, float], dict[str, float]]:
        """(penalised cost, per-term costs, per-hard-term largest violations) at ``x``."""
        soft, g = self.evaluate(x)
        names = ["preferred", "consistency", "yaw", *self.soft_labels]
        terms = dict(zip(names, map(float, soft)))
        violations = {}
        for name, sl in self.slices.items():
            shortfall = np.minimum(g[sl], 0.0)
            terms[name] = terms.get(name, 0.0) + self.problem.weights.penalty * float(self.g_weights[sl] @ shortfall**2)
            violations[name] = max(0.0, float(-shortfall.min())) if shortfall.size else 0.0
        return float(sum(terms.values())), terms, violations


class _Derivatives:
    """Soft objective, hard vector and their forward-difference Jacobians, cached per point.

    SLSQP asks for the objective, the constraints and both Jacobians at the same
    point: one evaluation (and one set of n perturbed evaluations) serves all four.
    """

    def __init__(self, compiled: _Compiled) -> None:
        self.compiled = compiled
        self._key: bytes | None = None
        self._jac_key: bytes | None = None

    def _value(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        key = x.tobytes()
        if key != self._key:
            soft, g = self.compiled.evaluate(x)
            self._key, self._f, self._g = key, float(soft.sum()), g
        return self._f, self._g

    def _jacobians(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = x.tobytes()
        if key != self._jac_key:
            f0, g0 = self._value(x)
            df = np.empty(len(x))
            dg = np.empty((len(g0), len(x)))
            for i in range(len(x)):
                xi = x.copy()
                # Step inward at the upper bound so the perturbed point stays in the box.
                h = FD_STEP if xi[i] + FD_STEP <= self.compiled.high[i] else -FD_STEP
                xi[i] += h
                soft, g = self.compiled.evaluate(xi)
                df[i] = (float(soft.sum()) - f0) / h
                dg[:, i] = (g - g0) / h
            self._jac_key, self._df, self._dg = key, df, dg
        return self._df, self._dg

    def fun(self, x: np.ndarray) -> float:
        return self._value(x)[0]

    def grad(self, x: np.ndarray) -> np.ndarray:
        return self._jacobians(x)[0]

    def cons(self, x: np.ndarray) -> np.ndarray:
        return self._value(x)[1]

    def cons_jac(self, x: np.ndarray) -> np.ndarray:
        return self._jacobians(x)[1]


class SubgoalSolver:
    """Solve keyframe problems: global search then local polish, or local only when warm.

    Args:
        seed: Seed of the global search (same seed, same problem: same answer).
        anneal_maxiter: Iterations of ``dual_annealing`` (each costs 2n evaluations).
        slsqp_maxiter: Iterations of SLSQP.
        verify_ik: Check the solution once with the arms' IK (``BimanualIK``) and count
            a residual above ``ik_tolerance`` as infeasible.
        ik_tolerance: Largest accepted IK position error (m).
        ik_iterations: IK iterations of the check, from the home configuration.
    """

    def __init__(
        self,
        seed: int = 0,
        anneal_maxiter: int = 100,
        slsqp_maxiter: int = 100,
        verify_ik: bool = False,
        ik_tolerance: float = 0.005,
        ik_iterations: int = 200,
    ) -> None:
        self.seed = seed
        self.anneal_maxiter = anneal_maxiter
        self.slsqp_maxiter = slsqp_maxiter
        self.verify_ik = verify_ik
        self.ik_tolerance = ik_tolerance
        self.ik_iterations = ik_iterations
        self._ik: Any = None
        self._home: np.ndarray | None = None

    def solve(
        self,
        problem: SubgoalProblem,
        warm_start: SubgoalSolution | None = None,
        require_feasible: bool = False,
    ) -> SubgoalSolution:
        """Synthesise the keyframe.

        Args:
            problem: The problem.
            warm_start: A previous solution of (nearly) the same problem: SLSQP runs from
                it alone, with a consistency pull toward it; if that ends infeasible, the
                cold search runs too and the better answer is kept.
            require_feasible: Raise instead of returning an infeasible solution.

        Raises:
            SolverProblemError: ``warm_start`` decides other arms, or lacks a yaw the problem decides.
            InfeasibleSubgoalError: ``require_feasible`` and no solution meets every hard term.
        """
        t0 = time.perf_counter()
        if warm_start is not None:
            if set(warm_start.positions) != set(problem.arms):
                raise SolverProblemError(
                    f"warm start decides {sorted(warm_start.positions)}, the problem {sorted(problem.arms)}"
                )
            if problem.decide_yaw and set(warm_start.yaw) != set(problem.arms):
                raise SolverProblemError("warm start has no yaw for every arm, and the problem decides yaw")
        compiled = _Compiled(problem, warm_start)
        iterations = 0
        if warm_start is not None:
            x0 = np.clip(self._vector(problem, warm_start), compiled.low, compiled.high)
            x, nit = self._polish(compiled, x0)
            iterations += nit
            method = "slsqp"
            if not self._feasible(compiled, x):
                cold, nit = self._cold(compiled, x)
                iterations += nit
                x = self._better(compiled, x, cold)
                method = "slsqp+dual_annealing+slsqp"
        else:
            x, iterations = self._cold(compiled, self._start(compiled))
            method = "dual_annealing+slsqp"
        cost, terms, violations = compiled.report(x)
        feasible = max(violations.values(), default=0.0) <= problem.tolerance
        p, yaws = compiled.split(x)
        solution = SubgoalSolution(
            positions={arm: p[i].copy() for i, arm in enumerate(problem.arms)},
            yaw={} if yaws is None else {arm: float(_wrap(yaws[i])) for i, arm in enumerate(problem.arms)},
            cost=cost,
            terms=terms,
            violations=violations,
            feasible=feasible,
            iterations=iterations,
            evaluations=compiled.evaluations,
            seconds=0.0,
            method=method,
            x=x.copy(),
        )
        if self.verify_ik:
            solution.ik_residual = self._ik_residuals(solution)
            worst = max(solution.ik_residual.values())
            solution.violations["ik"] = max(0.0, worst - self.ik_tolerance)
            solution.feasible = solution.feasible and worst <= self.ik_tolerance
        solution.seconds = time.perf_counter() - t0
        if require_feasible and not solution.feasible:
            failed = {k: round(v, 4) for k, v in solution.violations.items() if v > problem.tolerance}
            raise InfeasibleSubgoalError(f"no keyframe meets every hard constraint; violations: {failed}", solution)
        return solution

    # -- search strategies -------------------------------------------------------------------------

    def _cold(self, compiled: _Compiled, x0: np.ndarray) -> tuple[np.ndarray, int]:
        """Dual annealing on the penalised objective, then the SLSQP polish."""
        result = dual_annealing(
            compiled.penalised,
            bounds=list(zip(compiled.low, compiled.high)),
            maxiter=self.anneal_maxiter,
            no_local_search=True,  # the SLSQP polish is the local search
            x0=x0,
            **{_RNG_KEYWORD: np.random.default_rng(self.seed)},
        )
        x, nit = self._polish(compiled, np.clip(result.x, compiled.low, compiled.high))
        return x, int(result.nit) + nit

    def _polish(self, compiled: _Compiled, x0: np.ndarray) -> tuple[np.ndarray, int]:
        """SLSQP with the hard terms as constraints; if that fails, SLSQP on the penalised objective."""
        bounds = Bounds(compiled.low, compiled.high)
        derivatives = _Derivatives(compiled)
        result = minimize(
            derivatives.fun,
            x0,
            jac=derivatives.grad,
            method="SLSQP",
            bounds=bounds,
            constraints=[{"type": "ineq", "fun": derivatives.cons, "jac": derivatives.cons_jac}],
            options={"maxiter": self.slsqp_maxiter, "ftol": 1e-9},
        )
        x = self._better(compiled, x0, np.clip(result.x, compiled.low, compiled.high))
        nit = int(result.nit)
        if not self._feasible(compiled, x):
            # Incompatible constraints: settle for the least-violating compromise.
            fallback = minimize(
                compiled.penalised, x, method="SLSQP", bounds=bounds,
                options={"maxiter": self.slsqp_maxiter, "ftol": 1e-12},
            )
            x = self._better(compiled, x, np.clip(fallback.x, compiled.low, compiled.high))
            nit += int(fallback.nit)
        return x, nit

    def _feasible(self, compiled: _Compiled, x: np.ndarray) -> bool:
        _, g = compiled.evaluate(x)
        return bool(g.size == 0 or g.min() >= -compiled.problem.tolerance)

    def _better(self, compiled: _Compiled, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The feasible one of two points, else the one with the lower penalised cost."""
        fa, fb = self._feasible(compiled, a), self._feasible(compiled, b)
        if fa != fb:
            return a if fa else b
        return b if compiled.penalised(b) <= compiled.penalised(a) else a

    def _start(self, compiled: _Compiled) -> np.ndarray:
        """Initial guess: the preferred positions (the current pose), else the box centre."""
        problem = compiled.problem
        centre = 0.5 * (problem.low + problem.high)
        p = np.array([problem.preferred.get(arm, centre) for arm in problem.arms], dtype=float)
        x = p.ravel()
        if problem.decide_yaw:
            x = np.concatenate([x, compiled.pref_yaw])
        return np.clip(x, compiled.low, compiled.high)

    @staticmethod
    def _vector(problem: SubgoalProblem, solution: SubgoalSolution) -> np.ndarray:
        x = np.concatenate([np.asarray(solution.positions[arm], dtype=float) for arm in problem.arms])
        if problem.decide_yaw:
            pref = np.array([problem.preferred_yaw.get(arm, 0.0) for arm in problem.arms])
            yaws = np.array([solution.yaw[arm] for arm in problem.arms])
            x = np.concatenate([x, pref + _wrap(yaws - pref)])  # inside the yaw bounds
        return x

    # -- IK check ---------------------------------------------------------------------------------

    def _ik_residuals(self, solution: SubgoalSolution) -> dict[str, float]:
        """Position error of the arms' IK at the solution, side-grasp orientation (tool level)."""
        # Imported here: mink and the robot model are only needed when the check is asked for.
        from agentchord.solvers.poses import grasp_frame, pose_from_matrix
        from agentchord.solvers.ik import BimanualIK

        if self._ik is None:
            self._ik = BimanualIK(iterations=1, avoid_arm_collisions=False)
            self._home = self._ik.configuration.q.copy()
        self._ik.reset(self._home)
        targets = {}
        for arm, position in solution.positions.items():
            if arm in solution.yaw:
                approach = np.array([np.cos(solution.yaw[arm]), np.sin(solution.yaw[arm]), 0.0])
            else:
                approach = position - REACH[arm].shoulder  # pointing away from the shoulder
            targets[arm] = pose_from_matrix(position, grasp_frame(approach))
        for _ in range(self.ik_iterations):
            self._ik.solve(targets)
        return {arm: self._ik.residual(arm, target) for arm, target in targets.items()}
