"""Tool moves: to an object, to a target, by an offset, a roll about the approach, back home."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions import catalog
from agentchord.actions.base import ArmAction
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.geometry import level_frame, quat_matrix
from agentchord.actions.grasping.in_hand import axis_offset_in_tool, side_held_object
from agentchord.actions.grasping.finger_clearance import swept_hits
from agentchord.actions.joint_path import joint_path
from agentchord.actions.motion import (
    EMPTY_HAND_JOINT_SPEED,
    clip_to_workspace,
    grasp_frame,
    line_poses,
    move_along_solved_path,
    move_joints,
    move_to,
    pose_from_matrix,
    settle,
    wait_for_rest,
)
from agentchord.robot.aloha import HOME_Q
from agentchord.solvers.ik import PoseTarget, solve_from_scratch
from agentchord.solvers.obstacles import held_spheres, lift_over, scene_spheres
from agentchord.solvers.poses import quat_to_rotation


def _avoid(robot: RobotController, arm: str, exclude: tuple[str, ...]):
    """Obstacles (every object not held and not excluded) and what ``arm`` carries, from the latest frame."""
    frame = robot.frame
    return scene_spheres(frame, exclude=exclude), held_spheres(frame, arm)


class MoveToObj(ArmAction):
    """Move the tool (and what it holds) to an offset from an object's top point, upright."""

    name = "move_to_obj"
    args: catalog.MoveToObjArgs
    #: A side grasp made as planned holds the object's axis within this (m) of the tool centre;
    #: only a hold further off is corrected for (fallen grasps: 2-3 cm).
    CENTRED_WITHIN = 0.01

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        # A pushed target may still be sliding: aim at where it stops.
        yield from wait_for_rest(robot, self.args.obj)
        if self.args.keep_orientation:
            rotation = robot.rotation(arm)
        elif self.args.yaw is None:
            rotation = level_frame(robot.rotation(arm))
        else:
            yaw = np.radians(self.args.yaw)
            rotation = grasp_frame(np.array([np.cos(yaw), np.sin(yaw), 0.0]))
        off_centre = self._carried_off_centre(robot)
        target = robot.frame.objects[self.args.obj].top + np.asarray(self.args.offset) - rotation @ off_centre
        if self.args.path == "solved":
            # The object aimed at is the goal, not an obstacle.
            yield from move_along_solved_path(robot, arm, pose_from_matrix(target, rotation), lambda: _avoid(robot, arm, (self.args.obj,)))
        else:
            # Straight, unless what the arm carries would be driven through another object on the way.
            obstacles, carried = _avoid(robot, arm, ())
            for waypoint in lift_over(robot.commanded_pose(arm).pos, target, obstacles, carried):
                yield from move_to(robot, arm, pose_from_matrix(waypoint, rotation))
        # Re-aim at the object's latest position (it may have been moved).
        target = robot.frame.objects[self.args.obj].top + np.asarray(self.args.offset) - rotation @ off_centre
        yield from move_to(robot, arm, pose_from_matrix(target, rotation), speed=0.15)
        yield from settle(robot, arm)

    def _carried_off_centre(self, robot: RobotController) -> np.ndarray:
        """The side-held object's axis offset from the tool centre (tool frame), or zero within the dead band.

        The offset is meant for the held object as a centred grasp carries it: an object held off
        centre (a fallen grasp leaves a bottle's axis 2-3 cm out along the approach, and a pour then
        misses the cup by as much) is carried so that its axis lands where a centred one's would.
        """
        frame = robot.frame
        measured = quat_matrix(frame.arms[self.arm].ee_quat)
        held = side_held_object(frame, self.arm, measured)
        if held is None:
            return np.zeros(3)
        offset = axis_offset_in_tool(frame, self.arm, held, measured)
        return offset if float(np.linalg.norm(offset)) > self.CENTRED_WITHIN else np.zeros(3)


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


class MoveToTarget(ArmAction):
    """Move the tool to an absolute position (extrinsic frame), clipped to the workspace."""

    name = "move_to_target"
    args: catalog.MoveToTargetArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        if self.args.yaw is None:
            rotation = robot.rotation(self.arm)
        else:
            yaw = np.radians(self.args.yaw)
            rotation = grasp_frame(np.array([np.cos(yaw), np.sin(yaw), 0.0]))
        goal = pose_from_matrix(np.asarray(self.args.pos, dtype=float), rotation)
        if self.args.path == "solved":
            yield from move_along_solved_path(robot, self.arm, goal, lambda: _avoid(robot, self.arm, ()))
        else:
            yield from move_to(robot, self.arm, goal)
        yield from settle(robot, self.arm)


