"""The release's format as the import reads it: arm calls with their JSON paths, steps,
recovery bindings, each arm's history, and what the arms hold along a chain of steps."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from agentchord.graph.models import ActionCall


def fmt(x: float) -> str:
    return f"{x:g}"




def slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_") or "imported_task"


def norm(text: str) -> str:
    return re.sub(r"[^a-z0-9]", "", text.lower())




@dataclass
class RawCall:
    """A release arm call (``{fn, kwargs}``), where it is, and recovery-step extras."""

    call: dict[str, Any]
    file: str
    path: str
    extra: dict[str, Any] = field(default_factory=dict)


#: One step: our arm -> release call (None: idle).
RawStep = dict[str, "RawCall | None"]


@dataclass
class Track:
    """Each arm's history along a translation.

    Attributes:
        before: The arm's last release call.
        previous: Our last action on the arm.
        turned: Arms whose tool turned (a roll, a pitch) since they last grasped.
    """

    before: dict[str, RawCall] = field(default_factory=dict)
    previous: dict[str, str] = field(default_factory=dict)
    turned: set[str] = field(default_factory=set)

    def update(self, arm: str, call: ActionCall) -> None:
        self.previous[arm] = call.fn
        if call.fn == "grasp":
            self.turned.discard(arm)
        elif call.fn == "rotate_eef" or any(call.args.get("angles", ())):
            self.turned.add(arm)

    def copy(self) -> Track:
        return Track(dict(self.before), dict(self.previous), set(self.turned))


@dataclass
class CallContext:
    """What one release call is translated in view of.

    Attributes:
        arm: The call's arm.
        nxt: The arm's next release call (later in the steps, then in the continuation).
        before: The arm's previous release call.
        previous: Our previous action on the arm.
        holds: What each arm holds.
        turned: Whether the arm's tool turned since it last grasped.
    """

    arm: str
    nxt: RawCall | None
    before: RawCall | None
    previous: str | None
    holds: dict[str, str]
    turned: bool


@dataclass
class Binding:
    index: int
    edge_id: str
    name: str
    monitors: list[tuple[str, dict[str, Any]]]
    steps: list[RawStep]
    merge: str
    repeat: bool
    intent: str




def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def fmt_vec(v: Sequence[float]) -> str:
    return "(" + ", ".join(fmt(x) for x in v) + ")"


def kwargs_of(raw: RawCall | None) -> dict:
    """A release call's kwargs; empty where the call or its kwargs is not an object (the call's own
    translation reports that)."""
    if raw is None or not isinstance(raw.call, dict):
        return {}
    kwargs = raw.call.get("kwargs")
    return kwargs if isinstance(kwargs, dict) else {}


def roll_of(raw: RawCall | None) -> float:
    """The roll (deg) of a release ``rotate_eef`` call, 0 for anything else."""
    if raw is None or not isinstance(raw.call, dict) or raw.call.get("fn") != "rotate_eef":
        return 0.0
    degree = kwargs_of(raw).get("degree", 0)
    return float(degree) if is_number(degree) else 0.0


def fn_of(raw: RawCall | None) -> str | None:
    """The release action name of a call, None for none."""
    return raw.call.get("fn") if raw is not None and isinstance(raw.call, dict) else None


def holds_after(holds: dict[str, str], steps: list[dict[str, ActionCall | None]]) -> dict[str, str]:
    """What each arm holds after ``steps``: a grasp takes its object, a place or opening lets go."""
    holds = dict(holds)
    for step in steps:
        for arm, call in step.items():
            if call is None:
                continue
            if call.fn == "grasp":
                holds[arm] = call.args["obj"]
            elif call.fn in ("place", "open_gripper"):
                holds.pop(arm, None)
    return holds


def released_by(before: dict[str, str], steps: list[dict[str, ActionCall | None]]) -> list[tuple[str, str]]:
    """``(arm, obj)`` pairs that ``steps`` let go of on purpose."""
    holds, out = dict(before), []
    for step in steps:
        for arm, call in step.items():
            if call is None:
                continue
            if call.fn == "grasp":
                holds[arm] = call.args["obj"]
            elif call.fn in ("place", "open_gripper") and arm in holds:
                out.append((arm, holds.pop(arm)))
    return sorted(out)
