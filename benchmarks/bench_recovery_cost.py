"""The same forced drop, on each edge that holds the bottle, for AgentChord and AgentChord-BT.

A controlled ablation (paper Appendix E-C): identical scenes and identical disturbances, so the
difference in steps is the price of regressive backtracking over forward-moving recovery.

    .venv/bin/python benchmarks/bench_recovery_cost.py [--seeds 5]
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from statistics import mean

from rich.console import Console
from rich.table import Table

from agentchord.bench.runner import run_many
from agentchord.episode import EpisodeSpec
from agentchord.sim.disturbances import ScriptedDrop

TASK = "single_arm_pour_water"
#: (label, atomic action, which run of it, ticks into it): one drop on each bottle-holding edge.
CASES = [
    ("e1 grasp (lifting)", "grasp", 0, 160),
    ("e2 move to cup", "move_to_obj", 0, 30),
    ("e3 pour (early)", "rotate_eef", 0, 12),
    ("e4 back upright (late)", "rotate_eef", 1, 70),
    ("e5 place (lowering)", "place", 0, 50),
]
STRATEGIES = ("agentchord", "agentchord-bt")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    specs = [
        EpisodeSpec(TASK, strategy=strategy, seed=seed, disturbance=ScriptedDrop(action, nth, after))
        for label, action, nth, after in CASES
        for strategy in STRATEGIES
        for seed in range(args.seeds)
    ]
    results: dict[tuple[str, str], list[dict]] = defaultdict(list)
    case_of = {(c[1], c[2], c[3]): c[0] for c in CASES}
    for spec, summary in run_many(specs, workers=args.workers):
        d = spec.disturbance
        results[(case_of[(d.action, d.nth, d.after)], spec.strategy)].append(summary)
    table = Table(title=f"{TASK}: one forced drop per episode, {args.seeds} seeds per cell")
    table.add_column("drop during")
    for strategy in STRATEGIES:
        table.add_column(f"{strategy} success", justify="right")
        table.add_column(f"{strategy} steps", justify="right")
    table.add_column("steps saved", justify="right")
    for label, *_ in CASES:
        row = [label]
        steps = {}
        for strategy in STRATEGIES:
            runs = results[(label, strategy)]
            done = [r["steps"] for r in runs if r["success"]]
            steps[strategy] = mean(done) if done else None
            row += [f"{sum(r['success'] for r in runs)}/{len(runs)}", "-" if not done else f"{mean(done):.0f}"]
        a, b = steps["agentchord"], steps["agentchord-bt"]
        row.append("-" if a is None or b is None else f"{b - a:.0f}")
        table.add_row(*row)
    console = Console(width=140)
    console.print(table)
    console.print("steps = control ticks (50 Hz) over the successful episodes of the cell")


if __name__ == "__main__":
    main()
