"""What a trial hands the executor besides the world: a disturbance schedule and a success check.

Both come from the world's side (the simulator's seeded disturbances and task checks,
``worlds/sim``); the executor names only these protocols. A real robot's trial may have
neither: no injected disturbances, and success judged by the graph's goal constraints.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from agentchord.actions.base import ArmAction
    from agentchord.features.frame import FeatureFrame
    from agentchord.worlds.protocol import World


class DisturbanceEvent(Protocol):
    """One injected disturbance, as the executor books it.

    Attributes:
        tick: Tick it happened.
        kind: Its kind (``drop``, ``pull``, ``perturb``, ``shift``, ``knock``).
        obj: The object it acted on.
        arm: The arm that lost its object ("" when none).
        action: The atomic action that was running ("" when none).
    """

    tick: int
    kind: str
    obj: str
    arm: str
    action: str


class Disturbance(Protocol):
    """A seeded disturbance schedule: told of action starts and ends, applied every tick."""

    events: list[DisturbanceEvent]

    def action_started(self, arm: str, action: ArmAction, expected_ticks: int, tick: int) -> None:
        """An atomic action started on ``arm``."""
        ...

    def action_ended(self, arm: str) -> None:
        """The action on ``arm`` ended or was interrupted."""
        ...

    def apply(self, world: World, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject what is due now (through the world's own means: a simulator's forces and faults)."""
        ...


class Verdict(Protocol):
    """Whether the task succeeded, and why not."""

    success: bool
    reason: str


class SuccessTracker(Protocol):
    """Watches an episode's frames and judges its end state."""

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick (for events that must happen during the episode)."""
        ...

    def verdict(self, frame: FeatureFrame, world: World) -> Verdict:
        """Judge the end state."""
        ...
