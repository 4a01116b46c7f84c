"""Aggregate episode summaries into the metrics of DESIGN section 7, and print tables."""

from __future__ import annotations

import math
from statistics import mean

from rich.console import Console
from rich.table import Table


def wilson_interval(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95% Wilson score interval of a success rate."""
    if n == 0:
        return (0.0, 0.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(centre - half, 0.0), min(centre + half, 1.0))


def aggregate(summaries: list[dict]) -> dict:
    """Aggregates of one strategy's episodes."""
    n = len(summaries)
    successes = sum(s["success"] for s in summaries)
    latencies = [t for s in summaries for t in s["reaction_latency_ticks"]]
    with_drop = [s for s in summaries if s["drops_injected"] > 0]
    low, high = wilson_interval(successes, n)
    return {
        "episodes": n,
        "success_rate": successes / n if n else 0.0,
        "success_ci95": [round(low, 3), round(high, 3)],
        # As bench's tables: over the successful episodes (a strategy whose failures end early is not faster).
        "mean_time_s": round(mean(s["time_s"] for s in summaries if s["success"]), 3) if successes else None,
        "mean_steps": round(mean(s["steps"] for s in summaries), 1) if n else 0.0,
        "mean_steps_with_drop": round(mean(s["steps"] for s in with_drop), 1) if with_drop else None,
        # The paper counts steps "to complete a task": failed episodes end early and would flatter a strategy that gives up.
        "mean_steps_success_with_drop": round(mean(s["steps"] for s in with_drop if s["success"]), 1)
        if any(s["success"] for s in with_drop) else None,
        "episodes_with_drop": len(with_drop),
        "drops_injected": sum(s["drops_injected"] for s in summaries),
        "drops_detected": sum(s["drops_detected"] for s in summaries),
        "drops_recovered": sum(s["drops_recovered"] for s in summaries),
        "reaction_latency_ticks_mean": round(mean(latencies), 2) if latencies else None,
        "reaction_latency_ticks_max": max(latencies) if latencies else None,
        "mean_wall_s": round(mean(s["wall_s"] for s in summaries), 3) if n else 0.0,
        # Counted as failures in the success rate, and separately: objects beyond every arm's reach.
        "unrecoverable": sum(bool(s.get("unrecoverable")) for s in summaries),
        "disturbances": _disturbance_totals(summaries),
        "failures": [f"seed {s['seed']}: {s['reason']}" for s in sorted(summaries, key=lambda s: s["seed"]) if not s["success"]],
    }


def _disturbance_totals(summaries: list[dict]) -> dict[str, list[int]]:
    """Per disturbance kind, [injected, detected, recovered] summed over the episodes."""
    totals: dict[str, list[int]] = {}
    for summary in summaries:
        for kind, counts in summary.get("disturbances", {}).items():
            row = totals.setdefault(kind, [0, 0, 0])
            for k, count in enumerate(counts):
                row[k] += count
    return dict(sorted(totals.items()))


def paired_steps(by_strategy: dict[str, list[dict]]) -> dict | None:
    """Mean steps of each strategy over the seeds where every strategy succeeded and some saw a drop.

    The fairest step comparison: same scenes, same first disturbances, all completed.
    """
    names = list(by_strategy)
    if len(names) < 2:
        return None
    per_seed = {name: {s["seed"]: s for s in runs} for name, runs in by_strategy.items()}
    seeds = sorted(
        seed for seed in per_seed[names[0]]
        if all(seed in per_seed[n] and per_seed[n][seed]["success"] for n in names)
        and any(per_seed[n][seed]["drops_injected"] > 0 for n in names)
    )
    if not seeds:
        return {"seeds": [], "mean_steps": {n: None for n in names}}
    return {"seeds": seeds, "mean_steps": {n: round(mean(per_seed[n][s]["steps"] for s in seeds), 1) for n in names}}


def metric_rows(stats: dict) -> list[tuple[str, str]]:
    """One strategy's aggregates as (metric, value) rows."""
    low, high = stats["success_ci95"]
    time_s = stats["mean_time_s"]
    rows = [
        ("success rate (95% interval)", f"{100 * stats['success_rate']:.0f}% ({100 * low:.0f}-{100 * high:.0f}%)"),
        ("mean execution time, successful episodes (robot s)", "-" if time_s is None else f"{time_s:.2f}"),
        ("mean steps (control ticks)", f"{stats['mean_steps']:.0f}"),
    ]
    with_drop = stats["mean_steps_with_drop"]
    rows.append(("mean steps, episodes with a drop", "-" if with_drop is None else f"{with_drop:.0f} ({stats['episodes_with_drop']})"))
    done = stats["mean_steps_success_with_drop"]
    rows.append(("mean steps, successful episodes with a drop", "-" if done is None else f"{done:.0f}"))
    rows.append(("drops injected / detected / recovered", f"{stats['drops_injected']} / {stats['drops_detected']} / {stats['drops_recovered']}"))
    for kind, (injected, detected, recovered) in stats.get("disturbances", {}).items():
        if kind != "drop":
            rows.append((f"{kind}: injected / detected / recovered", f"{injected} / {detected} / {recovered}"))
    rows.append(("unrecoverable episodes (counted as failures)", str(stats.get("unrecoverable", 0))))
    lat_mean, lat_max = stats["reaction_latency_ticks_mean"], stats["reaction_latency_ticks_max"]
    rows.append(("reaction latency mean / max (ticks)", "-" if lat_mean is None else f"{lat_mean:.1f} / {lat_max}"))
    rows.append(("mean wall time per episode (s)", f"{stats['mean_wall_s']:.2f}"))
    return rows


def strategy_table(name: str, stats: dict) -> Table:
    """One strategy's aggregates as a rich table."""
    return strategies_table({name: stats}, title=name)


def strategies_table(results: dict[str, dict], title: str | None = None) -> Table:
    """Every strategy's aggregates side by side: a row per metric, a column per strategy (a metric one lacks: -)."""
    table = Table(title=title, show_header=True, header_style="bold")
    table.add_column("metric")
    rows = {name: dict(metric_rows(stats)) for name, stats in results.items()}
    for name in results:
        table.add_column(name if len(results) > 1 else "value", justify="right")
    labels = list(dict.fromkeys(label for values in rows.values() for label in values))
    for label in labels:
        table.add_row(label, *(rows[name].get(label, "-") for name in results))
    return table


def print_tables(results: dict[str, dict], console: Console | None = None, paired: dict | None = None) -> None:
    """Print the strategies side by side, each failure with its seed, and the paired step comparison."""
    console = console or Console()
    console.print(strategies_table(results))
    for name, stats in results.items():
        for reason in stats["failures"]:
            console.print(f"  [red]{name} failed[/red] {reason}", markup=True, highlight=False)
    if paired is not None and paired["seeds"]:
        steps = ", ".join(f"{name} {value:.0f}" for name, value in paired["mean_steps"].items())
        console.print(f"paired: over the {len(paired['seeds'])} seeds with a drop that every strategy completed, mean steps: {steps}")
