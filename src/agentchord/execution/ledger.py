"""The episode's disturbance metrics: what was detected, how fast, and what was recovered.

A disturbance is *open* from its injection until the next detection at or after it, which is its
detection (reaction latency: ticks from the disturbance to that detection; seconds from the
disturbance to the recovery switch, reasoning charged meanwhile included). A detection reported
late (a failure that waited for its branch while a second disturbance came) detects the latest
disturbance before it, not the one that came during the wait. It stays *unmerged* until the recovery
it started merges back into the nominal path (or its failure clears), and then counts as
recovered. A second disturbance may interrupt the first one's recovery: both merge together.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from agentchord.harness import DisturbanceEvent
from agentchord.worlds.protocol import CONTROL_HZ


@dataclass
class DisturbanceLedger:
    """Counts and latencies of the disturbances of one episode.

    Attributes:
        open: The disturbances injected and not detected yet, in order, each with the reasoning
            charged when it came (a detection takes the latest one before it and drops those before
            that one: a disturbance not detected before the next one is not counted).
        detected: Disturbances detected, in order.
        recovered: Disturbances whose recovery merged back (or whose failure cleared).
        unmerged: Detected disturbances whose recovery has not merged back yet.
        latency_ticks: Per detection, ticks from the disturbance to its detection.
        latency_s: Per recovery switch, seconds from the disturbance to the switch.
    """

    open: list[tuple[DisturbanceEvent, float]] = field(default_factory=list)
    detected: list[DisturbanceEvent] = field(default_factory=list)
    recovered: list[DisturbanceEvent] = field(default_factory=list)
    unmerged: list[DisturbanceEvent] = field(default_factory=list)
    latency_ticks: list[int] = field(default_factory=list)
    latency_s: list[float] = field(default_factory=list)
    _reasoning_at: dict[int, float] = field(default_factory=dict)  # id(event) -> reasoning charged when it came

    def injected(self, event: DisturbanceEvent, reasoning_s: float) -> None:
        """A disturbance happened (``reasoning_s``: reasoning charged so far in the episode)."""
        self.open.append((event, reasoning_s))

    def detection(self, tick: int) -> DisturbanceEvent | None:
        """A failure was detected at ``tick``: the open disturbance it detects, if any."""
        before = [k for k, (event, _) in enumerate(self.open) if event.tick <= tick]
        if not before:
            return None
        (event, reasoning_s), self.open = self.open[before[-1]], self.open[before[-1] + 1:]
        self._reasoning_at[id(event)] = reasoning_s
        self.detected.append(event)
        self.latency_ticks.append(tick - event.tick)
        self.unmerged.append(event)
        return event

    def switched(self, event: DisturbanceEvent, tick: int, reasoning_s: float) -> None:
        """The recovery for ``event`` starts at ``tick``: robot time plus the reasoning charged since."""
        self.latency_s.append((tick - event.tick) / CONTROL_HZ + reasoning_s - self._reasoning_at.get(id(event), reasoning_s))

    def merged(self) -> None:
        """The recoveries under way are over: what they were for is recovered."""
        self.recovered.extend(self.unmerged)
        self.unmerged = []

    def by_kind(self, injected: list[DisturbanceEvent]) -> dict[str, list[int]]:
        """Per kind injected: [injected, detected, recovered]."""
        groups = (injected, self.detected, self.recovered)
        return {kind: [sum(e.kind == kind for e in group) for group in groups] for kind in sorted({e.kind for e in injected})}

    def drops(self, injected: list[DisturbanceEvent]) -> tuple[int, int, int]:
        """Drops injected, detected and recovered (the paper's simulated disturbance)."""
        dropped, detected, recovered = (sum(e.kind == "drop" for e in group) for group in (injected, self.detected, self.recovered))
        return dropped, detected, recovered
