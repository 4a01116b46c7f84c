"""Seeded disturbances: the paper's random drop and its real-world disturbance kinds.

Kinds (all physical: forces and gripper faults, never teleports):

- ``drop``: the held object falls: the gripper is forced open for a moment.
- ``pull``: the held object is taken out of the gripper during motion: the
  gripper is forced open and the object is shoved away from the hand.
- ``perturb``: the object being grasped is pushed before the fingers close.
- ``shift``: a target the action refers to (the cup the bottle approaches;
  for an action without an object, the free object nearest the tool) slides
  to a new place.
- ``knock``: an object nobody holds is knocked over (a push high on it).

Two schedules. :class:`RandomDisturbances` draws once per atomic action
started (probability ``p``, a moment within the action, a kind): the paper's
simulated protocol, a stream that two strategies with the same seed consume
identically for their n-th action. :class:`ProtocolDisturbances` is the
paper's real-world protocol: one or two disturbances at random moments of
each trial. Scripted variants inject one chosen disturbance, for tests.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.worlds.sim.world import SimWorld

if TYPE_CHECKING:
    from agentchord.actions.base import ArmAction

#: Every disturbance kind, in a fixed order (the order seeded choices index into).
KINDS = ("drop", "pull", "perturb", "shift", "knock")
#: How long a gripper fault forces the fingers open (ticks at 50 Hz).
FAULT_TICKS = 12


@dataclass
class DisturbanceEvent:
    """One injected disturbance.

    Attributes:
        tick: Tick it happened.
        kind: One of :data:`KINDS`.
        obj: The object that was dropped, pulled, pushed or knocked.
        arm: The arm that lost its object ("" when no arm is involved).
        action: The atomic action that was running ("" when none was).
    """

    tick: int
    kind: str
    obj: str
    arm: str = ""
    action: str = ""


def _held_by(frame: FeatureFrame, arm: str) -> list[str]:
    return sorted(obj for a, obj in frame.holding if a == arm)


def _free_objects(frame: FeatureFrame, world: SimWorld) -> list[str]:
    # Rigid bodies only: a frame may also carry feature points (a cloth's corners).
    held = {obj for _, obj in frame.holding}
    return sorted(name for name in world.object_names if name not in held)


def _slide(world: SimWorld, obj: str, direction: np.ndarray, ticks: int = 6) -> None:
    # Overcome sliding friction plus 6 m/s^2 for 0.12 s: the object slides ~5-8 cm.
    spec = world.object_spec(obj)
    world.push(obj, spec.mass * (spec.friction * 9.81 + 6.0) * direction, ticks=ticks)


def _horizontal(rng: np.random.Generator) -> np.ndarray:
    angle = rng.uniform(0.0, 2.0 * np.pi)
    return np.array([np.cos(angle), np.sin(angle), 0.0])


def inject(kind: str, world: SimWorld, frame: FeatureFrame, rng: np.random.Generator,
           arm: str = "", action: ArmAction | None = None,
           direction: tuple[float, float, float] | None = None) -> DisturbanceEvent | None:
    """Apply one disturbance of ``kind`` now, if it applies to the current state.

    Args:
        kind: One of :data:`KINDS`.
        world: The world to act on.
        frame: The current features (who holds what).
        rng: Draws directions and choices (seeded by the schedule).
        arm: The arm whose action is running (drop, pull, perturb, shift).
        action: The running atomic action (its ``obj`` argument is the target).
        direction: Horizontal direction of a push or knock (None: drawn from ``rng``).

    Returns:
        The event, or None when the kind does not apply now (nothing held to
        drop, no grasp in progress to perturb, ...).

    Raises:
        ValueError: Unknown kind.
    """
    name = action.name if action is not None else ""
    target = getattr(getattr(action, "args", None), "obj", None)
    if direction is not None:
        push_dir = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    else:
        push_dir = _horizontal(rng)
    if kind in ("drop", "pull"):
        held = _held_by(frame, arm) if arm else []
        # Only a closed grip can lose its object: an opening gripper is releasing anyway.
        if not held or world.commands[arm].grip < 0.5:
            return None
        world.inject_gripper_fault(arm, FAULT_TICKS)
        if kind == "pull" and held[0] in world.object_names:
            # Taken out of the hand: shoved away from the gripper, outward and down.
            away = world.tcp_pose(arm)[1][:, 0]
            away = np.array([away[0], away[1], 0.0]) / max(np.linalg.norm(away[:2]), 1e-6)
            _slide(world, held[0], away)
        return DisturbanceEvent(world.tick, kind, held[0], arm, name)
    if kind == "perturb":
        if name != "grasp" or target not in world.object_names or frame.is_holding(arm, target):
            return None
        _slide(world, target, push_dir)
        return DisturbanceEvent(world.tick, kind, target, arm, name)
    if kind == "shift":
        free = _free_objects(frame, world)
        if target is None and arm and free:
            # An action without an object (a pour): move what the tool works over.
            tool = frame.arms[arm].ee
            target = min(free, key=lambda n: float(np.linalg.norm(frame.objects[n].pos[:2] - tool[:2])))
        if target is None or name == "grasp" or target not in free:
            return None
        _slide(world, target, push_dir)
        return DisturbanceEvent(world.tick, kind, target, arm, name)
    if kind == "knock":
        upright = [n for n in _free_objects(frame, world) if frame.objects[n].axis[2] > 0.9]
        if not upright:
            return None
        victim = target if target in upright else upright[int(rng.integers(len(upright)))]
        world.knock(victim, push_dir)
        return DisturbanceEvent(world.tick, kind, victim, "", name)
    raise ValueError(f"unknown disturbance kind {kind!r} (kinds: {', '.join(KINDS)})")


class Disturbance(Protocol):
    """What the executor drives: told of action starts and ends, applied every tick."""

    events: list[DisturbanceEvent]

    def action_started(self, arm: str, action: ArmAction, expected_ticks: int, tick: int) -> None:
        """An atomic action started on ``arm``."""

    def action_ended(self, arm: str) -> None:
        """The action on ``arm`` ended or was interrupted."""

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject what is due now."""


