"""Robot time vs wall time of nominal episodes, and where a control tick's time goes.

Prints a table (targets are printed, not asserted): a nominal single-arm pour
episode should run at >= 10x real time on one core.

    .venv/bin/python benchmarks/bench_episode.py [--seeds 5]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")  # one core, as the target says

import numpy as np
from rich.console import Console
from rich.table import Table

from agentchord.actions.controller import RobotController
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.features.oracle import OracleExtractor
from agentchord.solvers.ik import PoseTarget
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

TASK = "single_arm_pour_water"


def per_call_us(fn, repeats: int = 300) -> float:
    """Median wall time of one call, in microseconds."""
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return float(np.median(samples) * 1e6)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args()
    console = Console()

    table = Table(title=f"{TASK}: nominal episodes on one core (target >= 10x real time)")
    for column in ("seed", "steps", "robot s", "wall s", "x real time", "success"):
        table.add_column(column, justify="right")
    factors = []
    for seed in range(args.seeds):
        result = run_episode(EpisodeSpec(TASK, seed=seed))
        factor = result.time_s / result.wall_s
        factors.append(factor)
        table.add_row(str(seed), str(result.steps), f"{result.time_s:.2f}", f"{result.wall_s:.2f}", f"{factor:.1f}", str(result.success))
    table.add_row("median", "", "", "", f"{np.median(factors):.1f}", "")
    console.print(table)

    world = SimWorld(SIM_TASKS[TASK].sample_scene(np.random.default_rng(0)))
    robot = RobotController(world)
    extractor = OracleExtractor(world)
    robot.frame = extractor.frame
    pose = robot.commanded_pose("right")
    target = PoseTarget(pos=pose.pos + np.array([0.0, 0.0, 0.001]), quat=pose.quat)
    breakdown = Table(title="one control tick (50 Hz budget at 10x real time: 2000 us)")
    breakdown.add_column("part")
    breakdown.add_column("us per tick", justify="right")
    physics = per_call_us(world.step)
    ik = per_call_us(lambda: robot.ik.solve({"right": target}))
    features = per_call_us(extractor.update)
    breakdown.add_row(f"physics ({world.substeps} mj_step)", f"{physics:.0f}")
    breakdown.add_row(f"IK (mink, {robot.ik.iterations} QP iterations, both arms)", f"{ik:.0f}")
    breakdown.add_row("oracle feature frame", f"{features:.0f}")
    breakdown.add_row("sum", f"{physics + ik + features:.0f}")
    console.print(breakdown)


if __name__ == "__main__":
    main()
