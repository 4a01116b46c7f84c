"""How well characters / 4 counts the output tokens the latency model prices, against a real tokenizer.

The token-priced latency model counts a reply's tokens as characters / 4 (``agents.replies``): no
tokenizer ships with the project. This compares that count with GPT-4o's ``o200k_base`` encoding
on every reply the pipelined and sequential plans price (the six library graphs), when a tokenizer
with that encoding built in is installed (``pip install bpe-openai``: the vocabulary is in the wheel,
nothing is downloaded). Printed, not asserted.

    .venv/bin/python benchmarks/bench_token_count.py
"""

from __future__ import annotations

import json
import statistics
import sys

from rich.console import Console
from rich.table import Table

from agentchord.agents.replies import (
    augmentation_reply,
    branch_owners,
    branch_reply,
    count_tokens,
    grounded_reply,
    nominal_failures,
    nominal_reply,
)
from agentchord.execution.baselines.replies import stages_reply
from agentchord.graph.progress import forward_filter
from agentchord.library import load_task_graph

TASKS = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "fold_towel", "setup_coffee_tray")


def replies(task: str) -> dict[str, str]:
    """The replies priced for one task's library graph, as compact JSON."""
    graph = forward_filter(load_task_graph(task)).graph
    owners = branch_owners(graph)
    parts = {"nominal graph": nominal_reply(graph), "all branches": augmentation_reply(graph), "grounded values": grounded_reply(graph)}
    edge, failure = nominal_failures(graph)[0]
    parts[f"one branch ({edge}/{failure})"] = branch_reply(graph, edge, failure, owners)
    parts["ReKep's stages"] = stages_reply(graph)
    return {name: json.dumps(reply, separators=(",", ":"), ensure_ascii=False) for name, reply in parts.items()}


def main() -> int:
    console = Console()
    try:
        import bpe_openai
    except ImportError:
        console.print("bpe-openai is not installed: pip install bpe-openai (o200k_base is in its wheel) to compare.")
        return 0
    encoding = bpe_openai.get_encoding("o200k_base")
    table = Table(title="Output tokens: characters / 4 against o200k_base (GPT-4o)")
    for column in ("task", "reply", "chars / 4", "o200k", "ratio"):
        table.add_column(column, justify="left" if column in ("task", "reply") else "right")
    ratios: dict[str, list[float]] = {}
    for task in TASKS:
        for name, text in replies(task).items():
            real = len(encoding.encode(text))
            estimate = count_tokens(text)
            ratios.setdefault(name.split(" (")[0], []).append(estimate / real)
            table.add_row(task, name, str(estimate), str(real), f"{estimate / real:.2f}")
    console.print(table)
    for name, values in ratios.items():
        console.print(f"{name}: characters / 4 counts {statistics.mean(values):.2f} of the real tokens "
                      f"({min(values):.2f}-{max(values):.2f})")
    every = [v for values in ratios.values() for v in values]
    console.print(f"all: {statistics.mean(every):.2f}; at 120 tokens/s by characters / 4 the model decodes as fast as "
                  f"{120 * statistics.mean(every):.0f} real tokens/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
