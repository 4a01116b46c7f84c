"""Paired comparisons: one method against each other one on the same seeded episodes.

Every method of a sweep runs the same (task, condition, seed) episodes: the same scene and the
same disturbance schedule. Comparing two methods episode by episode, over the episodes both
complete, takes each episode's own difficulty out of the difference; a per-method mean over
its own successes does not (a method that loses the long, disturbed episodes averages over the
short ones). Pure functions: records in, rows and Markdown/CSV text out.
"""

from __future__ import annotations

import csv
import io
from collections import defaultdict
from dataclasses import dataclass
from statistics import mean

from agentchord.bench.tables import markdown_table, mean_ci, ordered
from agentchord.execution.methods import METHODS, SHORT

#: The method compared against the others unless told otherwise.
REFERENCE = "agentchord"


@dataclass(frozen=True)
class Difference:
    """A paired mean difference (reference minus other) with its 95% Student-t interval."""

    n: int
    reference: float
    other: float
    low: float
    high: float
    reference_better: int  # episodes where the reference is strictly lower

    @property
    def mean(self) -> float:
        """Mean difference, reference minus other (negative: the reference is lower)."""
        return self.reference - self.other


@dataclass(frozen=True)
class PairedRow:
    """The reference against one method.

    Attributes:
        method: The other method.
        both_complete: Episodes both methods completed.
        exec_time_s: Execution time over those episodes.
        robot_and_compute_s: Robot time plus measured compute over them (no modelled reasoning).
        steps: Control ticks over those of them that saw a disturbance (in either run).
        first_motion_s: Time to first motion over the episodes both completed.
        critical_reasoning_s: Reasoning on the critical path (all the robot held still for) over them.
    """

    method: str
    both_complete: int
    exec_time_s: Difference | None
    robot_and_compute_s: Difference | None
    steps: Difference | None
    first_motion_s: Difference | None = None
    critical_reasoning_s: Difference | None = None


def _difference(pairs: list[tuple[float, float]]) -> Difference | None:
    if not pairs:
        return None
    _, ci = mean_ci([a - b for a, b in pairs])
    assert ci is not None  # pairs is not empty
    low, high = ci
    return Difference(n=len(pairs), reference=mean(a for a, _ in pairs), other=mean(b for _, b in pairs),
                      low=low, high=high, reference_better=sum(a < b for a, b in pairs))


def _episodes(records: list[dict]) -> dict[tuple[str, str, int], dict[str, dict]]:
    """(task, condition, seed) -> method -> record."""
    episodes: dict[tuple[str, str, int], dict[str, dict]] = defaultdict(dict)
    for record in records:
        episodes[(record["task"], record["condition"], record["seed"])][record["method"]] = record
    return episodes


def _disturbed(*runs: dict) -> bool:
    return any(run["disturbances_injected"] > 0 for run in runs)


def paired_rows(records: list[dict], reference: str = REFERENCE) -> list[PairedRow]:
    """The reference against every other method of the records, in the paper's method order.

    Raises:
        ValueError: The records hold no episode of ``reference``.
    """
    episodes = _episodes(records)
    methods = {m for runs in episodes.values() for m in runs}
    if reference not in methods:
        raise ValueError(f"no records of {reference!r} (methods: {', '.join(sorted(methods))})")
    others = ordered(methods - {reference}, METHODS)
    rows = []
    for method in others:
        both = [(runs[reference], runs[method]) for runs in episodes.values()
                if reference in runs and method in runs and runs[reference]["success"] and runs[method]["success"]]
        rows.append(PairedRow(
            method=method,
            both_complete=len(both),
            exec_time_s=_difference([(a["exec_time_s"], b["exec_time_s"]) for a, b in both]),
            robot_and_compute_s=_difference([(a["robot_time_s"] + a["compute_s"], b["robot_time_s"] + b["compute_s"])
                                             for a, b in both]),
            steps=_difference([(a["steps"], b["steps"]) for a, b in both if _disturbed(a, b)]),
            first_motion_s=_difference([(a["first_motion_s"], b["first_motion_s"]) for a, b in both
                                        if a.get("first_motion_s") is not None and b.get("first_motion_s") is not None]),
            critical_reasoning_s=_difference([(a["critical_reasoning_s"], b["critical_reasoning_s"]) for a, b in both
                                              if a.get("critical_reasoning_s") is not None
                                              and b.get("critical_reasoning_s") is not None]),
        ))
    return rows


