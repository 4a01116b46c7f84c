"""When each agent's work arrives: the paper's sequential plan and AgentChord's pipelined one.

Sequential (the paper's order, ``agentchord-sequential``): the composer writes the nominal graph,
the arranger its failure modes and recovery branches, the conductor grounds all of it; the robot
waits for all three before it moves.

Pipelined (``agentchord``): a robot does not need the branches of its third edge before it starts
its first. The composer's reply streams in execution order (:func:`~agentchord.agents.replies.stream_order`);
as soon as an edge has streamed, the conductor grounds it, and once the node it reaches has too, the
arranger is asked for its failure modes; per mode the arranger then writes its recovery branch, once
the nominal nodes the branch leaves from and merges at have streamed too. The branch streams entry
first: the conductor grounds the entry as soon as it has streamed, the rest of the branch when the
reply ends. The other arm's way into a recovery (an arm-switching alternative, needed only when the
entry's arm cannot reach what fell) is written last, in a call of its own per mode, and grounded
after it. The calls are served as the model allows (``concurrency`` at once), in the order the robot
needs them: the edges' groundings, then edge k's modes and their branches before edge k+1's, then
the alternatives. The robot moves once the first edge is grounded; every other part arrives while
it moves, as an event on the episode's clock (:class:`PlanSchedule`). An edge's monitors are armed
once the arranger's list of its modes has arrived; a mode can be recovered from once its recovery
entry has arrived grounded; an edge further on in a branch, like a nominal one, and an alternative
the recovery binds are waited for if the robot needs them first.

A failure that fires before its branch has arrived **hurries** it: from that moment the calls its
branch still needs (the edge's list of modes, the branch, the grounding of its entry) go first
whenever a slot frees, as a planner told what the robot waits for
would send them (:meth:`PlanSchedule.hurried`). Calls that started before stay as they were.

Pure functions of a graph, a latency model and the hurries: the same inputs give the same schedule.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from agentchord.agents.replies import (
    alternatives_reply,
    augmentation_reply,
    branch_alternatives,
    branch_edges,
    branch_entry,
    branch_entry_tokens,
    branch_nominal_nodes,
    branch_owners,
    branch_reply,
    count_tokens,
    grounded_reply,
    grounding_patch,
    modes_reply,
    nominal_reply,
    streamed_tokens,
)
from agentchord.execution.reasoning import AnyLatencyModel, ModelledCall
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import nominal_path
from agentchord.worlds.protocol import CONTROL_HZ


def composer_call(graph: TaskGraph) -> ModelledCall:
    """The composer's one call: the nominal graph."""
    return ModelledCall("composer", "plan", count_tokens(nominal_reply(graph)), part="nominal graph")


def sequential_calls(graph: TaskGraph) -> list[ModelledCall]:
    """The paper's three calls, one after the other: nominal graph, branches, their grounding."""
    return [
        composer_call(graph),
        ModelledCall("arranger", "plan", count_tokens(augmentation_reply(graph)), part="failure modes and branches"),
        ModelledCall("conductor", "plan", count_tokens(grounded_reply(graph)), part="grounded edges and branches"),
    ]


@dataclass(frozen=True)
class ScheduledCall:
    """One call of a pipelined plan and when it ran (seconds from the start of planning)."""

    call: ModelledCall
    start_s: float
    end_s: float


