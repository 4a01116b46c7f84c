"""Where each method's execution time goes, and what the pipelined plan's early failures came to.

Pure functions: records in, Markdown and CSV out.

- The decomposition: each method's average execution time split into time to first motion, robot
  time after it (waits for a pipelined plan's parts included), compute, and the blocking reasoning
  after the first motion (re-plans, VQA queries), averaged as the tables average time (per cell over
  its successful episodes, then over the cells), so the parts add up to the tables' Average row.
- The early failures: every failure that fired before its recovery branch had arrived (pipelined
  AgentChord), its outcome, and how the same seed ended with the paper's sequential plan.
"""

from __future__ import annotations

from collections import defaultdict
from statistics import mean

from agentchord.bench.tables import TASK_TITLES, markdown_table, ordered
from agentchord.execution.methods import METHODS, SHORT

#: The methods whose early failures are compared: the pipelined plan and the paper's sequential one.
PIPELINED, SEQUENTIAL = "agentchord", "agentchord-sequential"

#: The parts of execution time, in the order they happen.
PARTS = ("first_motion_s", "robot_s", "after_s", "plan_wait_s")


def _parts(record: dict) -> dict[str, float]:
    """One episode's execution time in parts (a record from before pipelining waited for all its planning first)."""
    first = record.get("first_motion_s")
    if first is None:
        first = record["reasoning_s"] + record["compute_s"]
    return {
        "first_motion_s": first,
        "robot_s": record["robot_time_s"],
        "after_s": max(record["exec_time_s"] - first - record["robot_time_s"], 0.0),
        "plan_wait_s": record.get("plan_wait_s", 0.0),
    }


def decomposition(records: list[dict]) -> dict[str, dict[str, float]]:
    """Per method, the mean of each part of execution time over its cells (each cell over its successes).

    ``robot_s`` includes ``plan_wait_s`` (the robot held still, the world stepped); ``after_s`` is the
    reasoning and compute after the first motion that the robot held still for (re-plans, VQA queries);
    ``exec_s`` = first motion + robot + after, the tables' time.
    """
    cells: dict[tuple[str, str, str], list[dict]] = defaultdict(list)
    for record in records:
        if record["success"]:
            cells[(record["task"], record["condition"], record["method"])].append(_parts(record))
    by_method: dict[str, list[dict[str, float]]] = defaultdict(list)
    for (_, _, method), parts in cells.items():
        by_method[method].append({name: mean(p[name] for p in parts) for name in PARTS})
    out = {}
    for method, rows in by_method.items():
        means = {name: mean(row[name] for row in rows) for name in PARTS}
        means["exec_s"] = means["first_motion_s"] + means["robot_s"] + means["after_s"]
        out[method] = means
    return out


def decomposition_markdown(records: list[dict]) -> str:
    """The decomposition as a Markdown table, a row per method."""
    table = decomposition(records)
    methods = ordered(set(table), METHODS)
    header = ["Method", "Exec. time s", "First motion s", "Robot s", "of which waiting for the plan s",
              "Reasoning and compute after s"]
    rows = [[SHORT.get(m, m), f"{t['exec_s']:.1f}", f"{t['first_motion_s']:.2f}", f"{t['robot_s']:.1f}",
             f"{t['plan_wait_s']:.2f}", f"{t['after_s']:.1f}"] for m in methods for t in [table[m]]]
    return ("### Where the time goes\n\n" + markdown_table(header, rows) +
            "\nMeans over each method's cells of its successful episodes, as the tables' Average row: exec = first motion "
            "+ robot + what the robot held still for after it (re-plans, VQA queries, compute). Robot time includes the "
            "ticks the robot held still for a part of a pipelined plan that had not arrived.\n")


def early_failures(records: list[dict]) -> list[dict]:
    """Every failure that fired before its branch arrived, with its episode's and the sequential plan's outcome."""
    sequential = {(r["task"], r["condition"], r["seed"]): r for r in records if r["method"] == SEQUENTIAL}
    out = []
    for record in records:
        for failure in record.get("early_failures") or []:
            twin = sequential.get((record["task"], record["condition"], record["seed"]))
            out.append({
                "method": record["method"], "task": record["task"], "condition": record["condition"], "seed": record["seed"],
                "edge": failure["edge"], "failure": failure["failure"], "waited_s": failure["waited_ticks"] / 50.0,
                "then": failure["then"], "success": record["success"], "reason": record["reason"],
                "sequential": None if twin is None else twin["success"],
            })
    return out


def regressions(records: list[dict]) -> list[dict]:
    """The early failures whose episode failed where the sequential plan, same seed, succeeded."""
    return [e for e in early_failures(records) if not e["success"] and e["sequential"]]


def early_failures_markdown(records: list[dict]) -> str:
    """The early failures as a Markdown table, with a summary line."""
    rows = early_failures(records)
    episodes = {(e["task"], e["condition"], e["seed"]) for e in rows}
    pipelined = [r for r in records if r["method"] == PIPELINED]
    lost = regressions(records)
    lines = [f"### Failures before their branch arrived\n\n{len(rows)} in {len(episodes)} of {len(pipelined)} pipelined "
             f"episodes; {sum(e['success'] for e in rows)} of them in episodes that succeeded; "
             f"{len(lost)} in an episode that failed where the sequential plan (same seed) succeeded.\n"]
    if rows:
        header = ["Task", "Condition", "Seed", "Edge", "Failure", "Waited s", "Then", "Episode", "Sequential plan"]
        body = [[TASK_TITLES.get(e["task"], e["task"]), e["condition"], str(e["seed"]), e["edge"], e["failure"],
                 f"{e['waited_s']:.1f}", e["then"], "success" if e["success"] else f"failure: {e['reason']}",
                 "-" if e["sequential"] is None else ("success" if e["sequential"] else "failure")] for e in rows]
        lines.append(markdown_table(header, body))
    return "\n".join(lines)
