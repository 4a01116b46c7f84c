"""The atomic action catalogue: names, argument schemas and expected cost.

This module is pure data (no simulator import) so that graph validation, the
agents and the forward-moving filter can reason about actions without a world:
it is the graph's vocabulary of actions. The tick-level programs that realise
these actions live in :mod:`agentchord.actions` (which re-exports this module as
``agentchord.actions.catalog``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

Vec3 = tuple[float, float, float]


class _Args(BaseModel):
    model_config = ConfigDict(extra="forbid")


class GraspArgs(_Args):
    """Approach ``obj``, close on it, lift it clear of the table (a fallen object is set upright)."""

    obj: str
    pre_grasp_dis: float = Field(0.08, ge=0.0, le=0.3, description="Stand-off before the final approach (m).")
    height: float = Field(0.5, ge=0.1, le=0.9, description="Side grasp: height as a fraction of the object's height.")
    lift: float = Field(
        0.06, ge=0.0, le=0.3,
        description="Lift after closing (m); a top grasp lifts at least 4 cm, unless 0 (stay on the table: a two-arm grasp lifts afterwards).",
    )
    mode: Literal["auto", "side", "top"] = Field(
        "auto", description="side: horizontal approach; top: from above; auto: side for tall upright objects, else top."
    )
    offset: Vec3 = Field((0.0, 0.0, 0.0), description="Grasp offset from the grasp point, in offset_frame (m).")
    offset_frame: Literal["world", "object"] = Field(
        "world", description="Frame of offset: world axes, or the object's own axes (a handle of a tray that may have turned)."
    )
    yaw: float | None = Field(None, ge=-180.0, le=180.0, description="Side grasp: world yaw of the approach (deg); None = from the arm's base.")
    skip_if_held: bool = Field(
        False, description="If the arm already holds obj with a closed grip, do nothing (finish an interrupted synchronous grasp)."
    )
    skip_if_placed: bool = Field(
        False,
        description="If obj is not held and already lies where the edge's next place of it (same arm) puts it, only open the "
        "hand: a drop that finished the place (that place, with skip_if_placed, then only retreats).",
    )
    reseat: bool = Field(
        False,
        description="A fallen object that the turn upright in hand left more than 5 deg askew is put down upright, the arm "
        "goes home and grasps it again from the side: the nominal grasp geometry (a pour needs it) instead of the "
        "off-centre fallen-grasp hold. One left within 5 deg keeps the fallen-grasp hold.",
    )


class MoveToObjArgs(_Args):
    """Move the held object (or the tool) to an offset from ``obj``'s top point."""

    obj: str
    offset: Vec3 = (0.0, 0.0, 0.1)
    keep_orientation: bool = Field(False, description="Keep the tool's orientation (else: level side-grasp frame).")
    path: Literal["direct", "solved"] = Field(
        "direct", description="direct: a straight line; solved: the receding-horizon path solver, clear of other objects."
    )
    yaw: float | None = Field(
        None, ge=-180.0, le=180.0,
        description="Orientation hint: world yaw (deg) of the tool's horizontal approach axis; None keeps the current one.",
    )


class RotateEefArgs(_Args):
    """Roll the tool about its approach axis (tilt-to-pour and back)."""

    angle: float = Field(..., ge=-180.0, le=180.0, description="Degrees; positive tips the object's top toward -y of the tool.")


class PlaceArgs(_Args):
    """Lower the held object onto the table at ``target`` (x, y), then release and retreat."""

    obj: str
    target: tuple[float, float] | None = Field(None, description="Table position (m); None = straight down.")
    relative_to: str | None = Field(None, description="Take target as an (x, y) offset from this object's centre; None = absolute.")
    z_offset: float = Field(0.0, ge=-0.05, le=0.2)
    yaw: float | None = Field(
        None, ge=-180.0, le=180.0,
        description="World yaw (deg) of the object's long horizontal axis once placed (either direction); None keeps the current orientation.",
    )
    skip_if_placed: bool = Field(
        False,
        description="If obj is not held but already stands upright on the table, or lies released at target (within 3 cm, "
        "at yaw), only open and retreat (finish an interrupted synchronous place, or one a drop finished).",
    )
    free_hand: bool = Field(
        False,
        description="The place only empties the hand: if obj is no longer held (it fell), open and retreat instead of failing.",
    )
    within_reach: Literal["left", "right"] | None = Field(
        None,
        description="Set obj down at the nearest free spot this (other) arm reaches, chosen when the action runs: "
        "a hand-off in an arm-switching recovery; target and relative_to are then ignored.",
    )


class MoveToTargetArgs(_Args):
    """Move the tool to an absolute position (extrinsic frame)."""

    pos: Vec3
    yaw: float | None = Field(None, ge=-180.0, le=180.0, description="World yaw of a level tool's approach (deg); None keeps the orientation.")
    path: Literal["direct", "solved"] = Field(
        "direct", description="direct: a straight line; solved: the receding-horizon path solver, clear of other objects."
    )


class MoveByOffsetArgs(_Args):
    """Displace the tool by a translation and rotation, in the world or the tool frame."""

    offset: Vec3 = (0.0, 0.0, 0.0)
    angles: Vec3 = Field((0.0, 0.0, 0.0), description="Roll, pitch, yaw (deg) about the frame's x, y, z.")
    frame: Literal["extrinsic", "intrinsic"] = "extrinsic"


class InsertArgs(_Args):
    """Insert the held ``obj`` into ``into``'s opening along ``into``'s long axis: aligned first, ``standoff`` before the opening, then pushed in."""

    obj: str
    into: str
    depth: float = Field(0.03, ge=0.0, le=0.15, description="How far (m) past the opening the held object's tip goes.")
    standoff: float = Field(0.03, ge=0.005, le=0.15, description="Gap (m) before the opening where the tip is aligned first.")


class NoArgs(_Args):
    """No arguments."""


@dataclass(frozen=True)
class ActionSpec:
    """What the catalogue knows about one atomic action.

    Attributes:
        name: The action's name in graph files.
        args: Pydantic model that validates the action's ``args``.
        expected_ticks: Nominal duration in control ticks (50 Hz); the edge
            weight of the forward-moving principle (Eq. 8).
        object_fields: Argument names that must name a scene object.
        holds_object: Whether the arm holds an object while the action runs.
    """

    name: str
    args: type[BaseModel]
    expected_ticks: int
    object_fields: tuple[str, ...] = ()
    holds_object: bool = False


ACTIONS: dict[str, ActionSpec] = {
    spec.name: spec
    for spec in (
        ActionSpec("grasp", GraspArgs, 190, ("obj",)),
        ActionSpec("move_to_obj", MoveToObjArgs, 110, ("obj",), holds_object=True),
        ActionSpec("rotate_eef", RotateEefArgs, 80, holds_object=True),
        ActionSpec("place", PlaceArgs, 170, ("obj", "relative_to"), holds_object=True),
        ActionSpec("move_to_target", MoveToTargetArgs, 110),
        ActionSpec("move_by_offset", MoveByOffsetArgs, 60),
        ActionSpec("insert", InsertArgs, 120, ("obj", "into"), holds_object=True),
        ActionSpec("back", NoArgs, 100),
        ActionSpec("open_gripper", NoArgs, 25),
        ActionSpec("close_gripper", NoArgs, 25),
    )
}
