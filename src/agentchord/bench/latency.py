"""A sweep's execution times at other reasoning latencies: the same episodes, re-priced.

Offline every reasoning call is charged a stated latency, and the robot holds still while a
model answers (the world is not stepped). An episode's physics, steps and calls are therefore
the same at any latency, and its execution time at the latencies scaled by ``s`` is exactly
``robot time + compute + s * reasoning latency``. No episode is run again. A pipelined plan's
parts arriving while the robot moves cost only the ticks it waited for one; those are re-priced
with the reasoning, which is exact at ``s = 1`` and an approximation elsewhere.

A method's average over a table's rows (the tables' "Average" row) is then a line in ``s``:
``A + s R``, with ``A`` its robot time plus compute and ``R`` its reasoning latency, each
averaged like the table averages time. Two methods' lines cross at most once, so "faster below
this latency" is exact, not read off a grid. Pure functions: records in, rows and text out.
"""

from __future__ import annotations

import csv
import io
import math
from collections import defaultdict
from dataclasses import dataclass
from statistics import mean

from agentchord.bench.paired import REFERENCE
from agentchord.bench.tables import markdown_table, ordered
from agentchord.execution.methods import METHODS, SHORT

#: Latency scales tabled (x the sweep's latency model): none, faster models, as run, slower ones.
SCALES = (0.0, 0.1, 0.25, 0.5, 1.0, 2.0, 3.0)


@dataclass(frozen=True)
class TimeLine:
    """A method's average execution time as a function of the latency scale ``s``: ``base + s * reasoning``.

    Attributes:
        base: Robot time plus measured compute (s), averaged over the rows the method has.
        reasoning: Reasoning latency at the sweep's latency model (s), averaged the same way.
        rows: The (task, condition) rows averaged (those where the method completed an episode).
    """

    base: float
    reasoning: float
    rows: int

    def at(self, scale: float) -> float:
        """The average execution time (s) with every latency multiplied by ``scale``."""
        return self.base + scale * self.reasoning


def time_lines(records: list[dict]) -> dict[str, TimeLine]:
    """Per method, its average execution time as a line in the latency scale.

    Each (task, condition, method) cell is the mean over its successful episodes, and a method's
    line the mean over its cells, as the tables' average row is: at scale 1 it is that row's time.
    """
    won: dict[tuple[str, str, str], list[dict]] = defaultdict(list)
    for record in records:
        if record["success"]:
            won[(record["task"], record["condition"], record["method"])].append(record)
    cells: dict[str, list[tuple[float, float]]] = defaultdict(list)
    for (_, _, method), rows in won.items():
        # A pipelined plan's waits for parts that had not arrived scale with the latency too (exact at x1,
        # approximate elsewhere: the episodes would differ where a wait appears or vanishes).
        base = mean(r["robot_time_s"] + r["compute_s"] - r.get("plan_wait_s", 0.0) for r in rows)
        cells[method].append((base, mean(r["reasoning_s"] + r.get("plan_wait_s", 0.0) for r in rows)))
    return {
        method: TimeLine(base=mean(b for b, _ in values), reasoning=mean(r for _, r in values), rows=len(values))
        for method, values in cells.items()
    }


@dataclass(frozen=True)
class Crossing:
    """Where the reference's line meets another method's.

    Attributes:
        method: The other method.
        scale: The latency scale where both average the same time; None where the lines do not
            meet at a positive scale.
        faster_below: Whether the reference is the faster one below ``scale`` (else above it).
            Without a crossing: whether it is faster (or level) at every scale.
    """

    method: str
    scale: float | None
    faster_below: bool


def crossing(reference: TimeLine, other: TimeLine, method: str) -> Crossing:
    """Where ``reference`` and ``other`` take the same average time, and which side is the reference's."""
    slope = reference.reasoning - other.reasoning
    gap = other.base - reference.base  # the reference's lead with no reasoning at all
    if math.isclose(slope, 0.0, abs_tol=1e-9):
        return Crossing(method, None, gap >= 0.0)
    scale = gap / slope
    if scale <= 0.0:
        # Met at no positive scale: one line lies under the other for every s > 0.
        return Crossing(method, None, reference.at(1.0) <= other.at(1.0))
    return Crossing(method, scale, slope > 0.0)


def latency_rows(records: list[dict], plan_s: float, scales=SCALES) -> tuple[list[str], list[list[str]]]:
    """Header and rows: each method's average execution time at each latency scale, and the fastest."""
    lines = time_lines(records)
    methods = ordered(set(lines), METHODS)
    header = ["Latency x", "Planning call s"] + [SHORT.get(m, m) for m in methods] + ["Fastest"]
    rows = []
    for scale in scales:
        times = {m: lines[m].at(scale) for m in methods}
        fastest = min(times.values())
        best = [SHORT.get(m, m) for m in methods if math.isclose(times[m], fastest, abs_tol=0.05)]
        rows.append([f"{scale:g}", f"{round(scale * plan_s, 2):g}"] + [f"{times[m]:.1f}" for m in methods] + [", ".join(best)])
    return header, rows


def crossings_text(records: list[dict], plan_s: float, reference: str = REFERENCE) -> str:
    """One sentence per other method: at which latencies the reference is the faster of the two."""
    lines = time_lines(records)
    if reference not in lines:
        return ""
    name = SHORT.get(reference, reference)
    out = []
    for method in ordered(set(lines) - {reference}, METHODS):
        found = crossing(lines[reference], lines[method], method)
        other = SHORT.get(method, method)
        ours, theirs = lines[reference], lines[method]
        if math.isclose(ours.base, theirs.base, abs_tol=0.05) and math.isclose(ours.reasoning, theirs.reasoning, abs_tol=0.05):
            out.append(f"- {name} takes the same time as {other} at every latency.")
        elif found.scale is None:
            side = "faster than" if found.faster_below else "slower than"
            out.append(f"- {name} is {side} {other} at every latency.")
        else:
            side = "below" if found.faster_below else "above"
            out.append(f"- {name} is faster than {other} {side} x{found.scale:.2f} the stated latencies "
                       f"(a planning call of {found.scale * plan_s:.2f} s).")
    return "\n".join(out)


def latency_markdown(records: list[dict], plan_s: float, caption: str) -> str:
    """The table, the crossings and how they were computed, as Markdown."""
    header, rows = latency_rows(records, plan_s)
    return (f"### Execution time at other reasoning latencies\n\n{markdown_table(header, rows)}\n"
            f"{crossings_text(records, plan_s)}\n\n"
            "Each cell is the method's average execution time (s) over the table's rows, as in the "
            "tables' Average row, with every reasoning call's latency multiplied by the scale (x1: as "
            "run). The robot holds still while a model answers, so the episodes are the same at every "
            "latency and only their price changes; AgentChord's pipelined plan is the exception in part: "
            "the ticks it held still for a branch that had not arrived are scaled with the latency, exact at "
            f"x1 and approximate elsewhere (a wait may appear or vanish). {caption}\n")


def latency_csv(records: list[dict], plan_s: float) -> str:
    """The table as CSV, with each method's line (robot + compute, reasoning at x1)."""
    header, rows = latency_rows(records, plan_s)
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerows([header, *rows])
    writer.writerow([])
    writer.writerow(["method", "robot_and_compute_s", "reasoning_s_at_x1", "rows"])
    for method, line in sorted(time_lines(records).items(), key=lambda item: METHODS.index(item[0]) if item[0] in METHODS else 99):
        writer.writerow([method, round(line.base, 3), round(line.reasoning, 3), line.rows])
    return out.getvalue()