def parse_kinds(text: str) -> tuple[str, ...]:
    """``"drop,shift"`` -> ``("drop", "shift")``.

    Raises:
        ValueError: An unknown kind or an empty list.
    """
    kinds = tuple(k.strip() for k in text.split(",") if k.strip())
    unknown = [k for k in kinds if k not in KINDS]
    if unknown or not kinds:
        raise ValueError(f"unknown disturbance kind(s) {unknown or text!r} (kinds: {', '.join(KINDS)})")
    return kinds


@dataclass
class RandomDisturbances:
    """With probability ``p`` per atomic action, one disturbance at a random moment within it.

    With ``kinds=("drop",)`` this is the paper's simulated disturbance. If the
    drawn kind does not apply at the drawn moment (nothing held to drop),
    nothing happens.

    Args:
        p: Probability per atomic action.
        seed: Seed of the schedule.
        kinds: Kinds to draw from.
    """

    p: float
    seed: int
    kinds: tuple[str, ...] = ("drop",)
    events: list[DisturbanceEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not 0.0 <= self.p <= 1.0:
            raise ValueError(f"disturbance probability must be in [0, 1], got {self.p}")
        parse_kinds(",".join(self.kinds))
        self._rng = np.random.default_rng([self.seed, 0xD209])
        self._pending: dict[str, tuple[int, str, ArmAction]] = {}

    def action_started(self, arm: str, action: ArmAction, expected_ticks: int, tick: int) -> None:
        """Draw whether, when and what disturbs this action."""
        # Always draw all three so the stream stays aligned across strategies.
        hit, moment, pick = self._rng.random() < self.p, self._rng.random(), self._rng.random()
        if hit:
            kind = self.kinds[int(pick * len(self.kinds))]
            self._pending[arm] = (tick + 1 + int(moment * expected_ticks), kind, action)
        else:
            self._pending.pop(arm, None)

    def action_ended(self, arm: str) -> None:
        """The action ended before its drawn moment: nothing happens."""
        self._pending.pop(arm, None)

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject a disturbance that is due now."""
        for arm, (due, kind, action) in list(self._pending.items()):
            if world.tick < due:
                continue
            del self._pending[arm]
            event = inject(kind, world, frame, self._rng, arm, action)
            if event is not None:
                self.events.append(event)
                return event
        return None


@dataclass
class ProtocolDisturbances:
    """The paper's real-world protocol: one or two disturbances at random moments of each trial.

    Moments are drawn in ticks within ``window``; at its moment a disturbance
    of a drawn kind is injected as soon as it applies (retrying for up to
    ``patience`` ticks, then trying the other kinds in order).

    Args:
        seed: Seed of the schedule.
        kinds: Kinds to draw from.
        window: Range of ticks the moments are drawn from.
        patience: Ticks a due disturbance waits for a state it applies to.
    """

    seed: int
    kinds: tuple[str, ...] = KINDS
    window: tuple[int, int] = (60, 650)
    patience: int = 100
    events: list[DisturbanceEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        parse_kinds(",".join(self.kinds))
        self._rng = np.random.default_rng([self.seed, 0x9A07])
        count = int(self._rng.integers(1, 3))
        moments = sorted(int(t) for t in self._rng.integers(*self.window, size=count))
        self._due = [(t, self.kinds[int(self._rng.integers(len(self.kinds)))]) for t in moments]
        self._running: dict[str, ArmAction] = {}

    def action_started(self, arm: str, action: ArmAction, expected_ticks: int, tick: int) -> None:
        """Remember what each arm is doing (the target of perturb and shift)."""
        self._running[arm] = action

    def action_ended(self, arm: str) -> None:
        """The arm is idle."""
        self._running.pop(arm, None)

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject the next due disturbance once it applies."""
        if not self._due or world.tick < self._due[0][0]:
            return None
        due, kind = self._due[0]
        late = world.tick - due > self.patience
        order = [k for k in self.kinds if k != kind] if late else [kind]
        for candidate in order:
            for arm in sorted(self._running) or [""]:
                event = inject(candidate, world, frame, self._rng, arm, self._running.get(arm))
                if event is not None:
                    self._due.pop(0)
                    self.events.append(event)
                    return event
        if late:
            self._due.pop(0)  # nothing applies at all: skip this one
        return None


@dataclass
class ScriptedDisturbance:
    """One chosen disturbance during the ``nth`` run of ``action`` (0-based), ``after`` ticks in.

    For tests and demonstrations of one specific failure.
    """

    action: str
    kind: str = "drop"
    nth: int = 0
    after: int = 20
    seed: int = 0
    direction: tuple[float, float, float] | None = None
    events: list[DisturbanceEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        parse_kinds(self.kind)
        self._rng = np.random.default_rng([self.seed, 0x5C41])
        self._seen = 0
        self._due: tuple[str, int, ArmAction] | None = None

    def action_started(self, arm: str, action: ArmAction, expected_ticks: int, tick: int) -> None:
        """Arm the disturbance when the chosen run of the chosen action starts."""
        if action.name != self.action:
            return
        if self._seen == self.nth:
            self._due = (arm, tick + self.after, action)
        self._seen += 1

    def action_ended(self, arm: str) -> None:
        """Disarm an arm-bound disturbance whose action ended before the moment."""
        if self._due is not None and self._due[0] == arm and self.kind in ("drop", "pull", "perturb"):
            self._due = None

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject when due."""
        if self._due is None or world.tick < self._due[1]:
            return None
        arm, _, action = self._due
        self._due = None
        event = inject(self.kind, world, frame, self._rng, arm, action, self.direction)
        if event is not None:
            self.events.append(event)
        return event


def ScriptedDrop(action: str, nth: int = 0, after: int = 20) -> ScriptedDisturbance:  # noqa: N802  (reads as a type)
    """A drop during the ``nth`` run of ``action``, ``after`` ticks in."""
    return ScriptedDisturbance(action, "drop", nth, after)