@dataclass(frozen=True)
class PlanSchedule:
    """When each part of a pipelined plan arrives (seconds from the start of planning).

    Attributes:
        calls: Every call, in the order they started.
        first_motion_s: When the first edge is grounded: the robot moves from then on.
        edge_ready_s: Edge id (nominal or recovery) -> when its grounding has arrived: the robot waits
            at the edge's source until then.
        mode_ready_s: (edge id, failure mode name) -> when the mode can be recovered from: its trigger
            and its recovery entry, with the entry's alternatives, have arrived grounded.
        modes_listed_s: Nominal edge id -> when the arranger's list of its failure modes (their monitors)
            has arrived: the monitors are armed from then on. A recovery edge's come with it.
        owners: Recovery edge or node id -> the (nominal edge, failure mode) whose branch brings it.
        critical: The parts the first motion waited for (the composer's stream, the first edge's grounding).
        hurries: The failures that hurried their branches, in the order they fired.
        inputs: The graph and latency model it was made from (None: a schedule that cannot be hurried).
    """

    calls: tuple[ScheduledCall, ...]
    first_motion_s: float
    edge_ready_s: dict[str, float]
    mode_ready_s: dict[tuple[str, str], float]
    modes_listed_s: dict[str, float] = field(default_factory=dict)
    owners: dict[str, tuple[str, str]] = field(default_factory=dict)
    critical: tuple[str, ...] = ()
    hurries: tuple[Hurry, ...] = ()
    inputs: tuple[TaskGraph, AnyLatencyModel] | None = field(default=None, compare=False, repr=False)

    def tick_of(self, seconds: float) -> int:
        """The control tick (counted from the first motion) at which a part arriving at ``seconds`` is armed."""
        return max(0, math.ceil(round((seconds - self.first_motion_s) * CONTROL_HZ, 6)))

    def hurried(self, at_s: float, edge_id: str, failure: str | None, recovery_edge: str | None = None) -> PlanSchedule:
        """The schedule once a failure of ``edge_id`` (``failure``, or None: which mode is not known yet)
        fired at ``at_s`` before its branch arrived: what that branch still needs goes first from then on.
        With ``recovery_edge``: the robot waits for that recovery edge's grounding (an alternative it
        bound, an edge further on in a branch), and what it still needs goes first.

        What started before ``at_s`` keeps its times; a schedule without inputs stays as it is.
        """
        if self.inputs is None:
            return self
        graph, latency = self.inputs
        return pipelined_schedule(graph, latency, (*self.hurries, Hurry(at_s, edge_id, failure, recovery_edge)))

    def branches_ready_s(self, edge_id: str) -> float:
        """When every failure mode of ``edge_id`` has arrived (its list, if it has none)."""
        modes = [s for (edge, _), s in self.mode_ready_s.items() if edge == edge_id]
        return max([self.modes_listed_s.get(edge_id, 0.0), *modes])


@dataclass(frozen=True)
class Hurry:
    """A failure that fired before its branch arrived: from ``at_s`` on, its branch's calls go first.

    Attributes:
        at_s: When it fired (seconds from the start of planning).
        edge_id: The nominal edge it fired on; with ``recovery_edge``, that recovery edge itself.
        failure: Its failure mode; None for a monitor derived from the edge's constraints before the
            arranger listed the edge's modes (every mode of the edge is hurried then).
        recovery_edge: A recovery edge the robot waits for instead (its grounding and what that reads are
            hurried, not the modes' branches).
    """

    at_s: float
    edge_id: str
    failure: str | None = None
    recovery_edge: str | None = None


@dataclass
class _Job:
    call: ModelledCall
    priority: tuple
    key: str
    after: str | None = None  # the job whose end releases this one (None: ``release_s``)
    release_s: float | None = None
    not_before_s: float = 0.0  # with ``after``: what it also reads arrives then
    after_start: str | None = None  # the streaming job whose start, plus ``offset_s``, releases this one
    offset_s: float = 0.0
    start_s: float = 0.0
    end_s: float = 0.0
    hurried_s: float | None = None  # from then on it goes before every call not hurried (the earliest hurry)

    def rank(self, now: float) -> tuple:
        if self.hurried_s is not None and self.hurried_s <= now:
            return (0, self.hurried_s, self.priority)
        return (1, 0.0, self.priority)


