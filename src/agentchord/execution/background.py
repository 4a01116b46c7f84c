"""The rest of a pipelined plan answered by an LLM in a thread while the control loop runs.

With ``--reasoner llm`` the robot starts on the composer's nominal graph; the arranger and the
conductor are asked in a background thread (:class:`ThreadedPlan`). Their reply arrives at the tick
its measured latency puts it on the episode's clock: the control loop never runs ahead of the wall
clock while the reply is pending (it waits for the reply, or for real time to catch up, before each
tick it would otherwise take blind), so a reply that took ``L`` seconds is armed at the tick
``ceil(L * 50)`` after the first motion, however fast the simulator runs. The same latency given
to :class:`ScriptedPlan` gives the same episode offline (a test checks it). A call that fails, or
runs past its deadline, is an error the episode survives: the robot goes on with the monitors it
has, the reason in the trace.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field

from agentchord.graph.models import TaskGraph


@dataclass(frozen=True)
class Arrival:
    """The background plan's outcome.

    Attributes:
        latency_s: Seconds from its start (the first motion) to its reply.
        graph: The augmented, conducted graph; None when it failed.
        calls: The reasoner calls it made (for the trace), failed ones included.
        error: Why it failed; None when it succeeded.
    """

    latency_s: float
    graph: TaskGraph | None
    calls: list = field(default_factory=list)
    error: str | None = None


class ThreadedPlan:
    """``work`` run in a thread from :meth:`start`; :meth:`poll` paces the control loop against it.

    Args:
        work: Returns ``(graph, calls)``; raises on failure (the error's ``calls``, if any, are kept).
        clock: Monotonic seconds (tests may pass their own).
    """

    def __init__(self, work: Callable[[], tuple[TaskGraph, list]], clock: Callable[[], float] = time.perf_counter) -> None:
        self._work = work
        self._clock = clock
        self._pool: ThreadPoolExecutor | None = None
        self._future: Future | None = None
        self._started = 0.0
        self._ended: float | None = None

    def start(self) -> None:
        """Ask now: the first motion."""
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="agentchord-plan")
        self._started = self._clock()
        self._future = self._pool.submit(self._timed)

    def _timed(self) -> tuple[TaskGraph, list]:
        try:
            return self._work()
        finally:
            self._ended = self._clock()

    def poll(self, elapsed_s: float) -> Arrival | None:
        """The arrival, once the reply is in; None while it is pending and ``elapsed_s`` of episode time
        has not run ahead of the wall clock (the call waits until either holds)."""
        if self._future is None:
            return None
        ahead = elapsed_s - (self._clock() - self._started)
        if not self._future.done() and ahead > 0:
            try:
                self._future.exception(timeout=ahead)
            except TimeoutError:
                return None
        if not self._future.done():
            return None
        latency = (self._ended if self._ended is not None else self._clock()) - self._started
        self.close()
        error = self._future.exception()
        if error is not None:
            return Arrival(latency, None, list(getattr(error, "calls", []) or []), f"{type(error).__name__}: {error}")
        graph, calls = self._future.result()
        return Arrival(latency, graph, calls)

    def close(self) -> None:
        """Stop waiting for the thread (an episode that ends first leaves the call to finish on its own)."""
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = None


@dataclass
class ScriptedPlan:
    """A background plan whose reply is known: it arrives ``latency_s`` after the first motion.

    The offline twin of :class:`ThreadedPlan` (tests; replaying an LLM episode's latencies).
    """

    latency_s: float
    graph: TaskGraph | None
    error: str | None = None

    def start(self) -> None:
        """Nothing to ask."""

    def poll(self, elapsed_s: float) -> Arrival | None:
        """The arrival (known from the start)."""
        return Arrival(self.latency_s, self.graph, [], self.error)

    def close(self) -> None:
        """Nothing to stop."""
