"""The first observation the agents reason over: objects, arms and named regions, in plain numbers."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from agentchord.features.frame import UP, FeatureFrame
from agentchord.solvers.reach import BASE, SIDE_REACH, TOP_REACH, table_distance

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


class SceneObject(_Model):
    """One object of the scene as the reasoner sees it (world frame, metres).

    Attributes:
        name: The name graphs use for it (``bottle``).
        description: Category, colour, material, in words (optional).
        pos: Centre.
        quat: Orientation (w, x, y, z).
        axis: Unit principal axis (bottom to top for an upright object).
        extent: Full size along the object's principal axes.
        reachable_by: The arms that can grasp it where it lies (:func:`arms_reaching`); ``None``
            when not computed.
    """

    name: str
    description: str = ""
    pos: Vec3
    quat: Vec4 = (1.0, 0.0, 0.0, 0.0)
    axis: Vec3 = (0.0, 0.0, 1.0)
    extent: Vec3
    reachable_by: list[str] | None = None


class ArmState(_Model):
    """The measurable state of one arm at the first observation.

    Attributes:
        name: ``left`` or ``right``.
        ee: Tool centre point.
        width: Gripper opening (m).
        closed: Whether the gripper is commanded closed.
        holding: Name of the object in the gripper, if any.
        home: Whether the arm is at its home pose (false in an observation taken mid-task
            with the arm elsewhere: a plan that ends at home sends it back).
        base: Where the arm's base stands on the table plane (x, y).
        reach_top: How far (m, horizontally from ``base``) the arm reaches a point on the table
            from above: a top grasp, or setting an object down.
        reach_side: How far it reaches with a side grasp of a tall object (tool level).
    """

    name: str
    ee: Vec3
    width: float = 0.0
    closed: bool = False
    holding: str | None = None
    home: bool = True
    base: tuple[float, float] | None = None
    reach_top: float | None = None
    reach_side: float | None = None


class Region(_Model):
    """A named region of the table (a target area), a disc.

    Attributes:
        name: How instructions name it (``target``, ``forward``).
        description: More words that name it.
        center: Centre (x, y), metres.
        radius: Radius, metres.
    """

    name: str
    description: str = ""
    center: tuple[float, float]
    radius: float = Field(0.04, gt=0.0)


class Scene(_Model):
    """The first observation given to the agents: objects with poses and sizes, and the arms.

    Attributes:
        objects: Scene objects.
        arms: Arm states (may be empty when unknown).
        regions: Named regions of the table.
        notes: Anything else worth saying (table height, workspace bounds, in words).
    """

    objects: list[SceneObject]
    arms: list[ArmState] = Field(default_factory=list)
    regions: list[Region] = Field(default_factory=list)
    notes: str = ""

    @property
    def object_names(self) -> list[str]:
        """Names of the scene's objects, in order."""
        return [obj.name for obj in self.objects]

    @classmethod
    def from_frame(
        cls,
        frame: FeatureFrame,
        descriptions: Mapping[str, str] | None = None,
        notes: str = "",
        decimals: int = 4,
        regions: Iterable[Region] = (),
    ) -> Scene:
        """The scene seen in a feature frame (oracle or RGB-D), rounded for a prompt.

        Args:
            frame: The first frame of the episode.
            descriptions: Optional words per object name.
            notes: Free text passed on to the agents.
            regions: Named regions of the table.
            decimals: Rounding of every coordinate (4: 0.1 mm).
        """

        def r(values: Iterable[float]) -> Any:
            return tuple(round(float(v), decimals) for v in values)

        descriptions = descriptions or {}
        objects = [
            SceneObject(
                name=name,
                description=descriptions.get(name, ""),
                pos=r(feats.pos),
                quat=r(feats.quat),
                axis=r(feats.axis if feats.axis is not None else UP),
                extent=r(feats.extent),
                reachable_by=arms_reaching(feats.pos, feats.extent, [a for a in frame.arms if a in BASE]),
            )
            for name, feats in frame.objects.items()
        ]
        arms = []
        for name, arm in frame.arms.items():
            held = [obj for (a, obj) in sorted(frame.holding) if a == name]
            known = name in BASE  # a robot of our own: its measured reach
            arms.append(
                ArmState(
                    name=name,
                    ee=r(arm.ee),
                    width=round(float(arm.width), decimals),
                    closed=bool(arm.closed),
                    holding=held[0] if held else None,
                    base=BASE[name] if known else None,
                    reach_top=TOP_REACH if known else None,
                    reach_side=SIDE_REACH if known else None,
                )
            )
        return cls(objects=objects, arms=arms, regions=list(regions), notes=notes)


#: An object at least this tall (m) is taken with a side grasp, which reaches farther than a top one.
SIDE_GRASP_HEIGHT = 0.08


def grasp_reach(extent: Iterable[float]) -> float:
    """How far (m, from an arm's base) an arm reaches to grasp an object of this size on the table."""
    return SIDE_REACH if max(list(extent)[2:3] or [0.0]) >= SIDE_GRASP_HEIGHT else TOP_REACH


def arms_reaching(pos: Iterable[float], extent: Iterable[float], arms: Iterable[str] = tuple(BASE)) -> list[str]:
    """The arms that can grasp an object of ``extent`` lying at ``pos`` (its centre), by the measured reach."""
    x, y = list(pos)[:2]
    limit = grasp_reach(extent)
    return [arm for arm in arms if table_distance(arm, (x, y)) <= limit]