def pipelined_schedule(graph: TaskGraph, latency: AnyLatencyModel, hurries: tuple[Hurry, ...] = ()) -> PlanSchedule:
    """The pipelined plan of ``graph``: each call's start and end, and when each part is armed.

    Calls, in the order the robot needs them: the nominal edges' groundings first (without them the
    robot cannot go on; without a branch it can), then edge by edge the list of its failure modes,
    per mode its branch and the branch's grounding; last, per mode, the other arm's alternatives and
    their grounding. A call starts when what it reads has arrived
    (an edge's grounding the edge from the composer's stream; its modes the edge and its nodes; a
    branch also the nominal nodes it leaves from and merges at) and the model has a free slot (``latency.concurrency`` at once; the composer
    holds one while it streams); among the calls ready, the first in need goes first. A flat latency
    model does not stream: everything arrives with the whole nominal graph. ``hurries``: failures that
    fired before their branch (:meth:`PlanSchedule.hurried`).
    """
    path = nominal_path(graph)
    composer = composer_call(graph)
    composer_end = latency.price(composer)
    streamed = streamed_tokens(graph)
    owners = branch_owners(graph)

    def streamed_s(*ids: str) -> float:
        if not latency.streams:
            return composer_end
        tokens = max((streamed[i] for i in ids if i in streamed), default=0)
        return min(latency.first_token_s(composer) + latency.decode_s(tokens), composer_end)

    jobs: list[_Job] = []
    ground_key: dict[str, str] = {}  # recovery edge id, or "edge/mode" (its trigger), -> the job that grounds it
    for k, edge_id in enumerate(path):
        edge = graph.edge(edge_id)
        nominal = edge.model_copy(update={"failures": []})
        # The conductor grounds an edge's actions from the edge; the arranger's modes read what its nodes keep.
        jobs.append(_Job(ModelledCall("conductor", "plan", count_tokens(grounding_patch([nominal])), part=f"{edge_id} grounded"),
                         (0, k), f"edge:{edge_id}", release_s=streamed_s(edge_id)))
        jobs.append(_Job(ModelledCall("arranger", "plan", count_tokens(modes_reply(edge)), part=f"{edge_id} failure modes"),
                         (1, k, 0), f"modes:{edge_id}", release_s=streamed_s(edge_id, edge.source, edge.target)))
        for j, failure in enumerate(edge.failures):
            mode = f"{edge_id}/{failure.name}"
            reads = branch_nominal_nodes(graph, edge_id, failure.name, owners)
            branch = branch_reply(graph, edge_id, failure.name, owners)
            jobs.append(_Job(ModelledCall("arranger", "plan", count_tokens(branch), part=f"{mode} branch"), (1, k, 1, j),
                             f"branch:{mode}", after=f"modes:{edge_id}", not_before_s=streamed_s(edge_id, edge.target, *reads)))
            # The conductor grounds the branch's entry as soon as it has streamed (the robot needs it when the mode
            # fires), the rest of the branch once the arranger's reply ends.
            entry = set(branch_entry(graph, edge_id, failure.name, owners))
            edges = branch_edges(graph, edge_id, failure.name, owners)
            first = [e for e in edges if e.id in entry]
            patch = grounding_patch([edge.model_copy(update={"failures": [failure]}), *first])
            entry_job = _Job(ModelledCall("conductor", "plan", count_tokens(patch), part=f"{mode} entry grounded"),
                             (1, k, 2, j), f"entry:{mode}", after=f"branch:{mode}")
            if latency.streams:
                tokens = branch_entry_tokens(graph, edge_id, failure.name, owners)
                entry_job.after, entry_job.after_start = None, f"branch:{mode}"
                entry_job.offset_s = latency.first_token_s(jobs[-1].call) + latency.decode_s(tokens)
            jobs.append(entry_job)
            rest = [e for e in edges if e.id not in entry]
            if rest:
                jobs.append(_Job(ModelledCall("conductor", "plan", count_tokens(grounding_patch(rest)), part=f"{mode} rest grounded"),
                                 (1, k, 3, j), f"rest:{mode}", after=f"branch:{mode}"))
                ground_key.update({e.id: f"rest:{mode}" for e in rest})
            ground_key.update({e.id: f"entry:{mode}" for e in first})
            ground_key[f"{edge_id}/{failure.name}"] = f"entry:{mode}"
            # The other arm's way is needed only when the entry's arm cannot reach: written after every
            # edge's own branches, in a call of its own that reads the entry.
            alternatives = branch_alternatives(graph, edge_id, failure.name, owners)
            if alternatives:
                jobs.append(_Job(ModelledCall("arranger", "plan", count_tokens(alternatives_reply(graph, edge_id, failure.name, owners)),
                                              part=f"{mode} alternatives"), (2, k, j, 0), f"alternatives:{mode}", after=f"branch:{mode}"))
                jobs.append(_Job(ModelledCall("conductor", "plan", count_tokens(grounding_patch(alternatives)), part=f"{mode} alternatives grounded"),
                                 (2, k, j, 1), f"alternatives grounded:{mode}", after=f"alternatives:{mode}"))
                ground_key.update({e.id: f"alternatives grounded:{mode}" for e in alternatives})
    _hurry(jobs, hurries, graph, ground_key)
    done = _serve(jobs, latency, busy_until=[composer_end])
    ends = {job.key: job.end_s for job in done}
    recovery_ready = {item: ends[key] for item, key in ground_key.items() if "/" not in item}
    for recovery in graph.recovery_edges():  # owned by no nominal edge's mode: with the last branch's rest
        recovery_ready.setdefault(recovery.id, max(ends.values(), default=composer_end))
    modes: dict[tuple[str, str], float] = {}
    for edge, failure in graph.failures():
        # A mode can be recovered from once its trigger and its recovery entry have arrived grounded; an edge
        # further on in the branch, or the entry's alternative, is waited for when the robot is to start it.
        key = ground_key.get(f"{edge.id}/{failure.name}")
        own = ends[key] if key is not None else recovery_ready.get(edge.id, composer_end)
        entries = [recovery_ready[failure.recovery]] if failure.recovery in recovery_ready else []
        modes[(edge.id, failure.name)] = max([own, *entries])
    calls = [ScheduledCall(composer, 0.0, composer_end)]
    calls += [ScheduledCall(job.call, job.start_s, job.end_s) for job in sorted(done, key=lambda j: (j.start_s, j.priority))]
    edge_ready = {edge_id: ends[f"edge:{edge_id}"] for edge_id in path} | recovery_ready
    first_motion = edge_ready[path[0]] if path else composer_end
    listed = {edge_id: ends[f"modes:{edge_id}"] for edge_id in path}
    critical = (composer.part, f"{path[0]} grounded") if path else (composer.part,)
    return PlanSchedule(tuple(calls), first_motion, edge_ready, modes, listed, owners, critical, tuple(hurries), (graph, latency))


