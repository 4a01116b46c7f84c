"""Solve times of the conductor's constrained solvers (paper Eq. 9-10) over seeded pour-water scenes.

Sub-goal problems (half one arm holding the bottle, half two arms with a yaw each) are
solved cold (dual annealing + SLSQP), then warm (SLSQP from that solution) after the
scene moved ~1 cm; the one-arm keyframes are then reached by the receding-horizon path
solver from the bottle's place, and every re-solve is timed. Targets (printed, not
asserted; PASS when the p95 meets them): cold <= 1 s, warm <= 50 ms, path re-solve <= 50 ms.

SLSQP's small dense algebra runs ~20-40x slower when OpenBLAS spreads it over threads
on a busy machine, so this script runs on one BLAS thread (``OMP_NUM_THREADS=1``,
as the episode benchmark does); set the variable yourself to compare.

    .venv/bin/python benchmarks/bench_solvers.py [--problems 20] [--seed 0]
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from rich.console import Console
from rich.table import Table

from agentchord.features.frame import FeatureFrame, make_static_frame
from agentchord.solvers.constraints import expression_costs
from agentchord.solvers.obstacles import held_spheres, scene_spheres
from agentchord.solvers.path import RecedingHorizonPathSolver, plan_path
from agentchord.solvers.subgoal import SubgoalSolver
from agentchord.solvers.subgoal_problem import SubgoalProblem, SubgoalSolution

#: Targets (ms) per row kind.
TARGET_MS = {"cold": 1000.0, "warm": 50.0, "path": 50.0}
ROUND = {"bottle", "cup"}
LEFT_HOME = np.array([-0.25, 0.45, 0.25])
RIGHT_HOME = np.array([0.25, 0.45, 0.25])


def scene(rng: np.random.Generator, holding: bool, bottle=None, cup=None) -> FeatureFrame:
    """A pour-water frame: the single-arm task's sampling boxes; the right tool at the bottle if held."""
    bottle = np.array([rng.uniform(0.04, 0.12), rng.uniform(0.48, 0.60), 0.09]) if bottle is None else bottle
    cup = np.array([rng.uniform(-0.14, -0.06), rng.uniform(0.52, 0.64), 0.05]) if cup is None else cup
    right = bottle + [0.0, 0.0, 0.02] if holding else RIGHT_HOME
    return make_static_frame(
        {"bottle": {"pos": bottle, "extent": (0.056, 0.056, 0.18)}, "cup": {"pos": cup, "extent": (0.056, 0.056, 0.1)}},
        arms={"right": {"ee": right}, "left": {"ee": LEFT_HOME}},
        holding={("right", "bottle")} if holding else set(),
    )


def problem(frame: FeatureFrame, two_arms: bool) -> SubgoalProblem:
    """One arm: bring the held bottle over the cup. Two arms: pre-grasp poses in front of the cup and the bottle."""
    if not two_arms:
        costs = expression_costs(["dist(right.ee, cup.top + [0, -0.09, 0.08]) - 0.01"], frame)
        return SubgoalProblem(
            arms=("right",), costs=costs, obstacles=scene_spheres(frame, round_objects=ROUND),
            held={"right": held_spheres(frame, "right", round_objects=ROUND)},
            preferred={"right": frame.arms["right"].ee}, fixed={"left": frame.arms["left"].ee},
        )
    costs = expression_costs(
        ["dist(left.ee, cup.pos + [0, -0.1, 0.02]) - 0.005", "dist(right.ee, bottle.pos + [0, -0.1, 0.02]) - 0.005"],
        frame,
    )
    return SubgoalProblem(
        arms=("left", "right"), costs=costs, decide_yaw=True, obstacles=scene_spheres(frame, round_objects=ROUND),
        preferred={"left": LEFT_HOME, "right": RIGHT_HOME}, preferred_yaw={"left": np.pi / 2, "right": np.pi / 2},
    )


def percentiles(samples: list[float]) -> tuple[float, float]:
    """Median and p95 of samples in seconds, in ms."""
    return float(np.median(samples) * 1e3), float(np.percentile(samples, 95) * 1e3)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--problems", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    solver = SubgoalSolver(seed=args.seed)
    rows: dict[str, dict[str, list]] = {}

    def record(name: str, seconds: float, feasible: bool) -> None:
        row = rows.setdefault(name, {"seconds": [], "feasible": []})
        row["seconds"].append(seconds)
        row["feasible"].append(feasible)

    solver.solve(problem(scene(rng, True), False))  # warm up imports and caches
    for k in range(args.problems):
        two_arms = k % 2 == 1
        frame = scene(rng, holding=not two_arms)
        arms = "2 arms + yaw" if two_arms else "1 arm, held bottle"
        cold: SubgoalSolution = solver.solve(problem(frame, two_arms))
        record(f"sub-goal cold, {arms}", cold.seconds, cold.feasible)
        shift = rng.normal(size=(2, 3)) * [1.0, 1.0, 0.0]
        shift = 0.01 * shift / np.linalg.norm(shift, axis=1, keepdims=True)  # each object moves 1 cm
        moved = scene(rng, not two_arms, frame.objects["bottle"].pos + shift[0], frame.objects["cup"].pos + shift[1])
        warm = solver.solve(problem(moved, two_arms), warm_start=cold)
        record(f"sub-goal warm, {arms}", warm.seconds, warm.feasible)
        if not two_arms:
            held = held_spheres(frame, "right", round_objects=ROUND)
            path_solver = RecedingHorizonPathSolver(horizon=20, execute=5, held=held)
            executed = plan_path(frame.arms["right"].ee + [0.0, 0.0, 0.03], cold.positions["right"],
                                 scene_spheres(frame, round_objects=ROUND), path_solver)
            for seconds in executed.solve_seconds:
                record("path re-solve, held bottle", float(seconds),
                       executed.reached and executed.feasible)

    table = Table(
        title=f"Constrained solvers, {args.problems} seeded pour-water scenes (OMP_NUM_THREADS="
        f"{os.environ.get('OMP_NUM_THREADS')})",
        caption="cold: dual annealing + SLSQP; warm: SLSQP from the cold answer after each object moved 1 cm; "
        "path: one receding-horizon solve (H=20, k=5) toward the 1-arm keyframe",
    )
    for column in ("solve", "n", "median ms", "p95 ms", "target (p95)", "", "feasible"):
        table.add_column(column, justify="right")
    for name, row in rows.items():
        median, p95 = percentiles(row["seconds"])
        kind = "cold" if "cold" in name else "warm" if "warm" in name else "path"
        target = TARGET_MS[kind]
        verdict = "[green]PASS[/green]" if p95 <= target else "[red]FAIL[/red]"
        feasible = f"{sum(row['feasible'])}/{len(row['feasible'])}"
        n = str(len(row["seconds"]))
        table.add_row(name, n, f"{median:.1f}", f"{p95:.1f}", f"<= {target:.0f} ms", verdict, feasible)
    Console(width=120).print(table)


if __name__ == "__main__":
    main()