class MoveByOffset(ArmAction):
    """Displace the tool: a translation and roll/pitch/yaw in the world (extrinsic) or tool (intrinsic) frame."""

    name = "move_by_offset"
    args: catalog.MoveByOffsetArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        pose = robot.commanded_pose(self.arm)
        rotation = robot.rotation(self.arm)
        turn = Rotation.from_euler("xyz", self.args.angles, degrees=True).as_matrix()
        offset = np.asarray(self.args.offset, dtype=float)
        if self.args.frame == "intrinsic":
            goal_pos, goal_rot = pose.pos + rotation @ offset, rotation @ turn
        else:
            goal_pos, goal_rot = pose.pos + offset, turn @ rotation
        yield from move_to(robot, self.arm, pose_from_matrix(goal_pos, goal_rot))
        yield from settle(robot, self.arm, max_ticks=10)


#: Finger gap (m) an empty hand opens to before it goes home, and the most ticks it waits for it.
BACK_OPEN_WIDTH = 0.055
BACK_OPEN_MAX_TICKS = 20
#: Rises (m), lowest first, tried before going home where the joint-space move from where the
#: hand is would sweep the open fingers through an object.
BACK_RISES = (0.05, 0.10, 0.15, 0.20)


class Back(ArmAction):
    """Return the arm to its home configuration (joint space).

    An empty hand goes at the empty-hand joint speed, its fingers opened first, and straight up
    first where the joint-space move would sweep them through an object (a bottle or block just
    set down beside it); a hand that holds something goes at the usual speed.
    """

    name = "back"

    def script(self, robot: RobotController) -> Iterator[None]:
        if any(arm == self.arm for arm, _ in robot.frame.holding):
            yield from move_joints(robot, self.arm, HOME_Q)
        else:
            yield from self._open_before_leaving(robot)
            rise = self._clear_rise(robot)
            if rise is not None:
                yield from move_to(robot, self.arm, rise)
            yield from move_joints(robot, self.arm, HOME_Q, speed=EMPTY_HAND_JOINT_SPEED)
        robot.set_pose(self.arm, robot.ik.tcp_pose(self.arm))

    def _clear_rise(self, robot: RobotController) -> PoseTarget | None:
        """The lowest pose straight above the tool from which the way home sweeps no finger through
        an object; None where the way home from here is clear, or no rise makes it so.

        Measured before this check, under disturbances of every kind: the way home from a side
        place's retreat passed the fingers through the bottle or block just set down in 9 of 30
        episodes of the pours and the handover (none of 30 of the other three tasks); at the
        empty-hand speed that knocked a handed-over block off its spot and left it rocking.
        """
        frame = robot.frame
        if not swept_hits(frame, None, list(joint_path(robot, self.arm, HOME_Q).tool_poses)):
            return None
        start = robot.commanded_pose(self.arm)
        rotation = quat_to_rotation(start.quat).as_matrix()
        # Fingers that already straddle an object (it leans on them) leave it going up.
        straddled = swept_hits(frame, None, [(start.pos, rotation)])
        for height in BACK_RISES:
            pose = PoseTarget(pos=clip_to_workspace(start.pos + np.array([0.0, 0.0, height])), quat=start.quat)
            rising = swept_hits(frame, None, [(p.pos, rotation) for p in line_poses(start, pose, np.linspace(0.0, 1.0, 6))])
            if set(rising) - set(straddled):
                return None  # something over the hand: going up is no better
            q = solve_from_scratch(robot.scratch_ik(), robot.ik.configuration.q.copy(), self.arm, [pose], from_home=False)
            if q is not None and not swept_hits(frame, None, list(joint_path(robot, self.arm, HOME_Q, q_start=q).tool_poses)):
                return pose
        return None

    def _open_before_leaving(self, robot: RobotController) -> Iterator[None]:
        # A hand closed on nothing (an object slipped out just as its place ended) would drag
        # whatever still lies in its fingers (a towel corner) along: it has nothing to keep. The
        # fingers open before the arm sets off at the empty-hand speed.
        robot.set_grip(self.arm, 0.0)
        for _ in range(BACK_OPEN_MAX_TICKS):
            if robot.world.gripper_width(self.arm) >= BACK_OPEN_WIDTH:
                return
            yield
