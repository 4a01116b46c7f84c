"""Where a control tick's wall time goes, and the episode's speed against its physics alone.

For a rigid task and the towel, nominal episodes are run twice in one process: once bare, its
commands recorded, then the same commands replayed on a fresh world of the same seed as pure
physics (``substeps`` ``mj_step`` per tick, nothing else: the same trajectory, checked); once
with timers around the tick's parts (physics, IK, the feature frame, the monitors, the actions;
the rest is the executor's own Python). The ratio physics-only wall / episode wall is the share
of the physics' own speed the episode keeps. Targets are printed, not asserted: a rigid task's
ratio >= 0.7.

    .venv/bin/python benchmarks/bench_tick.py [--seeds 3] [--cloth-seeds 1] [--tasks single_arm_pour_water,fold_towel]
"""

from __future__ import annotations

import argparse
import os
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager

os.environ.setdefault("OMP_NUM_THREADS", "1")  # one core, as the episode benchmark's target says

import mujoco
import numpy as np
from rich.console import Console
from rich.table import Table

from agentchord.actions.controller import RobotController
from agentchord.execution.edge_program import EdgeProgram
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.executor import Executor
from agentchord.features.oracle import OracleExtractor
from agentchord.monitor import EdgeMonitors
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world, scene_rng
from agentchord.sim.world import SimWorld

TASKS = "single_arm_pour_water,fold_towel"
#: The tick's timed parts: (name, class, method). ``RobotController.step`` times the IK and the
#: commands; the world's step inside it is taken out.
PARTS: tuple[tuple[str, type, str], ...] = (
    ("physics (world.step)", SimWorld, "step"),
    ("IK + commands", RobotController, "step"),
    ("feature frame", OracleExtractor, "update"),
    ("monitors", EdgeMonitors, "evaluate"),
    ("actions (edge program)", EdgeProgram, "update"),
)


@contextmanager
def timed_parts(totals: dict[str, float]) -> Iterator[None]:
    """Wrap each part's method so its wall time adds up in ``totals`` (exclusive of nested parts)."""
    stack: list[float] = []  # per open part, the time its nested parts took

    def wrap(name: str, original: Callable) -> Callable:
        def timed(*args, **kwargs):
            stack.append(0.0)
            t0 = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                spent = time.perf_counter() - t0
                nested = stack.pop()
                totals[name] += spent - nested
                if stack:
                    stack[-1] += spent
        return timed

    run = Executor.run

    def counted_run(executor: Executor):
        totals.clear()  # the world's settling steps and the first frame, before the episode, do not count
        return run(executor)

    originals = [(cls, method, getattr(cls, method)) for _, cls, method in PARTS]
    for (name, cls, method), (_, _, original) in zip(PARTS, originals):
        setattr(cls, method, wrap(name, original))
    Executor.run = counted_run
    try:
        yield
    finally:
        for cls, method, original in originals:
            setattr(cls, method, original)
        Executor.run = run


def physics_only(task: str, seed: int, controls: list[np.ndarray], noslip: list[int]) -> tuple[float, np.ndarray]:
    """Wall time of replaying ``controls`` as pure physics on a fresh world of the trial; its final qpos.

    ``noslip``: the noslip iterations of each tick (a cloth's world runs the pass only while a finger touches it).
    """
    world = open_world(task, seed)
    model, data = world.model, world.data
    t0 = time.perf_counter()
    for ctrl, iterations in zip(controls, noslip, strict=True):
        data.ctrl[:] = ctrl
        model.opt.noslip_iterations = iterations
        for _ in range(world.substeps):
            mujoco.mj_step(model, data)
    return time.perf_counter() - t0, data.qpos.copy()


def measure(task: str, seed: int) -> dict[str, float]:
    """One seed of a task: the bare episode, its physics replayed, and the timed episode."""
    controls: list[np.ndarray] = []
    noslip: list[int] = []
    final: list[np.ndarray] = []

    def record(executor: Executor) -> None:
        controls.append(executor.world.data.ctrl.copy())
        noslip.append(int(executor.world.model.opt.noslip_iterations))
        final[:] = [executor.world.data.qpos]

    result = run_episode(EpisodeSpec(task, seed=seed), on_tick=record)
    physics_s, qpos = physics_only(task, seed, controls, noslip)
    totals: dict[str, float] = defaultdict(float)
    with timed_parts(totals):
        timed = run_episode(EpisodeSpec(task, seed=seed))
    ticks = timed.steps
    row = {name: totals[name] / ticks * 1e6 for name, _, _ in PARTS}
    row["executor rest"] = timed.wall_s / ticks * 1e6 - sum(row.values())
    row["tick (timed run)"] = timed.wall_s / ticks * 1e6
    row["tick (bare run)"] = result.wall_s / result.steps * 1e6
    row["physics only"] = physics_s / result.steps * 1e6
    row["ratio"] = physics_s / result.wall_s
    row["x real time"] = result.time_s / result.wall_s
    row["replay identical"] = float(np.array_equal(qpos, final[0]))
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--cloth-seeds", type=int, default=1, help="seeds of a cloth task (30 s of wall time each)")
    parser.add_argument("--tasks", default=TASKS, help="comma-separated tasks")
    args = parser.parse_args()
    console = Console()
    for task in args.tasks.split(","):
        seeds = args.cloth_seeds if SIM_TASKS[task].sample_scene(scene_rng(0)).cloth is not None else args.seeds
        rows = [measure(task, seed) for seed in range(seeds)]
        table = Table(title=f"{task}: one control tick, nominal episodes, median of {seeds} seeds (us per tick)")
        table.add_column("part")
        table.add_column("us per tick", justify="right")
        for name in [*(n for n, _, _ in PARTS), "executor rest", "tick (timed run)", "tick (bare run)", "physics only"]:
            table.add_row(name, f"{np.median([r[name] for r in rows]):.0f}")
        ratio = float(np.median([r["ratio"] for r in rows]))
        table.add_row("ratio physics only / episode (target >= 0.7 rigid)", f"{ratio:.2f}")
        table.add_row("episode x real time", f"{np.median([r['x real time'] for r in rows]):.1f}")
        table.add_row("physics replay identical to the episode", "yes" if all(r["replay identical"] for r in rows) else "NO")
        console.print(table)


if __name__ == "__main__":
    main()
