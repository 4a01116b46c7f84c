"""What the towel's physics costs, and what a cheaper setting of it costs the fold.

A fold-towel control tick is ~20 ms of MuJoCo (10 substeps of ~2 ms: the Newton solver over the
cloth's 147 degrees of freedom and ~300 constraint rows, then the noslip pass the corner pinch
holds by). Each variant below changes one physics setting of the towel scene only (the rigid
tasks are untouched) and runs whole episodes with the executor, so a variant is judged by what
the fold does with it, not by a replay: success, the failures that ended the others, and the
episode's speed in multiples of real time.

    .venv/bin/python benchmarks/bench_cloth_physics.py [--seeds 0,1,2] [--protocols none,real] [--variants all]

Variants (``--variants`` takes a comma-separated subset):

- ``as-is``: the shipped scene (timestep 2 ms, noslip 3 iterations, a 7 x 7 grid).
- ``noslip-off``: no noslip pass.
- ``noslip-touch``: the noslip pass only on ticks after a finger touched the cloth.
- ``dt-4ms`` / ``dt-5ms``: a longer physics step (5 or 4 substeps a tick).
- ``dt-4ms-noslip-touch``: both.
- ``grid-5``: a 5 x 5 grid (75 degrees of freedom).
"""

from __future__ import annotations

import argparse
import os
import statistics
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

os.environ.setdefault("OMP_NUM_THREADS", "1")

from rich.console import Console
from rich.table import Table

import agentchord.sim.world as sim_world
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.harness import DisturbanceSetting
from agentchord.sim.tasks.fold_towel import FoldTowel

TASK = "fold_towel"


@dataclass(frozen=True)
class Variant:
    """One setting of the towel scene's physics (None: as shipped)."""

    timestep: float | None = None
    noslip: int | None = None
    noslip_on_touch: bool = False
    grid: tuple[int, int] | None = None


VARIANTS = {
    "as-is": Variant(),
    "noslip-off": Variant(noslip=0),
    "noslip-touch": Variant(noslip_on_touch=True),
    "dt-4ms": Variant(timestep=0.004),
    "dt-5ms": Variant(timestep=0.005),
    "dt-4ms-noslip-touch": Variant(timestep=0.004, noslip_on_touch=True),
    "grid-5": Variant(grid=(5, 5)),
}


@contextmanager
def towel_physics(variant: Variant) -> Iterator[None]:
    """Worlds built inside take the variant's settings when their scene has a cloth."""
    init, step, count = sim_world.SimWorld.__init__, sim_world.SimWorld.step, FoldTowel.COUNT

    def patched_init(world, scene, *args, **kwargs):
        if scene.cloth is not None and variant.timestep is not None:
            scene.timestep = variant.timestep
        init(world, scene, *args, **kwargs)
        if scene.cloth is not None and variant.noslip is not None:
            world.model.opt.noslip_iterations = variant.noslip

    def touch_step(world):
        if world.scene.cloth is not None:
            # The contacts of the last tick: a pinch loads the cloth on the ticks after it closed on it.
            world.model.opt.noslip_iterations = 3 if world._finger_cloth_contacts else 0
        step(world)

    sim_world.SimWorld.__init__ = patched_init
    if variant.noslip_on_touch:
        sim_world.SimWorld.step = touch_step
    if variant.grid is not None:
        FoldTowel.COUNT = variant.grid
    try:
        yield
    finally:
        sim_world.SimWorld.__init__, sim_world.SimWorld.step, FoldTowel.COUNT = init, step, count


def run_variant(variant: Variant, seeds: list[int], protocol: str | None) -> dict:
    """Episodes of one variant: successes, the reasons of the others, the median speed (x real time)."""
    setting = DisturbanceSetting.from_options(protocol=protocol) if protocol else DisturbanceSetting.from_options()
    speeds, failed = [], []
    with towel_physics(variant):
        for seed in seeds:
            result = run_episode(EpisodeSpec(TASK, seed=seed, disturbances=setting))
            speeds.append(result.time_s / result.wall_s)
            if not result.success:
                failed.append(f"{seed}: {result.reason[:70]}")
    return {"success": len(seeds) - len(failed), "speed": statistics.median(speeds), "failed": failed}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="0,1,2", help="comma-separated seeds")
    parser.add_argument("--protocols", default="none,real", help="comma-separated: none, real, stress")
    parser.add_argument("--variants", default="all", help=f"comma-separated: {', '.join(VARIANTS)}")
    args = parser.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    names = list(VARIANTS) if args.variants == "all" else args.variants.split(",")
    unknown = [n for n in names if n not in VARIANTS]
    if unknown:
        parser.error(f"--variants: unknown {', '.join(unknown)} (known: {', '.join(VARIANTS)})")
    table = Table(title=f"fold towel, seeds {args.seeds}: the towel's physics against the fold")
    for column in ("variant", "protocol", "success", "x real time (median)", "failures"):
        table.add_column(column)
    for name in names:
        for protocol in args.protocols.split(","):
            row = run_variant(VARIANTS[name], seeds, None if protocol == "none" else protocol)
            table.add_row(name, protocol, f"{row['success']}/{len(seeds)}", f"{row['speed']:.2f}", "\n".join(row["failed"]))
    Console().print(table)


if __name__ == "__main__":
    main()
