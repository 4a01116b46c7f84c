"""The atomic action library (paper Table IV): the name -> program table and ``make_action``.

The programs live by concept in ``actions.grasp``, ``actions.place``, ``actions.move`` and
``actions.gripper``; they are re-exported here for existing importers.
Actions perceive through the feature frame (``robot.frame``), never through
simulator internals, so the same scripts run on oracle or RGB-D features.
Every script starts from the robot's current commanded state: that is what
lets a recovery edge begin wherever the failure left the arm.
"""

from __future__ import annotations

from agentchord.actions import catalog
from agentchord.actions.base import ArmAction
from agentchord.actions.grasp import (
    EMPTY_HAND_JOINT_SPEED,
    MOVED_DURING_APPROACH,
    OFF_CENTRE_TOLERANCE,
    UPRIGHT_TOLERANCE_DEG,
    Grasp,
    GraspMissed,
)
from agentchord.actions.gripper import CloseGripper, OpenGripper
from agentchord.actions.insert import Insert
from agentchord.actions.move import Back, MoveByOffset, MoveToObj, MoveToTarget, RotateEef
from agentchord.actions.place import (
    LEVEL_CLEARANCE,
    LEVEL_IN_HAND_DEG,
    RELEASE_MARGIN,
    RIM_CLEARANCE,
    Place,
)

__all__ = [
    "EMPTY_HAND_JOINT_SPEED",
    "LEVEL_CLEARANCE",
    "LEVEL_IN_HAND_DEG",
    "MOVED_DURING_APPROACH",
    "OFF_CENTRE_TOLERANCE",
    "PROGRAMS",
    "RELEASE_MARGIN",
    "RIM_CLEARANCE",
    "UPRIGHT_TOLERANCE_DEG",
    "Back",
    "CloseGripper",
    "Grasp",
    "GraspMissed",
    "Insert",
    "MoveByOffset",
    "MoveToObj",
    "MoveToTarget",
    "OpenGripper",
    "Place",
    "RotateEef",
    "make_action",
]


PROGRAMS: dict[str, type[ArmAction]] = {
    cls.name: cls for cls in (Grasp, MoveToObj, MoveToTarget, MoveByOffset, RotateEef, Place, Back, OpenGripper, CloseGripper, Insert)
}


def make_action(fn: str, arm: str, args: dict) -> ArmAction:
    """Instantiate an atomic action from a graph's action call.

    Raises:
        KeyError: Unknown action (graph validation reports this earlier).
        pydantic.ValidationError: Arguments that do not fit the catalogue.
    """
    spec = catalog.ACTIONS[fn]
    return PROGRAMS[fn](arm, spec.args.model_validate(args))
