"""Where objects end up after each disturbance kind (docs/disturbances.md states the models).

Per kind, one scripted disturbance per seed in the same scenario (``bench.landing.SCENARIOS``),
the object measured once at rest: distance moved, share upright, share each arm could take
(reach model confirmed by the IK), share off the table. Printed, not asserted (the tests
check the stated ranges on a few seeds).

    .venv/bin/python benchmarks/bench_disturbances.py [--seeds 20] [--kinds drop,pull,perturb,shift,knock]
"""

from __future__ import annotations

import argparse
import multiprocessing

from rich.console import Console
from rich.table import Table

from agentchord.bench.landing import SCENARIOS, landing, summarise


def _one(job: tuple[str, int]):
    return landing(*job)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--kinds", default=",".join(SCENARIOS))
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    kinds = [k.strip() for k in args.kinds.split(",") if k.strip()]
    jobs = [(kind, seed) for kind in kinds for seed in range(args.seeds)]
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        results = pool.map(_one, jobs)
    table = Table(title=f"Landing of disturbed objects ({args.seeds} seeds per kind)")
    for column in ("kind", "scenario", "n", "moved median (5-95%) cm", "upright", "left reaches", "right reaches",
                   "some arm reaches", "off table"):
        table.add_column(column, justify="right")
    for kind in kinds:
        stats = summarise([r for r in results if r is not None and r.kind == kind])
        task, obj, action, after = SCENARIOS[kind]
        table.add_row(
            kind, f"{obj} during {action}", str(stats["n"]),
            f"{100 * stats['moved_median_m']:.1f} ({100 * stats['moved_p5_m']:.1f}-{100 * stats['moved_p95_m']:.1f})",
            *(f"{100 * stats[k]:.0f}%" for k in ("upright", "reach_left", "reach_right", "reach_any", "off_table")),
        )
    Console().print(table)


if __name__ == "__main__":
    main()
