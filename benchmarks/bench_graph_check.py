"""How long `graph check` and `graph render` take on a large graph (printed, not asserted).

Targets: `graph check` of a 10,000-node graph under 5 s; `graph render` refuses or finishes under 30 s.
The graph is a chain of pour-water-like sub-goals, every third edge with a failure mode whose
recovery branch merges forward, so that every check (ids, references, actions, expressions,
reachability, the forward-moving principle) has work to do.

    .venv/bin/python benchmarks/bench_graph_check.py [--nodes 10000]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml
from rich.console import Console
from rich.table import Table


def big_graph(nodes: int) -> dict:
    """A valid graph of about ``nodes`` nodes (nominal chain plus recovery nodes)."""
    chain = max(2, (nodes * 3) // 4)
    data: dict = {
        "task": "single_arm_pour_water",
        "instruction": "A long chain.",
        "start": "v0",
        "goal": f"v{chain - 1}",
        "objects": ["bottle", "cup"],
        "nodes": [
            {"id": f"v{i}", "semantic": f"step {i}", "constraints": ["0.5 - holding(right, bottle)"]}
            for i in range(chain)
        ],
        "edges": [],
    }
    recovery = 0
    for i in range(chain - 1):
        edge = {
            "id": f"e{i}",
            "source": f"v{i}",
            "target": f"v{i + 1}",
            "actions": {"right": {"fn": "move_to_obj", "args": {"obj": "cup", "offset": [0.05, -0.1, 0.1]}}},
            "path_constraints": ["tilt(bottle) - 20"],
        }
        data["edges"].append(edge)
        if i % 3 == 0 and len(data["nodes"]) < nodes and i + 2 < chain:
            r = f"r{recovery}"
            recovery += 1
            edge["failures"] = [
                {
                    "name": "bottle_dropped",
                    "monitor": "0.5 - holding(right, bottle)",
                    "intent": "regrasp",
                    "recovery": f"{r}_in",
                }
            ]
            data["nodes"].append({"id": r, "kind": "recovery", "semantic": "regrasped"})
            data["edges"].append(
                {
                    "id": f"{r}_in",
                    "kind": "recovery",
                    "source": f"v{i}",
                    "target": r,
                    "actions": {"right": {"fn": "grasp", "args": {"obj": "bottle"}}},
                    "cost": 1,
                }
            )
            data["edges"].append(
                {
                    "id": f"{r}_out",
                    "kind": "recovery",
                    "source": r,
                    "target": f"v{i + 2}",
                    "actions": {"right": {"fn": "move_to_obj", "args": {"obj": "cup"}}},
                    "cost": 1,
                }
            )
    return data


def _timed(command: list[str]) -> tuple[float, int, str]:
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    last = (done.stdout + done.stderr).strip().splitlines()
    return time.perf_counter() - start, done.returncode, (last[-1] if last else "")[:90]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--nodes", type=int, default=10_000)
    args = parser.parse_args()
    agentchord = str(Path(sys.executable).with_name("agentchord"))
    table = Table(title=f"a {args.nodes}-node graph, wall time of the command (targets: check < 5 s, render < 30 s or refused)")
    for column in ("command", "seconds", "exit", "last line"):
        table.add_column(column)
    with tempfile.TemporaryDirectory() as tmp:
        data = big_graph(args.nodes)
        yaml_path, json_path = Path(tmp) / "big.yaml", Path(tmp) / "big.json"
        yaml_path.write_text(yaml.safe_dump(data, sort_keys=False))
        json_path.write_text(json.dumps(data))
        for name, command in (
            ("graph check (YAML)", [agentchord, "graph", "check", str(yaml_path)]),
            ("graph check (JSON)", [agentchord, "graph", "check", str(json_path)]),
            ("graph render .svg", [agentchord, "graph", "render", str(json_path), "-o", str(Path(tmp) / "g.svg")]),
            ("graph render .dot", [agentchord, "graph", "render", str(json_path), "-o", str(Path(tmp) / "g.dot")]),
            ("graph render .mmd", [agentchord, "graph", "render", str(json_path), "-o", str(Path(tmp) / "g.mmd")]),
        ):
            seconds, status, last = _timed(command)
            table.add_row(name, f"{seconds:.2f}", str(status), last)
    Console().print(table)


if __name__ == "__main__":
    main()
