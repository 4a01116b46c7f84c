"""A sweep's records as the paper's tables (I, II, V), with 95% confidence intervals.

Pure functions: records in, rows and Markdown/CSV text out. Conventions (docs/results.md):

- success rate with its Wilson score interval;
- execution time = robot time + measured compute + reasoning latency, averaged over the
  successful episodes (the paper measures it "until the task is completed"; a failed
  episode ends early and would flatter a method that gives up), with a Student-t interval;
- steps (control ticks) over the successful episodes that saw a disturbance, the episodes
  where recovery is what is compared;
- time to first motion (the reasoning and compute the robot waited for before it moved) and
  reasoning on the critical path (all the robot held still for: before its first motion, for a
  blocking call, for a part of a pipelined plan), over the successful episodes like time.
"""

from __future__ import annotations

import csv
import io
import math
from collections import defaultdict
from dataclasses import dataclass
from statistics import mean, stdev

from scipy import stats as scipy_stats

from agentchord.bench.report import wilson_interval
from agentchord.execution.methods import METHODS, SHORT

#: The paper's task order and names.
TASK_TITLES = {
    "single_arm_pour_water": "Single-arm pour water",
    "dual_arm_pour_water": "Dual-arm pour water",
    "rearrange_table": "Rearrange table",
    "handover_block": "Handover block",
    "fold_towel": "Fold towel",
    "setup_coffee_tray": "Setup coffee tray",
}
#: Table V's methods: ReKep, the backtracking ablation, AgentChord.
ABLATION_METHODS = ("rekep", "agentchord-bt", "agentchord")


@dataclass(frozen=True)
class Cell:
    """One method's aggregates on one task under one condition."""

    n: int
    successes: int
    success_ci: tuple[float, float]
    time_s: float | None
    time_ci: tuple[float, float] | None
    robot_time_s: float | None
    reasoning_s: float | None
    steps_disturbed: float | None
    disturbed: int
    reasoning_calls: float
    replans: float
    first_motion_s: float | None = None
    critical_reasoning_s: float | None = None

    @property
    def success_rate(self) -> float:
        """Successes over episodes."""
        return self.successes / self.n if self.n else 0.0


def mean_ci(values: list[float]) -> tuple[float | None, tuple[float, float] | None]:
    """Mean and its 95% Student-t interval (the mean itself for one value; ``None`` for none)."""
    if not values:
        return None, None
    centre = mean(values)
    if len(values) < 2:
        return centre, (centre, centre)
    half = float(scipy_stats.t.ppf(0.975, len(values) - 1)) * stdev(values) / math.sqrt(len(values))
    return centre, (centre - half, centre + half)


def cell(records: list[dict]) -> Cell:
    """The aggregates of one (task, condition, method) group of records."""
    n = len(records)
    successes = sum(bool(r["success"]) for r in records)
    won = [r for r in records if r["success"]]
    time_s, time_ci = mean_ci([r["exec_time_s"] for r in won])
    disturbed = [r for r in won if r["disturbances_injected"] > 0]
    return Cell(
        n=n, successes=successes, success_ci=wilson_interval(successes, n),
        time_s=time_s, time_ci=time_ci,
        robot_time_s=mean(r["robot_time_s"] for r in won) if won else None,
        reasoning_s=mean(r["reasoning_s"] for r in won) if won else None,
        steps_disturbed=mean(r["steps"] for r in disturbed) if disturbed else None,
        disturbed=len([r for r in records if r["disturbances_injected"] > 0]),
        reasoning_calls=mean(sum(r["reasoning_calls"].values()) for r in records) if records else 0.0,
        replans=mean(r["replans"] for r in records) if records else 0.0,
        first_motion_s=_mean_of(won, "first_motion_s"),
        critical_reasoning_s=_mean_of(won, "critical_reasoning_s"),
    )


def _mean_of(records: list[dict], name: str) -> float | None:
    """The mean of a field over records that have it (records written before the field lack it)."""
    values = [r[name] for r in records if r.get(name) is not None]
    return mean(values) if values else None


def group(records: list[dict]) -> dict[tuple[str, str, str], Cell]:
    """Aggregates per (task, condition, method)."""
    groups: dict[tuple[str, str, str], list[dict]] = defaultdict(list)
    for record in records:
        groups[(record["task"], record["condition"], record["method"])].append(record)
    return {key: cell(rows) for key, rows in groups.items()}


def ordered(names, order) -> list[str]:
    """``names`` in ``order``, unknown ones last, sorted."""
    known = [n for n in order if n in names]
    return known + sorted(set(names) - set(known))


