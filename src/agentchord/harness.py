"""What a trial hands the executor besides the world: a disturbance schedule and a success check.

The one home of the trial's protocols and the values they pass. The simulator implements them
(``sim/``: seeded disturbances, each task's success check); the executor names only these.
A real robot's trial may have neither: no injected disturbances, and success judged by the graph's
goal constraints.

A layer of its own, just above the feature frames it reads: both the executor and the simulator
(which sits below the executor) import it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from agentchord.features.frame import FeatureFrame
    from agentchord.worlds.protocol import World


#: Every disturbance kind, in a fixed order (the order seeded choices index into).
KINDS = ("drop", "pull", "perturb", "shift", "knock")
#: Protocol presets: the paper's real-world protocol (Table II) and the all-kinds stress test.
PRESETS: dict[str, tuple[str, ...]] = {"real": ("perturb", "pull"), "stress": KINDS}
#: The protocols a setting may name: the presets, and ``custom`` (1-2 per trial of the given kinds).
PROTOCOLS = (*PRESETS, "custom")
#: Ticks the moments of a protocol's disturbances are drawn from.
PROTOCOL_WINDOW = (60, 650)


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


@dataclass(frozen=True)
class DisturbanceSetting:
    """How the episodes of a run are disturbed: the one value every front end builds, the same way.

    Either random per-action draws (``protocol`` None: each atomic action is disturbed with
    probability ``p``, the paper's Table I with ``kinds=("drop",)``), or a protocol (1-2 disturbances
    of ``kinds`` at random moments of each trial within ``window``, whatever ``p``: ``real`` is the
    paper's Table II, ``stress`` every kind, ``custom`` the kinds given). The seed of an episode
    draws the schedule (the simulator's ``sim.disturbances.schedule``).

    Attributes:
        p: Probability per atomic action, in [0, 1].
        kinds: The kinds drawn from.
        protocol: ``real``, ``stress``, ``custom``, or None.
        window: Ticks a protocol's moments are drawn from.

    Raises:
        ValueError: ``p`` not a finite number in [0, 1], an unknown kind or protocol, or an empty window.
    """

    p: float = 0.0
    kinds: tuple[str, ...] = ("drop",)
    protocol: str | None = None
    window: tuple[int, int] = PROTOCOL_WINDOW

    def __post_init__(self) -> None:
        if not (isinstance(self.p, int | float) and math.isfinite(self.p) and 0.0 <= self.p <= 1.0):
            raise ValueError(f"disturbance probability p must be a finite number in [0, 1], got {self.p!r}")
        parse_kinds(",".join(self.kinds))
        if self.protocol is not None and self.protocol not in PROTOCOLS:
            raise ValueError(f"unknown disturbance protocol {self.protocol!r} (protocols: {', '.join(PROTOCOLS)})")
        if not 0 <= self.window[0] < self.window[1]:
            raise ValueError(f"disturbance window must be 0 <= start < end ticks, got {self.window!r}")

    @classmethod
    def from_options(cls, p: float = 0.0, disturb: str | tuple[str, ...] | None = ("drop",), protocol: str | None = None,
                     window: tuple[int, int] = PROTOCOL_WINDOW) -> DisturbanceSetting:
        """The setting of a front end's options: ``--p``, ``--disturb`` (kinds, comma-separated or a
        sequence) and ``--protocol`` (a preset brings its own kinds; ``custom`` takes ``disturb``'s).

        Raises:
            ValueError: As the class does.
        """
        if protocol in PRESETS:
            kinds = PRESETS[protocol]
        elif isinstance(disturb, str):
            kinds = parse_kinds(disturb)
        else:
            kinds = parse_kinds(",".join(disturb or ()))
        return cls(p=float(p), kinds=kinds, protocol=protocol, window=window)

    @property
    def disturbed(self) -> bool:
        """Whether any episode is disturbed at all."""
        return self.protocol is not None or self.p > 0

    def to_dict(self) -> dict[str, Any]:
        """What an episode's trace and a run's JSON say of it."""
        return {"p": self.p, "kinds": list(self.kinds), "protocol": self.protocol}

    def describe(self) -> str:
        """One line for a banner: ``drop at p = 0.1 per action``, ``perturb, pull: 1-2 per trial (real protocol)``."""
        if self.protocol is not None:
            return f"{', '.join(self.kinds)}: 1-2 per trial ({self.protocol} protocol)"
        if self.p > 0:
            return f"{', '.join(self.kinds)} at p = {self.p:g} per action"
        return "none"


#: No disturbance at all.
UNDISTURBED = DisturbanceSetting()


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
