"""The episode's disturbance metrics: what was detected, how fast, and what was recovered.

A disturbance is *open* from its injection until the next detection, which is its detection
(reaction latency: ticks from the disturbance to that detection; seconds from the disturbance to
the recovery switch, reasoning charged meanwhile included). It stays *unmerged* until the recovery
it started merges back into the nominal path (or its failure clears), and then counts as
recovered. A second disturbance may interrupt the first one's recovery: both merge together.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from agentchord.execution.harness import DisturbanceEvent
from agentchord.worlds.protocol import CONTROL_HZ


@dataclass
class DisturbanceLedger:
    """Counts and latencies of the disturbances of one episode.

    Attributes:
        open: The last disturbance injected and not detected yet.
        detected: Disturbances detected, in order.
        recovered: Disturbances whose recovery merged back (or whose failure cleared).
        unmerged: Detected disturbances whose recovery has not merged back yet.
        latency_ticks: Per detection, ticks from the disturbance to its detection.
        latency_s: Per recovery switch, seconds from the disturbance to the switch.
    """

    open: DisturbanceEvent | None = None
    detected: list[DisturbanceEvent] = field(default_factory=list)
    recovered: list[DisturbanceEvent] = field(default_factory=list)
    unmerged: list[DisturbanceEvent] = field(default_factory=list)
    latency_ticks: list[int] = field(default_factory=list)
    latency_s: list[float] = field(default_factory=list)
    _reasoning_at_open: float = 0.0

    def injected(self, event: DisturbanceEvent, reasoning_s: float) -> None:
        """A disturbance happened (``reasoning_s``: reasoning charged so far in the episode)."""
        self.open = event
        self._reasoning_at_open = reasoning_s

    def detection(self, tick: int) -> DisturbanceEvent | None:
        """A failure was detected at ``tick``: the open disturbance it detects, if any."""
        event, self.open = self.open, None
        if event is not None:
            self.detected.append(event)
            self.latency_ticks.append(tick - event.tick)
            self.unmerged.append(event)
        return event

    def switched(self, event: DisturbanceEvent, tick: int, reasoning_s: float) -> None:
        """The recovery for ``event`` starts at ``tick``: robot time plus the reasoning charged since."""
        self.latency_s.append((tick - event.tick) / CONTROL_HZ + reasoning_s - self._reasoning_at_open)

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
        return tuple(sum(e.kind == "drop" for e in group) for group in (injected, self.detected, self.recovered))
