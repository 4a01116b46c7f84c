"""What a trial hands the executor besides the world: a disturbance schedule and a success check.

The one home of the trial's protocols and the values they pass. The simulator implements them
(``worlds/sim``: seeded disturbances, each task's success check); the executor names only these.
A real robot's trial may have neither: no injected disturbances, and success judged by the graph's
goal constraints.

A layer of its own, just above the feature frames it reads: both the executor and the simulator
(which sits below the executor) import it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from agentchord.features.frame import FeatureFrame
    from agentchord.worlds.protocol import World


@dataclass
class DisturbanceEvent:
    """One injected disturbance, as the schedule reports it and the executor books it.

    Attributes:
        tick: Tick it happened.
        kind: Its kind (``drop``, ``pull``, ``perturb``, ``shift``, ``knock``).
        obj: The object that was dropped, pulled, pushed or knocked.
        arm: The arm that lost its object ("" when no arm is involved).
        action: The atomic action that was running ("" when none was).
    """

    tick: int
    kind: str
    obj: str
    arm: str = ""
    action: str = ""


class RunningAction(Protocol):
    """What a disturbance schedule reads of an atomic action that started: its name and arguments
    (an ``obj`` argument is the object it works on)."""

    name: str
    args: Any


class Disturbance(Protocol):
    """A seeded disturbance schedule: told of action starts and ends, applied every tick."""

    events: list[DisturbanceEvent]

    def action_started(self, arm: str, action: RunningAction, expected_ticks: int, tick: int) -> None:
        """An atomic action started on ``arm``."""
        ...

    def action_ended(self, arm: str) -> None:
        """The action on ``arm`` ended or was interrupted."""
        ...

    def apply(self, world: Any, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject what is due now (through the world's own means: a simulator's forces and faults)."""
        ...


@dataclass
class Verdict:
    """Whether the task succeeded, and why not.

    Attributes:
        success: Whether it succeeded.
        reason: What holds, or what does not.
        settling: It failed only because something is still moving: judged again once at rest.
    """

    success: bool
    reason: str
    settling: bool = False


class SuccessTracker(Protocol):
    """Watches an episode's frames and judges its end state."""

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick (for events that must happen during the episode)."""
        ...

    def verdict(self, frame: FeatureFrame, world: World) -> Verdict:
        """Judge the end state."""
        ...
