"""Reading instructions: parse + ground + compose per instruction of the paraphrase suite.

For every case of tests/data/paraphrases.yaml that states a goal: the time to parse the
instruction (lark grammar), ground it in its scene (goal predicates), and compose the
nominal graph (STRIPS plan + schedule), the best of ``--repeats`` runs; one row per task,
median and max over its instructions. Target (printed, not asserted): every instruction
read and planned in <= 150 ms (one core). The grammar is built once per process (its own row).
Arranging and conducting the graph are benchmarks/bench_planning.py's.

    .venv/bin/python benchmarks/bench_language.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import yaml
from rich.console import Console
from rich.table import Table

from agentchord.agents.exceptions import ReasonerError
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.rules.composer import compose
from agentchord.agents.rules.instructions import read_instruction
from agentchord.agents.rules.language import parse, parser
from agentchord.worlds.sim.tasks import SIM_TASKS
from agentchord.worlds.sim.world import SimWorld

SUITE = Path(__file__).resolve().parents[1] / "tests" / "data" / "paraphrases.yaml"
TARGET_MS = 150.0


def main() -> None:
    args_parser = argparse.ArgumentParser(description=__doc__)
    args_parser.add_argument("--repeats", type=int, default=3)
    args = args_parser.parse_args()
    cases = [c for c in yaml.safe_load(SUITE.read_text())["cases"] if "goal" in c]
    start = time.perf_counter()
    parser()
    build_ms = 1000.0 * (time.perf_counter() - start)
    scenes = {}
    refused: list[str] = []
    rows: dict[str, list[tuple[float, float, float, float]]] = defaultdict(list)
    for case in cases:
        task = case["task"]
        if task not in scenes:
            sim = SIM_TASKS[task]
            scenes[task] = observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))
        best = None
        try:
            read_instruction(case["instruction"], scenes[task])
        except ReasonerError:
            refused.append(case["instruction"])  # timed only where it reads (the suite's misses are refused)
            continue
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            parse(case["instruction"])
            t1 = time.perf_counter()
            reading = read_instruction(case["instruction"], scenes[task])  # parses again: grounding's own cost is the difference
            t2 = time.perf_counter()
            compose(reading.goal, scenes[task], task, case["instruction"])
            t3 = time.perf_counter()
            parse_ms, ground_ms, compose_ms = 1000 * (t1 - t0), 1000 * (t2 - t1 - (t1 - t0)), 1000 * (t3 - t2)
            total = 1000 * (t3 - t1)
            if best is None or total < best[3]:
                best = (parse_ms, max(0.0, ground_ms), compose_ms, total)
        rows[task].append(best)
    table = Table(title=f"Reading instructions (rules reasoner), best of {args.repeats}; target <= {TARGET_MS:.0f} ms per instruction")
    for column in ("task", "instructions", "parse ms", "ground ms (beyond parse)", "compose ms", "total ms (median)", "total ms (max)", "ok"):
        table.add_column(column, justify="left" if column == "task" else "right")
    worst = 0.0
    for task, values in rows.items():
        totals = [v[3] for v in values]
        worst = max(worst, max(totals))
        table.add_row(
            task, str(len(values)), f"{statistics.median(v[0] for v in values):.1f}", f"{statistics.median(v[1] for v in values):.1f}",
            f"{statistics.median(v[2] for v in values):.1f}", f"{statistics.median(totals):.1f}", f"{max(totals):.1f}",
            "PASS" if max(totals) <= TARGET_MS else "FAIL",
        )
    everything = [v[3] for values in rows.values() for v in values]
    table.add_row("all", str(len(everything)), "", "", "", f"{statistics.median(everything):.1f}", f"{max(everything):.1f}",
                  "PASS" if worst <= TARGET_MS else "FAIL")
    console = Console()
    console.print(table)
    console.print(f"grammar built once per process: {build_ms:.0f} ms; not timed (refused): {len(refused)}")


if __name__ == "__main__":
    main()