def _pct(c: Cell | None) -> str:
    if c is None:
        return "-"
    low, high = c.success_ci
    return f"{100 * c.success_rate:.0f} [{100 * low:.0f}, {100 * high:.0f}]"


def _time(c: Cell | None) -> str:
    if c is None or c.time_s is None or c.time_ci is None:  # time_ci is None exactly when time_s is
        return "-"
    low, high = c.time_ci
    return f"{c.time_s:.1f} ± {(high - low) / 2:.1f}"


def _steps(c: Cell | None) -> str:
    return "-" if c is None or c.steps_disturbed is None else f"{c.steps_disturbed:.0f}"


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"


#: Per-method column groups of a table: header prefix, cell text, the value the average row means.
_PARTS = {
    "success": ("Success %", _pct, lambda c: 100 * c.success_rate, "{:.1f}"),
    "time": ("Exec. time s", _time, lambda c: c.time_s, "{:.1f}"),
    "first": ("First motion s", lambda c: "-" if c is None else _seconds(c.first_motion_s), lambda c: c.first_motion_s, "{:.1f}"),
    "critical": ("Critical reasoning s", lambda c: "-" if c is None else _seconds(c.critical_reasoning_s),
                 lambda c: c.critical_reasoning_s, "{:.1f}"),
    "steps": ("Steps", _steps, lambda c: c.steps_disturbed, "{:.0f}"),
}


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _average_row(cells: dict, keys: list[tuple[str, str]], methods: list[str], parts: list[str], with_condition: bool) -> list[str]:
    """Mean over the table's rows of each method's figures (blank where no row has one)."""
    row = ["Average", ""] if with_condition else ["Average"]
    for part in parts:
        _, _, value, form = _PARTS[part]
        for method in methods:
            found = [cells.get((task, cond, method)) for task, cond in keys]
            values = [value(c) for c in found if c is not None]
            values = [v for v in values if v is not None]
            row.append(form.format(mean(values)) if values else "-")
    return row


def table_layout(records: list[dict], methods: list[str] | None = None, with_steps: bool = True,
                 with_condition: bool = True, with_timing: bool = True) -> tuple[list[str], list[list[str]]]:
    """Rows in the paper's layout: a row per task (and condition), per method success | time (| time to first
    motion | reasoning on the critical path) (| steps)."""
    cells = group(records)
    methods = ordered({m for _, _, m in cells} if methods is None else methods, METHODS)
    tasks = ordered({t for t, _, _ in cells}, list(TASK_TITLES))
    conditions = sorted({c for _, c, _ in cells}, key=lambda label: (label.startswith("protocol"), label))
    parts = ["success", "time"] + (["first", "critical"] if with_timing else []) + (["steps"] if with_steps else [])
    header = ["Task"] + (["Condition"] if with_condition else [])
    header += [f"{_PARTS[part][0]} {SHORT.get(m, m)}" for part in parts for m in methods]
    rows, keys = [], []
    for task in tasks:
        for condition in conditions:
            if not any((task, condition, m) in cells for m in methods):
                continue
            keys.append((task, condition))
            row = [TASK_TITLES.get(task, task)] + ([condition] if with_condition else [])
            row += [_PARTS[part][1](cells.get((task, condition, m))) for part in parts for m in methods]
            rows.append(row)
    rows.append(_average_row(cells, keys, methods, parts, with_condition))
    return header, rows


#: The widest line a table is meant to take (a terminal of 120 characters).
MAX_TABLE_WIDTH = 120


