"""Cost of evaluating the active edge's compiled monitors, per tick, for every edge of a task.

Target (printed, not asserted): <= 100 us per tick for the active monitors.

    .venv/bin/python benchmarks/bench_monitors.py [--task single_arm_pour_water]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from rich.console import Console
from rich.table import Table

from agentchord.expr import Vocabulary, compile_expr
from agentchord.features.oracle import OracleExtractor
from agentchord.monitor import EdgeMonitors
from agentchord.library import load_task_graph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--task", default="single_arm_pour_water")
    parser.add_argument("--ticks", type=int, default=5000)
    args = parser.parse_args()
    graph = load_task_graph(args.task)
    world = SimWorld(SIM_TASKS[args.task].sample_scene(np.random.default_rng(0)))
    frame = OracleExtractor(world).update()
    vocabulary = Vocabulary(frozenset(graph.objects))

    table = Table(title=f"{args.task}: compiled monitors per tick (target <= 100 us)")
    for column in ("edge", "kind", "monitors", "us per tick", "compile us"):
        table.add_column(column, justify="right")
    worst = 0.0
    for edge in graph.edges:
        if not edge.failures:
            continue
        t0 = time.perf_counter()
        monitors = EdgeMonitors.compile(edge, vocabulary)
        compile_us = (time.perf_counter() - t0) * 1e6
        t0 = time.perf_counter()
        for _ in range(args.ticks):
            monitors.evaluate(frame)
            monitors.reset()  # keep the triggers from firing: we time evaluation only
        per_tick = (time.perf_counter() - t0) / args.ticks * 1e6
        worst = max(worst, per_tick)
        table.add_row(edge.id, edge.kind, str(len(monitors.monitors)), f"{per_tick:.1f}", f"{compile_us:.0f}")
    Console().print(table)
    constraints = [compile_expr(c, vocabulary) for node in graph.nodes for c in node.constraints]
    t0 = time.perf_counter()
    for _ in range(args.ticks):
        for c in constraints:
            c.scalar(frame)
    all_us = (time.perf_counter() - t0) / args.ticks * 1e6
    Console().print(f"worst edge: {worst:.1f} us per tick; all {len(constraints)} node constraints of the graph: {all_us:.1f} us")


if __name__ == "__main__":
    main()
