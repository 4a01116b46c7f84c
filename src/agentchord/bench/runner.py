"""Run many seeded episodes in local worker processes (one simulator per process)."""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterable, Iterator

from agentchord.execution.episode import EpisodeSpec, run_episode


def _run(spec: EpisodeSpec) -> tuple[EpisodeSpec, dict]:
    result = run_episode(spec)
    return spec, {"seed": spec.seed, "strategy": spec.strategy, **result.summary()}


def default_workers() -> int:
    """One worker per available core."""
    return max(len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1, 1)


def run_many(specs: Iterable[EpisodeSpec], workers: int | None = None,
             progress: Callable[[EpisodeSpec, dict], None] | None = None) -> Iterator[tuple[EpisodeSpec, dict]]:
    """Run episodes, yielding ``(spec, summary)`` as they finish (order not kept).

    Each episode is deterministic given its spec, so running in parallel does
    not change any result.
    """
    specs = list(specs)
    workers = min(workers or default_workers(), len(specs)) or 1
    if workers == 1:
        for spec in specs:
            item = _run(spec)
            if progress:
                progress(*item)
            yield item
        return
    # "spawn": MuJoCo and BLAS threads do not survive fork reliably.
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        for item in pool.imap_unordered(_run, specs):
            if progress:
                progress(*item)
            yield item
