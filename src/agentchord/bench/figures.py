"""A sweep's records as PNG figures: success and time against p (the paper's Fig. 4), steps per method."""

from __future__ import annotations

import io
from collections import defaultdict

from agentchord.bench.tables import TASK_TITLES, group
from agentchord.bench.sweep import Condition
from agentchord.execution.methods import METHODS, SHORT


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")  # headless: no display here or on a cluster node
    import matplotlib.pyplot as plt

    return plt


def _png(figure) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=120, bbox_inches="tight")
    _pyplot().close(figure)
    return buffer.getvalue()


def stress_figure(records: list[dict], task: str | None = None) -> bytes | None:
    """Success rate (with 95% CI) and mean execution time against p, one line per method.

    Args:
        records: The sweep's records; only the random-drop conditions are drawn.
        task: One task, or None to pool every task's episodes per p.

    Returns:
        The PNG, or None when fewer than two values of p are in the records.
    """
    chosen = [r for r in records if r["protocol"] is None and (task is None or r["task"] == task)]
    if len({r["p"] for r in chosen}) < 2:
        return None
    pooled = [{**r, "task": task or "all"} for r in chosen]
    cells = group(pooled)
    methods = [m for m in METHODS if any(k[2] == m for k in cells)]
    ps = sorted({Condition.from_label(k[1]).p for k in cells})
    plt = _pyplot()
    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for method in methods:
        xs, rates, lows, highs, times_x, times = [], [], [], [], [], []
        for p in ps:
            c = cells.get((task or "all", Condition(p=p).label, method))
            if c is None:
                continue
            xs.append(p)
            rates.append(100 * c.success_rate)
            lows.append(100 * c.success_ci[0])
            highs.append(100 * c.success_ci[1])
            if c.time_s is not None:
                times_x.append(p)
                times.append(c.time_s)
        line, = left.plot(xs, rates, marker="o", label=SHORT.get(method, method))
        left.fill_between(xs, lows, highs, color=line.get_color(), alpha=0.12)
        right.plot(times_x, times, marker="o", color=line.get_color(), label=SHORT.get(method, method))
    title = TASK_TITLES.get(task, task) if task else "all tasks"
    left.set(xlabel="drop probability p per atomic action", ylabel="success rate (%)", ylim=(0, 105), title=f"Success, {title}")
    right.set(xlabel="drop probability p per atomic action", ylabel="execution time (s), successful episodes",
              title=f"Execution time, {title}")
    left.legend(fontsize=8)
    left.grid(alpha=0.3)
    right.grid(alpha=0.3)
    return _png(figure)


def steps_figure(records: list[dict]) -> bytes | None:
    """Mean steps of the successful episodes with a disturbance, per method, one group of bars per task and condition."""
    cells = group(records)
    if not cells:
        return None
    methods = [m for m in METHODS if any(k[2] == m for k in cells)]
    rows = sorted({(t, c) for t, c, _ in cells}, key=lambda row: (list(TASK_TITLES).index(row[0]) if row[0] in TASK_TITLES else 99, row[1]))
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(max(6, 1.6 * len(rows)), 4))
    width = 0.8 / max(len(methods), 1)
    series: dict[str, list[float]] = defaultdict(list)
    for t, c in rows:
        for m in methods:
            cell = cells.get((t, c, m))
            series[m].append(cell.steps_disturbed if cell is not None and cell.steps_disturbed is not None else 0.0)
    for k, m in enumerate(methods):
        axes.bar([i + k * width for i in range(len(rows))], series[m], width, label=SHORT.get(m, m))
    axes.set_xticks([i + 0.4 - width / 2 for i in range(len(rows))])
    axes.set_xticklabels([f"{TASK_TITLES.get(t, t)}\n{c}" for t, c in rows], fontsize=7)
    axes.set_ylabel("steps (control ticks),\nsuccessful disturbed episodes")  # two lines: fits the figure's height
    axes.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))  # beside the bars, never over them
    axes.grid(axis="y", alpha=0.3)
    return _png(figure)