def _hurry(jobs: list[_Job], hurries: tuple[Hurry, ...], graph: TaskGraph, ground_key: dict[str, str]) -> None:
    """Mark the calls each hurried branch still needs: the edge's list of modes, the branch, the grounding of
    its entry (another mode's branch may bring it), and the calls they read. Not the entry's alternatives:
    the robot needs one only if its arm cannot reach, which is known when the recovery binds."""
    by_key = {job.key: job for job in jobs}
    for hurry in hurries:
        if hurry.recovery_edge is not None:  # a recovery edge's grounding, not a mode's branch
            modes, keys = [], [ground_key[hurry.recovery_edge]] if hurry.recovery_edge in ground_key else []
        else:
            modes = [hurry.failure] if hurry.failure is not None else [f.name for f in graph.edge(hurry.edge_id).failures]
            keys = [f"modes:{hurry.edge_id}"]
        for name in modes:
            keys.append(f"entry:{hurry.edge_id}/{name}")
            failure = next((f for f in graph.edge(hurry.edge_id).failures if f.name == name), None)
            if failure is not None:
                keys += [ground_key[failure.recovery]] if failure.recovery in ground_key else []
        while keys:
            job = by_key.get(keys.pop())
            if job is None or (job.hurried_s is not None and job.hurried_s <= hurry.at_s):
                continue
            job.hurried_s = hurry.at_s
            keys += [k for k in (job.after, job.after_start) if k is not None]


def _serve(jobs: list[_Job], latency: AnyLatencyModel, busy_until: list[float]) -> list[_Job]:
    """List scheduling: whenever a slot is free, the released job first in need starts."""
    slots = list(busy_until) + [0.0] * (latency.concurrency - len(busy_until))
    pending = list(jobs)
    ended: dict[str, float] = {}
    started: dict[str, float] = {}
    done: list[_Job] = []
    while pending:
        for job in pending:
            if job.release_s is None and job.after in ended:
                job.release_s = max(ended[job.after], job.not_before_s)
            if job.release_s is None and job.after_start in started:
                job.release_s = max(started[job.after_start] + job.offset_s, job.not_before_s)
        released = [(j, j.release_s) for j in pending if j.release_s is not None]
        slot = min(range(len(slots)), key=lambda i: slots[i])
        now = max(slots[slot], min(release_s for _, release_s in released))
        job = min((j for j, release_s in released if release_s <= now), key=lambda j: j.rank(now))
        job.start_s, job.end_s = now, now + latency.price(job.call)
        slots[slot] = job.end_s
        ended[job.key] = job.end_s
        started[job.key] = job.start_s
        pending.remove(job)
        done.append(job)
    return done
