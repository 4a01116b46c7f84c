"""What an episode did: its outcome and the metrics of DESIGN section 7."""

from __future__ import annotations

from dataclasses import dataclass, field

from agentchord.execution.trace import Trace

#: Prefix of the reason of an episode that ended because no arm can take an object any more.
UNRECOVERABLE = "unrecoverable"


@dataclass
class EpisodeResult:
    """What an episode did: the metrics of DESIGN section 7.

    ``drops_*`` count the paper's drop disturbance; ``disturbances`` maps every injected
    kind to [injected, detected, recovered]. Reaction latencies are ticks from a
    disturbance to the first detection after it. ``repairs`` counts accepted online repairs.
    """

    success: bool
    reason: str
    steps: int
    time_s: float
    wall_s: float
    path: list[str]
    failures_detected: int
    recoveries: int
    repairs: int
    drops_injected: int
    drops_detected: int
    drops_recovered: int
    reaction_latency_ticks: list[int]
    disturbances: dict[str, list[int]]
    trace: Trace = field(repr=False)
    #: Measured wall time of the planner's own work during the episode (re-plans, repairs).
    compute_s: float = 0.0
    #: Reasoning latency charged: modelled per call offline, measured for a real LLM.
    reasoning_s: float = 0.0
    #: Reasoning calls by kind (``plan``, ``vqa``, ``vlm``).
    reasoning_calls: dict[str, int] = field(default_factory=dict)
    #: Seconds from each detected disturbance to the start of its recovery, reasoning included.
    reaction_latency_s: list[float] = field(default_factory=list)
    #: Re-plans made (the re-planning baselines).
    replans: int = 0
    #: Seconds from receiving the task to the robot's first motion: the reasoning (and compute) it waited for.
    first_motion_s: float = 0.0
    #: Seconds the robot held still mid-episode for a part of a pipelined plan that had not arrived (in ``time_s``).
    plan_wait_s: float = 0.0
    #: Failures that fired before their recovery branch had arrived: edge, failure, tick, ticks waited, what came of it.
    early_failures: list[dict] = field(default_factory=list)

    @property
    def exec_time_s(self) -> float:
        """Execution time: robot time + measured compute + reasoning latency (DESIGN section 6)."""
        return self.time_s + self.compute_s + self.reasoning_s

    @property
    def critical_reasoning_s(self) -> float:
        """Reasoning on the critical path: what the robot held still for, before its first motion and after."""
        return self.reasoning_s + self.plan_wait_s

    @property
    def unrecoverable(self) -> bool:
        """Whether it ended because an object was beyond every arm (off the table, out of reach)."""
        return self.reason.startswith(UNRECOVERABLE)

    def summary(self) -> dict:
        """The JSON summary of ``agentchord run --json``."""
        return {
            "success": self.success,
            "reason": self.reason,
            "steps": self.steps,
            "time_s": round(self.time_s, 3),
            "wall_s": round(self.wall_s, 3),
            "failures_detected": self.failures_detected,
            "recoveries": self.recoveries,
            "repairs": self.repairs,
            "drops_injected": self.drops_injected,
            "drops_detected": self.drops_detected,
            "drops_recovered": self.drops_recovered,
            "reaction_latency_ticks": self.reaction_latency_ticks,
            "reaction_latency_s": [round(x, 3) for x in self.reaction_latency_s],
            "exec_time_s": round(self.exec_time_s, 3),
            "robot_time_s": round(self.time_s, 3),
            "compute_s": round(self.compute_s, 3),
            "reasoning_s": round(self.reasoning_s, 3),
            "reasoning_calls": dict(self.reasoning_calls),
            "replans": self.replans,
            "first_motion_s": round(self.first_motion_s, 3),
            "critical_reasoning_s": round(self.critical_reasoning_s, 3),
            "plan_wait_s": round(self.plan_wait_s, 3),
            "early_failures": self.early_failures,
            "disturbances": self.disturbances,
            "unrecoverable": self.unrecoverable,
            "path": self.path,
        }
