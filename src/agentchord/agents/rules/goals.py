"""Goal specifications: what the offline composer plans for, as predicates over the scene.

A :class:`GoalSpec` is an ordered list of predicates (poured-into, placed, inside, on,
handed-over, folded) plus whether the arms end at home. The order is the order the
instruction states them in: the planner achieves them one after the other, keeping
what it achieved. Goal specs are written by hand (``--goal goal.yaml``) or grounded
from an instruction (:mod:`agentchord.agents.rules.instructions`).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

Arm = Literal["left", "right"]


class _Goal(BaseModel):
    model_config = ConfigDict(extra="forbid")

    def objects(self) -> list[str]:
        """Scene objects the predicate names."""
        raise NotImplementedError


class Poured(_Goal):
    """``source``'s contents poured into ``target``.

    Attributes:
        source: The object poured from (a bottle, jug).
        target: The container poured into (a cup, glass).
        arm: The arm that pours; ``None`` lets the planner choose.
        hold_target: The other arm holds the target steady while pouring.
    """

    kind: Literal["poured"] = "poured"
    source: str
    target: str
    arm: Arm | None = None
    hold_target: bool = False

    def objects(self) -> list[str]:
        return [self.source, self.target]


class Placed(_Goal):
    """``obj`` stands on the table, released, at a place.

    Exactly one way of saying where, or none: ``region`` (a named region of the scene),
    ``at`` (absolute x, y), ``relative_to`` + ``offset`` (beside another object), or none
    of them: put it down where it was taken from (a free spot if that is taken).

    Attributes:
        obj: The object.
        region: Name of a scene region.
        at: Absolute table position (m).
        relative_to: Anchor object for ``offset``.
        offset: (dx, dy) from the anchor's centre (m).
        yaw: World yaw of the object's long axis once placed (deg); ``None``: any.
        arm: The arm that places it; ``None`` lets the planner choose.
    """

    kind: Literal["placed"] = "placed"
    obj: str
    region: str | None = None
    at: tuple[float, float] | None = None
    relative_to: str | None = None
    offset: tuple[float, float] = (0.0, 0.0)
    yaw: float | None = None
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj] + ([self.relative_to] if self.relative_to else [])


class Inside(_Goal):
    """``obj`` released inside ``container`` (a capsule in a tray, a block in a cup)."""

    kind: Literal["inside"] = "inside"
    obj: str
    container: str
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj, self.container]


class On(_Goal):
    """``obj`` released on top of ``support`` (a stack)."""

    kind: Literal["on_top_of"] = "on_top_of"  # not "on": YAML reads a bare on as true
    obj: str
    support: str
    arm: Arm | None = None

    def objects(self) -> list[str]:
        return [self.obj, self.support]


class HandedOver(_Goal):
    """``obj`` passed from ``giver`` to ``receiver`` (the receiver closes before the giver opens)."""

    kind: Literal["handed_over"] = "handed_over"
    obj: str
    giver: Arm = "left"
    receiver: Arm = "right"

    def objects(self) -> list[str]:
        return [self.obj]


class Folded(_Goal):
    """A cloth folded in half: its near corners laid on its far corners.

    The cloth is seen through its corner points, named ``{cloth}_bl``, ``_br``,
    ``_tl`` and ``_tr`` (bottom = near the robot's front edge, top = far).
    """

    kind: Literal["folded"] = "folded"
    cloth: str

    def objects(self) -> list[str]:
        return [f"{self.cloth}_{c}" for c in ("bl", "br", "tl", "tr")]


Goal = Annotated[Poured | Placed | Inside | On | HandedOver | Folded, Field(discriminator="kind")]


class GoalSpec(BaseModel):
    """An ordered list of goal predicates.

    Attributes:
        goals: Predicates achieved in this order, each kept once achieved.
        home: Both arms end at home.
    """

    model_config = ConfigDict(extra="forbid")

    goals: list[Goal] = Field(min_length=1)
    home: bool = True

    def objects(self) -> list[str]:
        """Every object the goals name, first mention first."""
        names: list[str] = []
        for goal in self.goals:
            names += [n for n in goal.objects() if n not in names]
        return names