def table_markdown(records: list[dict], title: str, caption: str, methods: list[str] | None = None,
                   with_steps: bool = True, with_condition: bool = True, with_timing: bool = True) -> str:
    """Titled Markdown tables, each narrow enough for a terminal of 120 characters, with the caption.

    The main table has the paper's own columns, success with its interval and execution time, a row per
    method of each task (and condition); the time to the first motion with the reasoning on its critical
    path, and the steps of disturbed successful episodes, have tables of their own.
    """
    cells = group(records)
    methods = ordered({m for _, _, m in cells} if methods is None else methods, METHODS)
    keys = _row_keys(cells, methods)
    lead = ["Task"] + (["Condition"] if with_condition else [])

    def lead_of(task: str, condition: str, first: bool) -> list[str]:
        # The task (and condition) once per block of method rows, as a person reads it.
        return ([TASK_TITLES.get(task, task)] + ([condition] if with_condition else [])) if first else [""] * len(lead)

    main = []
    for task, condition in keys:
        for k, method in enumerate(m for m in methods if (task, condition, m) in cells):
            c = cells[(task, condition, method)]
            main.append([*lead_of(task, condition, k == 0), SHORT.get(method, method), _pct(c), _time(c)])
    for k, method in enumerate(methods):
        found = [cells[(t, cond, method)] for t, cond in keys if (t, cond, method) in cells]
        times = [c.time_s for c in found if c.time_s is not None]
        main.append([*(["Average"] if k == 0 else [""]), *([""] if with_condition else []), SHORT.get(method, method),
                     f"{mean(100 * c.success_rate for c in found):.1f}" if found else "-", f"{mean(times):.1f}" if times else "-"])
    parts = [f"### {title}\n\n" + markdown_table([*lead, "Method", "Success % [95% CI]", "Exec. time s"], main)]
    if with_timing and any(c.first_motion_s is not None for c in cells.values()):
        timing = [[*lead_of(task, condition, k == 0), SHORT.get(method, method), _seconds(c.first_motion_s), _seconds(c.critical_reasoning_s)]
                  for task, condition in keys
                  for k, (method, c) in enumerate((m, cells[(task, condition, m)]) for m in methods if (task, condition, m) in cells)]
        parts.append(f"#### {title}: time to the first motion\n\n"
                     + markdown_table([*lead, "Method", "First motion s", "Critical reasoning s"], timing))
    if with_steps:
        header = [*lead, *(f"Steps {SHORT.get(m, m)}" for m in methods)]
        steps = [[TASK_TITLES.get(t, t), *([cond] if with_condition else []), *(_steps(cells.get((t, cond, m))) for m in methods)]
                 for t, cond in keys]
        parts.append(f"#### {title}: steps of the disturbed episodes each method completed\n\n" + markdown_table(header, steps))
    return "\n".join(parts) + f"\n{caption}\n"


def _row_keys(cells: dict, methods: list[str]) -> list[tuple[str, str]]:
    """The (task, condition) rows some method has, tasks in the paper's order, drops before protocols."""
    tasks = ordered({t for t, _, _ in cells}, list(TASK_TITLES))
    conditions = sorted({c for _, c, _ in cells}, key=lambda label: (label.startswith("protocol"), label))
    return [(t, c) for t in tasks for c in conditions if any((t, c, m) in cells for m in methods)]


def summary_csv(records: list[dict]) -> str:
    """Every (task, condition, method) group's aggregates as CSV (long format, one row per group)."""
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(["task", "condition", "method", "episodes", "successes", "success_rate", "success_ci_low", "success_ci_high",
                     "exec_time_s", "exec_time_ci_low", "exec_time_ci_high", "robot_time_s", "reasoning_s",
                     "steps_disturbed_success", "episodes_disturbed", "reasoning_calls", "replans", "first_motion_s",
                     "critical_reasoning_s"])
    for (task, condition, method), c in sorted(group(records).items(), key=lambda item: (
            list(TASK_TITLES).index(item[0][0]) if item[0][0] in TASK_TITLES else 99, item[0][1],
            METHODS.index(item[0][2]) if item[0][2] in METHODS else 99)):
        def r(x, digits=3):
            return "" if x is None else round(x, digits)
        writer.writerow([task, condition, method, c.n, c.successes, r(c.success_rate), r(c.success_ci[0]), r(c.success_ci[1]),
                         r(c.time_s), r(c.time_ci[0] if c.time_ci else None), r(c.time_ci[1] if c.time_ci else None),
                         r(c.robot_time_s), r(c.reasoning_s), r(c.steps_disturbed, 1), c.disturbed, r(c.reasoning_calls, 2), r(c.replans, 2),
                         r(c.first_motion_s), r(c.critical_reasoning_s)])
    return out.getvalue()


def ordering(records: list[dict], method: str = "agentchord") -> dict[str, dict]:
    """Whether ``method`` leads on mean success, mean execution time and mean disturbed steps.

    Means are over the (task, condition) rows every method has. Returns, per metric, the
    per-method means and whether ``method`` is best (ties count as best).
    """
    cells = group(records)
    methods = ordered({m for _, _, m in cells}, METHODS)
    rows = [row for row in {(t, c) for t, c, _ in cells} if all((*row, m) in cells for m in methods)]
    out: dict[str, dict] = {}
    for metric, attr, better in (("success", "success_rate", max), ("exec_time_s", "time_s", min), ("steps_disturbed", "steps_disturbed", min)):
        means = {}
        for m in methods:
            values = [getattr(cells[(*row, m)], attr) for row in rows]
            values = [v for v in values if v is not None]
            means[m] = mean(values) if values else None
        known = {m: v for m, v in means.items() if v is not None}
        best = better(known.values()) if known else None
        out[metric] = {"means": means, "best": method in known and known[method] == best}
    return out
