"""The atomic action library (paper Table IV) as interruptible arm programs.

Actions perceive through the feature frame (``robot.frame``), never through
simulator internals, so the same scripts run on oracle or RGB-D features.
Every script starts from the robot's current commanded state: that is what
lets a recovery edge begin wherever the failure left the arm.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions import catalog
from agentchord.actions.base import ActionFailed, ArmAction
from agentchord.actions.controller import RobotController
from agentchord.actions.motion import grasp_frame, grip, move_joints, move_to, pose_from_matrix, settle
from agentchord.worlds.sim.scene import HOME_Q

#: Tilt (deg) beyond which an object counts as fallen for a side grasp.
UPRIGHT_TOLERANCE_DEG = 25.0


def _tilt_deg(axis: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(axis[2], -1.0, 1.0))))


class Grasp(ArmAction):
    """Side grasp of an upright object wherever it stands, then lift it."""

    name = "grasp"
    args: catalog.GraspArgs

    def _grasp_point(self, robot: RobotController) -> tuple[np.ndarray, float]:
        feats = robot.frame.objects[self.args.obj]
        if _tilt_deg(feats.axis) > UPRIGHT_TOLERANCE_DEG:
            raise ActionFailed(f"{self.args.obj} is not upright (tilt {_tilt_deg(feats.axis):.0f} deg)")
        height = float(np.linalg.norm(feats.top - feats.bottom))
        point = feats.bottom + self.args.height * height * feats.axis
        return point, float(feats.extent[0])

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        robot.set_grip(arm, 0.0)
        point, _ = self._grasp_point(robot)
        approach = point - robot.world.arm_base(arm)
        rotation = grasp_frame(approach)
        x_axis = rotation[:, 0]
        pre = point - self.args.pre_grasp_dis * x_axis
        start = robot.commanded_pose(arm).pos
        if start[2] < pre[2] + 0.03 and np.linalg.norm(start[:2] - pre[:2]) > 0.05:
            # Coming from low (a recovery after a drop): rise first so the fingers clear the object.
            yield from move_to(robot, arm, pose_from_matrix(np.r_[start[:2], pre[2] + 0.08], robot.rotation(arm)))
        yield from move_to(robot, arm, pose_from_matrix(pre, rotation))
        # Re-observe: the object may have moved while the arm approached.
        point, _ = self._grasp_point(robot)
        yield from move_to(robot, arm, pose_from_matrix(point, rotation), speed=0.15)
        yield from settle(robot, arm)
        yield from grip(robot, arm, 1.0)
        if not robot.frame.is_holding(arm, self.args.obj):
            raise ActionFailed(f"fingers closed but {self.args.obj} is not held")
        lift = robot.commanded_pose(arm).pos + np.array([0.0, 0.0, self.args.lift])
        yield from move_to(robot, arm, pose_from_matrix(lift, rotation), speed=0.15)


class MoveToObj(ArmAction):
    """Move the tool (and what it holds) to an offset from an object's top point, upright."""

    name = "move_to_obj"
    args: catalog.MoveToObjArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        rotation = grasp_frame(robot.rotation(arm)[:, 0])
        target = robot.frame.objects[self.args.obj].top + np.asarray(self.args.offset)
        yield from move_to(robot, arm, pose_from_matrix(target, rotation))
        # Re-aim at the object's latest position (it may have been moved).
        target = robot.frame.objects[self.args.obj].top + np.asarray(self.args.offset)
        yield from move_to(robot, arm, pose_from_matrix(target, rotation), speed=0.15)
        yield from settle(robot, arm)


class RotateEef(ArmAction):
    """Roll the tool about its approach axis: tilt-to-pour and back to upright."""

    name = "rotate_eef"
    args: catalog.RotateEefArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        pose = robot.commanded_pose(arm)
        goal = robot.rotation(arm) @ Rotation.from_euler("x", self.args.angle, degrees=True).as_matrix()
        yield from move_to(robot, arm, pose_from_matrix(pose.pos, goal))
        yield from settle(robot, arm, max_ticks=10)


class Place(ArmAction):
    """Lower the held object onto the table, release it, retreat."""

    name = "place"
    args: catalog.PlaceArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        obj = robot.frame.objects[self.args.obj]
        tool = robot.commanded_pose(arm)
        rotation = grasp_frame(robot.rotation(arm)[:, 0])
        above = tool.pos.copy()
        if self.args.target is not None:
            # Put the object's centre, not the tool, over the target.
            above[:2] += np.asarray(self.args.target) - obj.pos[:2]
        above[2] = max(above[2], tool.pos[2])
        yield from move_to(robot, arm, pose_from_matrix(above, rotation))
        obj = robot.frame.objects[self.args.obj]
        drop = obj.bottom[2] - (self.args.z_offset + 0.004)
        down = robot.commanded_pose(arm).pos - np.array([0.0, 0.0, drop])
        yield from move_to(robot, arm, pose_from_matrix(down, rotation), speed=0.12)
        yield from settle(robot, arm, max_ticks=10)
        yield from grip(robot, arm, 0.0, ticks=8)
        retreat = down - 0.08 * rotation[:, 0] + np.array([0.0, 0.0, 0.04])
        yield from move_to(robot, arm, pose_from_matrix(retreat, rotation))


class Back(ArmAction):
    """Return the arm to its home configuration (joint space)."""

    name = "back"

    def script(self, robot: RobotController) -> Iterator[None]:
        yield from move_joints(robot, self.arm, HOME_Q)
        robot.set_pose(self.arm, robot.ik.tcp_pose(self.arm))


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


PROGRAMS: dict[str, type[ArmAction]] = {
    cls.name: cls for cls in (Grasp, MoveToObj, RotateEef, Place, Back, OpenGripper, CloseGripper)
}


def make_action(fn: str, arm: str, args: dict) -> ArmAction:
    """Instantiate an atomic action from a graph's action call.

    Raises:
        KeyError: Unknown action (graph validation reports this earlier).
        pydantic.ValidationError: Arguments that do not fit the catalogue.
    """
    spec = catalog.ACTIONS[fn]
    return PROGRAMS[fn](arm, spec.args.model_validate(args))
