"""Where a sweep's episodes run: a local process pool, or Ray tasks on a cluster.

Both yield ``(key, record)`` as episodes finish, in any order; an episode's record depends
only on its key and the sweep's config (the same seed gives the same episode), so the
backend changes when a record arrives, never what it says (wall-clock fields aside:
:data:`MEASURED_FIELDS`).
"""

from __future__ import annotations

from collections.abc import Iterator

from agentchord.bench.exceptions import BackendError
from agentchord.bench.runner import default_workers, pooled
from agentchord.bench.sweep import EpisodeKey, SweepConfig, run_record

BACKENDS = ("local", "ray")
#: Record fields measured on the wall clock of whatever machine ran the episode.
MEASURED_FIELDS = frozenset({"wall_s", "compute_s", "exec_time_s"})


def _run(job: tuple[EpisodeKey, SweepConfig]) -> tuple[EpisodeKey, dict]:
    return _episode(*job)


def _episode(key: EpisodeKey, config: SweepConfig) -> tuple[EpisodeKey, dict]:
    return key, run_record(key, config)


def run_local(keys: list[EpisodeKey], config: SweepConfig, workers: int | None = None) -> Iterator[tuple[EpisodeKey, dict]]:
    """Episodes in a pool of worker processes (default: one per core); one worker runs them in this process."""
    yield from pooled(_run, [(key, config) for key in keys], workers)


def run_ray(keys: list[EpisodeKey], config: SweepConfig, address: str | None = None,
            workers: int | None = None) -> Iterator[tuple[EpisodeKey, dict]]:
    """Episodes as Ray tasks: on a local Ray instance (``workers`` CPUs), or on the cluster at ``address``.

    Raises:
        BackendError: Ray is not installed, or the cluster cannot be joined.
    """
    try:
        import ray
    except ImportError:
        raise BackendError("--backend ray needs Ray: pip install 'agentchord[ray]'") from None
    started_here = not ray.is_initialized()
    if started_here:
        try:
            if address:
                ray.init(address=address, log_to_driver=False)
            else:
                ray.init(num_cpus=workers or default_workers(), include_dashboard=False, log_to_driver=False)
        except (ConnectionError, RuntimeError, ValueError) as error:
            raise BackendError(f"cannot start or join Ray{f' at {address}' if address else ''}: {error}") from None
    try:
        remote = ray.remote(num_cpus=1, max_retries=2)(_episode)
        config_ref = ray.put(config)
        # A bounded window of tasks in flight: results stream back as they finish, memory stays flat.
        window = 4 * int(ray.cluster_resources().get("CPU", 1))
        pending: list = []
        queue = list(keys)
        while queue or pending:
            while queue and len(pending) < window:
                pending.append(remote.remote(queue.pop(0), config_ref))
            done, pending = ray.wait(pending, num_returns=1)
            yield ray.get(done[0])
    finally:
        if started_here:
            ray.shutdown()
