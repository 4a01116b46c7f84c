"""Run many seeded episodes in local worker processes (one simulator per process)."""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterable, Iterator
from typing import TypeVar

from agentchord.episode import EpisodeSpec, run_episode


def _run(spec: EpisodeSpec) -> tuple[EpisodeSpec, dict]:
    result = run_episode(spec)
    return spec, {"seed": spec.seed, "strategy": spec.strategy, **result.summary()}


def default_workers() -> int:
    """One worker per available core."""
    return max(len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1, 1)


Item = TypeVar("Item")
Result = TypeVar("Result")


def pooled(fn: Callable[[Item], Result], items: Iterable[Item], workers: int | None = None) -> Iterator[Result]:
    """``fn`` over ``items`` in worker processes (one worker: in this process), results as they finish.

    ``fn`` must be a module-level function (it is pickled into the workers).
    """
    items = list(items)
    workers = min(workers or default_workers(), len(items)) or 1
    if workers == 1:
        yield from map(fn, items)
        return
    # "spawn": MuJoCo and BLAS threads do not survive fork reliably. chunksize 1: results arrive as items end.
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        yield from pool.imap_unordered(fn, items, chunksize=1)


def run_many(specs: Iterable[EpisodeSpec], workers: int | None = None,
             progress: Callable[[EpisodeSpec, dict], None] | None = None) -> Iterator[tuple[EpisodeSpec, dict]]:
    """Run episodes, yielding ``(spec, summary)`` as they finish (order not kept).

    Each episode is deterministic given its spec, so running in parallel does
    not change any result.
    """
    for item in pooled(_run, specs, workers):
        if progress:
            progress(*item)
        yield item
