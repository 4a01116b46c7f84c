"""Seeded disturbances. Issue 2 ships the paper's simulated one: the random drop.

The schedule is a stream drawn from the seed, consumed once per atomic action
started, so two strategies run with the same seed see the same draws for
their n-th action: the same disturbances until their paths diverge.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.worlds.sim.world import SimWorld


@dataclass
class DropEvent:
    """One injected disturbance.

    Attributes:
        tick: Tick it happened (for a drop: the gripper was forced open).
        arm: The arm that lost its object ("" when no arm is involved).
        obj: The object that was dropped or pushed.
        action: The atomic action that was running.
        kind: ``drop`` or ``shift``.
    """

    tick: int
    arm: str
    obj: str
    action: str
    kind: str = "drop"


def drop_if_held(world: SimWorld, frame: FeatureFrame, arm: str, action: str, fault_ticks: int) -> DropEvent | None:
    """Force ``arm``'s gripper open if it holds an object with a closed grip.

    An opening gripper is releasing anyway, and an empty one has nothing to drop.
    """
    held = sorted(obj for a, obj in frame.holding if a == arm)
    if not held or world.commands[arm].grip < 0.5:
        return None
    world.inject_gripper_fault(arm, fault_ticks)
    return DropEvent(tick=world.tick, arm=arm, obj=held[0], action=action)


@dataclass
class RandomDrop:
    """With probability ``p`` per atomic action, the held object is dropped at a random moment.

    The drop is a gripper fault: the fingers are forced open for ``fault_ticks``
    ticks, then control returns to the program. If the arm holds nothing at
    the drawn moment, nothing happens (there is nothing to drop).

    Args:
        p: Probability per atomic action.
        seed: Seed of the schedule.
        fault_ticks: How long the fingers are forced open.
    """

    p: float
    seed: int
    fault_ticks: int = 12
    events: list[DropEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not 0.0 <= self.p <= 1.0:
            raise ValueError(f"drop probability must be in [0, 1], got {self.p}")
        self._rng = np.random.default_rng([self.seed, 0xD209])
        self._pending: dict[str, tuple[int, str]] = {}

    def action_started(self, arm: str, action: str, expected_ticks: int, tick: int) -> None:
        """Draw whether (and when) this action will suffer a drop."""
        # Always draw both numbers so the stream stays aligned across strategies.
        drop, moment = self._rng.random() < self.p, self._rng.random()
        if drop:
            self._pending[arm] = (tick + 1 + int(moment * expected_ticks), action)
        else:
            self._pending.pop(arm, None)

    def action_ended(self, arm: str) -> None:
        """The action ended (or was interrupted) before its drawn moment: no drop."""
        self._pending.pop(arm, None)

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DropEvent | None:
        """Inject a drop that is due now."""
        for arm, (due, action) in list(self._pending.items()):
            if world.tick < due:
                continue
            del self._pending[arm]
            event = drop_if_held(world, frame, arm, action, self.fault_ticks)
            if event is not None:
                self.events.append(event)
                return event
        return None


@dataclass
class ScriptedDrop:
    """A drop at a chosen moment: during the ``nth`` run of ``action`` (0-based), ``after`` ticks in.

    For tests and demonstrations of one specific failure; same interface as :class:`RandomDrop`.
    """

    action: str
    nth: int = 0
    after: int = 20
    fault_ticks: int = 12
    events: list[DropEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._seen = 0
        self._due: tuple[str, int] | None = None

    def action_started(self, arm: str, action: str, expected_ticks: int, tick: int) -> None:
        """Arm the drop when the chosen run of the chosen action starts."""
        if action != self.action:
            return
        if self._seen == self.nth:
            self._due = (arm, tick + self.after)
        self._seen += 1

    def action_ended(self, arm: str) -> None:
        """Disarm if the action ended before the moment."""
        if self._due is not None and self._due[0] == arm:
            self._due = None

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DropEvent | None:
        """Force the gripper open when due, if it holds something."""
        if self._due is None or world.tick < self._due[1]:
            return None
        arm = self._due[0]
        self._due = None
        event = drop_if_held(world, frame, arm, self.action, self.fault_ticks)
        if event is not None:
            self.events.append(event)
        return event


@dataclass
class ScriptedPush:
    """Push an object (e.g. the cup) during the ``nth`` run of ``action``, ``after`` ticks in.

    A horizontal force for a few ticks: the object slides, as when a person moves the target.
    Recorded in the trace as a ``shift`` disturbance.
    """

    action: str
    obj: str
    force: tuple[float, float, float] = (0.0, 3.0, 0.0)
    nth: int = 0
    after: int = 20
    ticks: int = 8
    events: list[DropEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._seen = 0
        self._due: int | None = None

    def action_started(self, arm: str, action: str, expected_ticks: int, tick: int) -> None:
        """Arm the push when the chosen run of the chosen action starts."""
        if action == self.action:
            if self._seen == self.nth:
                self._due = tick + self.after
            self._seen += 1

    def action_ended(self, arm: str) -> None:
        """Pushes do not depend on the action still running."""

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DropEvent | None:
        """Push when due."""
        if self._due is None or world.tick < self._due:
            return None
        self._due = None
        world.push(self.obj, np.asarray(self.force, dtype=float), self.ticks)
        event = DropEvent(tick=world.tick, arm="", obj=self.obj, action=self.action, kind="shift")
        self.events.append(event)
        return event


#: Anything with the schedule interface the executor drives.
Disturbance = RandomDrop | ScriptedDrop | ScriptedPush
