"""Open and close the gripper."""

from __future__ import annotations

from collections.abc import Iterator

from agentchord.actions.base import ArmAction
from agentchord.actions.controller import RobotController
from agentchord.actions.motion import grip


class OpenGripper(ArmAction):
    """Open the gripper."""

    name = "open_gripper"

    def script(self, robot: RobotController) -> Iterator[None]:
        yield from grip(robot, self.arm, 0.0)


class CloseGripper(ArmAction):
    """Close the gripper."""

    name = "close_gripper"

    def script(self, robot: RobotController) -> Iterator[None]:
        yield from grip(robot, self.arm, 1.0)
