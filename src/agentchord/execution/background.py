"""The rest of a pipelined plan answered by an LLM in a thread while the control loop runs.

With ``--reasoner llm`` the robot starts on the composer's nominal graph; the arranger and the
conductor are asked in a background thread (:class:`ThreadedPlan`). Their reply arrives at the tick
its measured latency puts it on the episode's clock: the control loop never runs ahead of the wall
clock while the reply is pending (it waits for the reply, or for real time to catch up, before each
tick it would otherwise take blind), so a reply that took ``L`` seconds is armed at the tick
``ceil(L * 50)`` after the first motion, however fast the simulator runs. The same latency given
to :class:`ScriptedPlan` gives the same episode offline (a test checks it). A call that fails, or
runs past its deadline, is an error the episode survives: the robot goes on with the monitors
derived from each edge's own constraints (:mod:`agentchord.execution.arrivals`), and a failure that
would need a branch ends the episode with the plan's error as its reason.
"""

from __future__ import annotations

import time
from collections.abc import Callable
import threading
from dataclasses import dataclass, field

from agentchord.agents.exceptions import ReasonerTransportError
from agentchord.graph.models import TaskGraph


@dataclass(frozen=True)
class Arrival:
    """The background plan's outcome.

    Attributes:
        latency_s: Seconds from its start (the first motion) to its reply.
        graph: The augmented, conducted graph; None when it failed.
        calls: The reasoner calls it made (for the trace), failed ones included.
        error: Why it failed; None when it succeeded.
        outage: Whether it failed because the endpoint could not be reached or refused every retry
            (an outage, not an answer the model got wrong).
        fallback: Who wrote ``graph`` instead when the LLM's plan failed (``rules``: the offline arranger
            and conductor), with ``error`` saying why; None when the plan is the LLM's own.
    """

    latency_s: float
    graph: TaskGraph | None
    calls: list = field(default_factory=list)
    error: str | None = None
    outage: bool = False
    fallback: str | None = None


class FallbackPlan(Exception):
    """Raised by a background plan's work that failed and was replaced: carries the graph written instead.

    Attributes:
        graph: The graph the fallback wrote.
        calls: The calls made, the failed ones included.
        cause: The failure it replaced.
        by: Who wrote the graph (``rules``).
    """

    def __init__(self, graph: TaskGraph, calls: list, cause: BaseException, by: str) -> None:
        super().__init__(f"{type(cause).__name__}: {cause}")
        self.graph, self.calls, self.cause, self.by = graph, calls, cause, by


def is_outage(error: BaseException) -> bool:
    """Whether ``error`` is an LLM outage: the endpoint unreachable, timing out or refusing every retry."""
    return isinstance(error, ReasonerTransportError)


class ThreadedPlan:
    """``work`` run in a daemon thread from :meth:`start`; :meth:`poll` paces the control loop against it.

    The thread is a daemon and nothing joins it: an episode that ends (or a process interrupted)
    while the call is still in flight does not wait for it. The call finishes or dies with the
    process; its reply, if any, is dropped.

    Args:
        work: Returns ``(graph, calls)``; raises on failure (the error's ``calls``, if any, are kept).
        clock: Monotonic seconds (tests may pass their own).
    """

    def __init__(self, work: Callable[[], tuple[TaskGraph, list]], clock: Callable[[], float] = time.perf_counter) -> None:
        self._work = work
        self._clock = clock
        self._done = threading.Event()
        self._thread: threading.Thread | None = None
        self._result: tuple[TaskGraph, list] | None = None
        self._error: BaseException | None = None
        self._started = 0.0
        self._ended: float | None = None
        self._closed = False

    def start(self) -> None:
        """Ask now: the first motion."""
        self._started = self._clock()
        self._thread = threading.Thread(target=self._timed, name="agentchord-plan", daemon=True)
        self._thread.start()

    def _timed(self) -> None:
        try:
            self._result = self._work()
        except BaseException as error:  # the episode survives any failure of the plan
            self._error = error
        finally:
            self._ended = self._clock()
            self._done.set()

    def poll(self, elapsed_s: float) -> Arrival | None:
        """The arrival, once the reply is in; None while it is pending and ``elapsed_s`` of episode time
        has not run ahead of the wall clock (the call waits until either holds)."""
        if self._thread is None or self._closed:
            return None
        ahead = elapsed_s - (self._clock() - self._started)
        if not self._done.is_set() and ahead > 0:
            self._done.wait(timeout=ahead)
        if not self._done.is_set():
            return None
        latency = (self._ended if self._ended is not None else self._clock()) - self._started
        self.close()
        error = self._error
        if isinstance(error, FallbackPlan):
            cause = error.cause
            return Arrival(latency, error.graph, error.calls, f"{type(cause).__name__}: {cause}", is_outage(cause), error.by)
        if error is not None:
            return Arrival(latency, None, list(getattr(error, "calls", []) or []), f"{type(error).__name__}: {error}",
                           outage=is_outage(error))
        assert self._result is not None  # set before the event, when no error was
        graph, calls = self._result
        return Arrival(latency, graph, calls)

    def close(self) -> None:
        """Stop waiting for the thread: a reply that comes later is dropped (the daemon is not joined)."""
        self._closed = True


@dataclass
class ScriptedPlan:
    """A background plan whose reply is known: it arrives ``latency_s`` after the first motion.

    The offline twin of :class:`ThreadedPlan` (tests; replaying an LLM episode's latencies).
    """

    latency_s: float
    graph: TaskGraph | None
    error: str | None = None
    outage: bool = False
    fallback: str | None = None

    def start(self) -> None:
        """Nothing to ask."""

    def poll(self, elapsed_s: float) -> Arrival | None:
        """The arrival (known from the start)."""
        return Arrival(self.latency_s, self.graph, [], self.error, self.outage, self.fallback)

    def close(self) -> None:
        """Nothing to stop."""