def common_steps(records: list[dict]) -> tuple[int, dict[str, float]]:
    """Mean steps per method over the disturbed episodes every method of the records completed.

    Returns:
        How many such episodes there are, and each method's mean steps over them (empty if none).
    """
    episodes = _episodes(records)
    methods = ordered({m for runs in episodes.values() for m in runs}, METHODS)
    common = [runs for runs in episodes.values()
              if all(m in runs and runs[m]["success"] for m in methods) and _disturbed(*runs.values())]
    if not common:
        return 0, {}
    return len(common), {m: mean(runs[m]["steps"] for runs in common) for m in methods}


def _cells(d: Difference | None, digits: int) -> list[str]:
    """``reference / other``, ``Δ [low, high]``, ``wins/n``."""
    if d is None:
        return ["-", "-", "-"]
    # One pair (or pairs all alike) has no spread to make an interval of: say so, not "+165 [+165, +165]".
    interval = (f"[{d.low:+.{digits}f}, {d.high:+.{digits}f}]" if d.n > 1 and d.low != d.high
                else f"(no interval: {d.n} pair{'' if d.n == 1 else 's'})")
    return [f"{d.reference:.{digits}f} / {d.other:.{digits}f}", f"{d.mean:+.{digits}f} {interval}", f"{d.reference_better}/{d.n}"]


def paired_layout(records: list[dict], reference: str = REFERENCE) -> tuple[list[str], list[list[str]]]:
    """Header and rows: per other method, time and steps of both, the paired difference, the wins."""
    ref = SHORT.get(reference, reference)
    header = ["Method", "Both complete",
              f"Exec. time s {ref} / other", "Δ s [95% CI]", f"{ref} faster in",
              f"Robot + compute s {ref} / other", "Δ s [95% CI]",
              f"Steps {ref} / other (disturbed)", "Δ [95% CI]", f"{ref} fewer in",
              f"First motion s {ref} / other", f"Critical reasoning s {ref} / other"]
    rows = []
    for row in paired_rows(records, reference):
        rows.append([SHORT.get(row.method, row.method), str(row.both_complete), *_cells(row.exec_time_s, 1),
                     *_cells(row.robot_and_compute_s, 1)[:2], *_cells(row.steps, 0),
                     _cells(row.first_motion_s, 1)[0], _cells(row.critical_reasoning_s, 1)[0]])
    return header, rows


def paired_markdown(records: list[dict], reference: str = REFERENCE) -> str:
    """The paired table, its reading, and the steps over the episodes every method completed."""
    header, rows = paired_layout(records, reference)
    ref = SHORT.get(reference, reference)
    n, steps = common_steps(records)
    common = (f"Steps over the {n} disturbed episodes every method completed: "
              + ", ".join(f"{SHORT.get(m, m)} {value:.0f}" for m, value in steps.items()) + "."
              if n else "No disturbed episode was completed by every method.")
    return (f"### Paired: {ref} against each method on the same episodes\n\n" + markdown_table(header, rows) + "\n"
            f"Over the episodes both methods completed (same task, condition and seed: the same scene and "
            f"disturbance schedule); steps over those of them with a disturbance in either run. "
            f"Δ = {ref} minus the other method, mean with its 95% t-interval; negative: {ref} is lower. "
            f"Robot + compute leaves out the modelled reasoning latency. First motion: the reasoning (and compute) "
            f"the robot waited for before it moved; critical reasoning: all it held still for.\n\n{common}\n")


def paired_csv(records: list[dict], reference: str = REFERENCE) -> str:
    """The paired rows as CSV (one row per other method, every number)."""
    out = io.StringIO()
    writer = csv.writer(out)
    fields = ("n", "reference", "other", "mean", "low", "high", "reference_better")
    metrics = ("exec_time_s", "robot_and_compute_s", "steps", "first_motion_s", "critical_reasoning_s")
    writer.writerow(["reference", "method", "both_complete"] + [f"{m}_{f}" for m in metrics for f in fields])
    for row in paired_rows(records, reference):
        values = []
        for metric in metrics:
            d = getattr(row, metric)
            if d is None:
                values += [""] * len(fields)
            else:
                values += [d.n, *(round(x, 3) for x in (d.reference, d.other, d.mean, d.low, d.high)), d.reference_better]
        writer.writerow([reference, row.method, row.both_complete, *values])
    return out.getvalue()
