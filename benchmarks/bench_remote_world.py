"""What driving a world in another process costs: per-tick overhead of the remote world.

Serves the simulator with ``agentchord serve`` (a separate process, on localhost) and
drives the same seeded episodes locally and remotely. Prints (targets printed, not asserted):

- the bare protocol cost: one ``step`` round trip minus the simulator's own tick
  (serialising both commands, the state reply, ZeroMQ over localhost, decoding);
  target <= 1 ms per tick;
- whole nominal episodes local vs remote: robot time / wall time (x real time), the
  per-tick wall-time difference, and whether the two episodes are identical.

    .venv/bin/python benchmarks/bench_remote_world.py [--task T] [--seeds 3] [--ticks 500]
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from rich.console import Console
from rich.table import Table

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.worlds.protocol import ArmCommand
from agentchord.worlds.remote import RemoteWorld
from agentchord.sim.trial import open_world


def start_server(task: str) -> tuple[subprocess.Popen, str]:
    """``agentchord serve`` on a free port; its address."""
    process = subprocess.Popen([sys.executable, "-m", "agentchord.cli", "serve", "--task", task, "--port", "0"],
                               stdout=subprocess.PIPE, text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    line = process.stdout.readline()
    match = re.search(r"tcp://[0-9.]+:\d+", line)
    if match is None:
        process.kill()
        raise RuntimeError(f"the server did not start: {line!r}")
    return process, match.group(0)


def tick_costs(address: str, task: str, ticks: int) -> tuple[float, float]:
    """Median wall time (ms) of one tick: local ``step``, remote ``step`` (the same commands)."""
    local, remote = open_world(task, 0), RemoteWorld(address, task, 0)
    try:
        times = {"local": [], "remote": []}
        for name, world in (("local", local), ("remote", remote)):
            home = world.arm_q("right")
            for k in range(ticks):
                q = home + 0.1 * np.sin(0.02 * k) * np.array([1.0, 0.5, -0.5, 0.0, 0.5, 0.0])
                world.command("right", ArmCommand(q=q, grip=0.0))
                t0 = time.perf_counter()
                world.step()
                times[name].append(time.perf_counter() - t0)
        return float(np.median(times["local"]) * 1e3), float(np.median(times["remote"]) * 1e3)
    finally:
        remote.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--task", default="single_arm_pour_water")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--ticks", type=int, default=500)
    args = parser.parse_args()
    console = Console()
    server, address = start_server(args.task)
    try:
        local_ms, remote_ms = tick_costs(address, args.task, args.ticks)
        table = Table(title=f"{args.task}: one control tick, median of {args.ticks} (target: overhead <= 1 ms)")
        for column in ("local step ms", "remote step ms", "overhead ms / tick"):
            table.add_column(column, justify="right")
        table.add_row(f"{local_ms:.3f}", f"{remote_ms:.3f}", f"{remote_ms - local_ms:.3f}")
        console.print(table)

        table = Table(title=f"{args.task}: nominal episodes, local vs remote world (server: another process)")
        for column in ("seed", "steps", "local x real time", "remote x real time", "overhead ms / tick", "same episode"):
            table.add_column(column, justify="right")
        overheads, factors = [], []
        for seed in range(args.seeds):
            local = run_episode(EpisodeSpec(args.task, seed=seed))
            remote = run_episode(EpisodeSpec(args.task, seed=seed, world=address))
            same = (local.steps, local.success, local.path, local.trace.events) == (
                remote.steps, remote.success, remote.path, remote.trace.events)
            overhead = (remote.wall_s - local.wall_s) / max(local.steps, 1) * 1e3
            overheads.append(overhead)
            factors.append(local.time_s / local.wall_s)
            table.add_row(str(seed), str(local.steps), f"{local.time_s / local.wall_s:.1f}", f"{remote.time_s / remote.wall_s:.1f}",
                          f"{overhead:.3f}", str(same))
        table.add_row("median", "", f"{np.median(factors):.1f}", "", f"{np.median(overheads):.3f}", "")
        console.print(table)
    finally:
        server.terminate()
        server.wait(10)


if __name__ == "__main__":
    main()
