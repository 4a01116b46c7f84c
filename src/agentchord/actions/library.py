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
from agentchord.actions.motion import (
    approach,
    grasp_frame,
    grip,
    move_along_solved_path,
    move_joints,
    move_to,
    pose_from_matrix,
    settle,
    wait_for_rest,
)
from agentchord.features.frame import tilt_deg
from agentchord.solvers.exceptions import NoHandoffSpotError
from agentchord.solvers.handoff import handoff_spot
from agentchord.solvers.ik import PoseTarget, solve_from_scratch
from agentchord.solvers.obstacles import held_spheres, lift_over, scene_spheres
from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX, FINGER_GAP_OFFSET, FINGER_RANGE, HOME_Q

#: Joint speed (rad/s, largest joint) of joint-space moves with an empty hand.
EMPTY_HAND_JOINT_SPEED = 2.0
#: Tilt (deg) beyond which an object counts as fallen for a side grasp.
UPRIGHT_TOLERANCE_DEG = 25.0
#: An object that moved more than this (m) while the tool approached it is looked at again.
MOVED_DURING_APPROACH = 0.01
#: A closed grasp whose grasp point is farther than this (m) from where the tool aimed is off-centre.
OFF_CENTRE_TOLERANCE = 0.025


class GraspMissed(ActionFailed):
    """The fingers closed but the object is not between them."""


def _level(rotation: np.ndarray) -> np.ndarray:
    """The tool's level side-grasp frame for its current approach; a top-down tool is kept."""
    if abs(rotation[2, 0]) > 0.7:
        return rotation
    return grasp_frame(rotation[:, 0])


def _matrix(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = quat
    return Rotation.from_quat([x, y, z, w]).as_matrix()


def _long_axis(feats) -> np.ndarray:
    """An object's long horizontal direction: its axis if lying, else its longer horizontal side."""
    if tilt_deg(feats.axis) >= Grasp.FALLEN_DEG:
        return feats.axis
    rot = _matrix(feats.quat)
    return rot[:, 0] if feats.extent[0] >= feats.extent[1] else rot[:, 1]


def _yaw_turn(robot: RobotController, arm: str, direction: np.ndarray, yaw_deg: float, goal: np.ndarray) -> np.ndarray:
    """Rotation about world z that brings ``direction``'s yaw to ``yaw_deg``, either way round (mod 180).

    Of the two turns, the smaller one unless it would drive the wrist-rotate joint (whose axis
    is the tool's approach) past its range: a top grasp often leaves that joint at a limit.
    The waist's own turn toward ``goal`` (x, y) is accounted for.
    """
    current = np.degrees(np.arctan2(direction[1], direction[0]))
    delta = (yaw_deg - current + 90.0) % 180.0 - 90.0
    candidates = [delta] if abs(delta) < 1e-6 else [delta, delta - np.copysign(180.0, delta)]
    best = candidates[0]
    if _wrist_margin(robot, arm, best, goal) < 0.0:
        best = max(candidates, key=lambda turn: _wrist_margin(robot, arm, turn, goal))
    return Rotation.from_euler("z", best, degrees=True).as_matrix()


def _wrist_margin(robot: RobotController, arm: str, turn_deg: float, goal: np.ndarray) -> float:
    """Predicted distance (rad) of the wrist-rotate joint to its range after turning the tool
    ``turn_deg`` about world z while moving to ``goal`` (x, y); the waist's own turn is accounted for."""
    lo, hi = robot.ik.model.joint(f"{ARM_PREFIX[arm]}/wrist_rotate").range
    q = robot.ik.arm_q(arm)[ARM_JOINTS.index("wrist_rotate")]
    base = robot.world.arm_base(arm)[:2]
    here, there = robot.commanded_pose(arm).pos[:2] - base, np.asarray(goal)[:2] - base
    waist = np.degrees(np.arctan2(there[1], there[0]) - np.arctan2(here[1], here[0]))
    waist = (waist + 180.0) % 360.0 - 180.0
    # A turn about world z is a turn about the approach axis scaled by its vertical component.
    after = q + np.radians(turn_deg - waist) * robot.rotation(arm)[2, 0]
    return float(min(after - lo, hi - after))


class Grasp(ArmAction):
    """Grasp an object wherever it is, then lift it; a fallen object is set upright in hand.

    Side grasp (tall upright objects: bottles, cups): horizontal approach from
    the arm's base at ``height`` of the object. Top grasp (short or flat
    objects: blocks, capsules, cutlery): from above, fingers across the
    object's narrow horizontal side. A fallen tall object (lying on its side)
    is grasped from above across its middle, lifted, swung so its top points
    away from the robot and pitched up: the action ends, like the upright case,
    with the object held upright in a side grasp.
    """

    name = "grasp"
    args: catalog.GraspArgs

    #: Tilt (deg) beyond which the object is treated as lying on its side.
    FALLEN_DEG = 60.0
    #: Tilt (deg) beyond which an object leaning on something is grasped like a fallen one.
    LEANING_AS_FALLEN_DEG = 40.0
    #: Tries before a grasp that closes on nothing fails.
    ATTEMPTS = 3
    #: Objects shorter than this (m) are grasped from above in ``auto`` mode.
    SIDE_MIN_HEIGHT = 0.08
    #: The finger tips reach this far past the tool centre (m): keep them off the table.
    FINGERTIP_REACH = 0.039
    #: Side grasps tried in order where the asked one cannot be made: (share of the pre-grasp
    #: distance, rise of the pre-grasp pose in m, grasp height as a share of the object's or
    #: None for the asked one; a higher one is only ever taken).
    SIDE_VARIANTS = ((1.0, 0.0, None), (1.0, 0.03, None), (0.5, 0.0, None), (0.5, 0.03, None), (0.5, 0.03, 0.8))

    def script(self, robot: RobotController) -> Iterator[None]:
        held = robot.targets[self.arm].grip_closed_settled and robot.frame.is_holding(self.arm, self.args.obj)
        if self.args.skip_if_held and held:
            return  # already grasped (an interrupted synchronous grasp whose other half failed)
        for attempt in range(self.ATTEMPTS):
            try:
                yield from self._let_go(robot)
                yield from wait_for_rest(robot, self.args.obj)
                yield from self._attempt(robot)
                return
            except GraspMissed:
                # The object moved as the fingers closed (a nudge, a roll): look again and retry.
                if attempt == self.ATTEMPTS - 1:
                    raise

    def _mode(self, robot: RobotController) -> str:
        """How the object is taken now: ``top``, ``side`` (upright or leaning a little) or ``fallen`` (lying)."""
        feats = robot.frame.objects[self.args.obj]
        tilt = tilt_deg(feats.axis)
        height = float(np.linalg.norm(feats.top - feats.bottom))
        mode = self.args.mode
        if mode == "auto":
            mode = "side" if height >= self.SIDE_MIN_HEIGHT else "top"
        if mode == "top":
            return "top"
        # Leaning on something (pushed into another object): a little, the closing fingers stand it
        # up; far, it is taken as if it lay there.
        return "side" if tilt < self.LEANING_AS_FALLEN_DEG else "fallen"

    def target_poses(self, robot: RobotController) -> list[PoseTarget]:
        """The tool poses this grasp would go to from the current frame: above/before the object, then at it.

        Feasibility checks (reach, IK) use them before the arm moves.
        """
        mode = self._mode(robot)
        if mode == "top":
            rotation, point = self._top_frame(robot)
            pre = point + np.array([0.0, 0.0, self.args.pre_grasp_dis])
        elif mode == "fallen":
            rotation, point = self._fallen_frame(robot)
            pre = point + np.array([0.0, 0.0, self.args.pre_grasp_dis])
        else:
            pre, point, rotation = self._side_plan(robot)
        return [pose_from_matrix(pre, rotation), pose_from_matrix(point, rotation)]

    def _attempt(self, robot: RobotController) -> Iterator[None]:
        feats = robot.frame.objects[self.args.obj]
        self._seen_at = feats.pos.copy()
        self._taken_as = self._mode(robot)
        self._height_fraction: float | None = None
        self._upright_at_start = tilt_deg(feats.axis) <= UPRIGHT_TOLERANCE_DEG
        if feats.pos[2] < -0.02:
            raise ActionFailed(f"{self.args.obj} fell off the table")
        mode = self._mode(robot)
        if mode == "top":
            yield from self._top_grasp(robot)
        elif mode == "side":
            yield from self._side_grasp(robot)
        elif mode == "fallen":
            yield from self._fallen_grasp(robot)
            if self.args.reseat:
                yield from self._reseat(robot)

    def _reseat(self, robot: RobotController) -> Iterator[None]:
        """Put an object just set upright in hand down on the table, go home, side-grasp it again.

        The fallen grasp leaves the object off-centre in the hand and the wrist wound far from
        its usual configuration; a fresh side grasp from home restores the nominal grasp.
        """
        arm = self.arm
        feats = robot.frame.objects[self.args.obj]
        rotation = robot.rotation(arm)
        lowest = min(feats.bottom[2], feats.top[2])
        down = robot.commanded_pose(arm).pos - np.array([0.0, 0.0, lowest - 0.004])
        yield from move_to(robot, arm, pose_from_matrix(down, rotation), speed=0.12)
        yield from settle(robot, arm, max_ticks=10)
        yield from grip(robot, arm, 0.0, ticks=8)
        retreat = down - 0.08 * rotation[:, 0] + np.array([0.0, 0.0, 0.04])
        yield from move_to(robot, arm, pose_from_matrix(retreat, rotation))
        # The hand is empty: unwind the wrist (wound far by the fallen grasp) at twice the usual speed.
        yield from move_joints(robot, arm, HOME_Q, speed=EMPTY_HAND_JOINT_SPEED)
        robot.set_pose(arm, robot.ik.tcp_pose(arm))
        yield from wait_for_rest(robot, self.args.obj)
        if tilt_deg(robot.frame.objects[self.args.obj].axis) > UPRIGHT_TOLERANCE_DEG:
            # It fell over when set down: the retry loop grasps it again from where it lies.
            raise GraspMissed(f"{self.args.obj} did not stay upright when set down")
        yield from self._side_grasp(robot)

    def _let_go(self, robot: RobotController) -> Iterator[None]:
        # After a drop the object may still rest on the fingers (a rolled tool stacks them
        # vertically): open, roll the tool back level and back off so it falls free.
        arm = self.arm
        if robot.targets[arm].grip > 0.0 or robot.frame.arms[arm].width < 0.05:
            robot.set_grip(arm, 0.0)
            approach = robot.rotation(arm)[:, 0]
            if abs(approach[2]) > 0.9:  # a top grasp: just rise
                rotation, back = robot.rotation(arm), np.array([0.0, 0.0, 0.06])
            else:
                rotation = grasp_frame(approach)
                back = -0.12 * rotation[:, 0] + np.array([0.0, 0.0, 0.04])
            yield from move_to(robot, arm, pose_from_matrix(robot.commanded_pose(arm).pos + back, rotation), speed=0.2)
        robot.set_grip(arm, 0.0)

    def _side_point(self, robot: RobotController, height_fraction: float | None = None) -> np.ndarray:
        feats = robot.frame.objects[self.args.obj]
        height = float(np.linalg.norm(feats.top - feats.bottom))
        fraction = self.args.height if height_fraction is None else height_fraction
        return feats.bottom + fraction * height * feats.axis + self._offset(feats)

    def _side_variant(self, robot: RobotController, variant: tuple[float, float, float | None]):
        scale, rise, fraction = variant
        if fraction is not None:
            fraction = max(fraction, self.args.height)
        point = self._side_point(robot, fraction)
        rotation = self._side_rotation(robot, point)
        pre = point - scale * self.args.pre_grasp_dis * rotation[:, 0] + np.array([0.0, 0.0, rise])
        return pre, point, rotation, fraction

    def _side_plan(self, robot: RobotController) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The side grasp's pre-grasp point, grasp point and tool rotation, and remembers its height.

        The asked one, unless the IK reaches it neither from the current configuration nor from
        home (an object beside the arm's own base: backing off folds the elbow past its limit);
        then the first of ``SIDE_VARIANTS`` it reaches (a shorter or higher pre-grasp, a higher
        grasp point).
        """
        plans = [self._side_variant(robot, variant) for variant in self.SIDE_VARIANTS]
        chosen = plans[0]
        q = robot.ik.configuration.q.copy()
        ik = robot.scratch_ik(avoid_other_arm=False)
        for index, (pre, point, rotation, _) in enumerate(plans):
            poses = [pose_from_matrix(pre, rotation), pose_from_matrix(point, rotation)]
            # The asked grasp from where the arm is, every grasp from home: the same choice on every frame.
            if solve_from_scratch(ik, q, self.arm, poses, from_current=index == 0) is not None:
                chosen = plans[index]
                break
        pre, point, rotation, self._height_fraction = chosen
        return pre, point, rotation

    def _clear_from_below(self, robot: RobotController, height: float) -> Iterator[None]:
        # Coming from low (a recovery after a drop): rise first so the fingers clear the object.
        start = robot.commanded_pose(self.arm).pos
        if start[2] < height:
            yield from move_to(robot, self.arm, pose_from_matrix(np.r_[start[:2], height], robot.rotation(self.arm)))

    def _close_and_check(self, robot: RobotController) -> Iterator[None]:
        try:
            yield from settle(robot, self.arm, max_ticks=30, required=0.015)
        except ActionFailed:
            # Pushed during the approach, it may now lie where this approach cannot end: look again.
            moved = float(np.linalg.norm(robot.frame.objects[self.args.obj].pos - self._seen_at))
            if moved > MOVED_DURING_APPROACH:
                raise GraspMissed(f"{self.args.obj} moved {100 * moved:.1f} cm during the approach") from None
            if robot.ik.arms_close():
                # The collision limit held this arm back from the other one (busy beside it): try again.
                raise GraspMissed(f"the other arm was in the way of the grasp of {self.args.obj}") from None
            raise
        aimed = robot.commanded_pose(self.arm).pos.copy()
        yield from grip(robot, self.arm, 1.0)
        if not robot.frame.is_holding(self.arm, self.args.obj):
            raise GraspMissed(f"fingers closed but {self.args.obj} is not held")
        # Pushed while the fingers closed, it is held off-centre (a pour or a place would then miss):
        # where the grasp point is now, seen from where the tool aimed, says so.
        # (Not for a fallen or leaning object: the closing fingers turn it, which is the point.)
        upright = tilt_deg(robot.frame.objects[self.args.obj].axis) <= UPRIGHT_TOLERANCE_DEG
        off = 0.0
        if self._taken_as == "top":
            off = float(np.linalg.norm(self._top_frame(robot)[1] - aimed))
        elif self._taken_as == "side" and upright and self._upright_at_start:
            off = float(np.linalg.norm(self._side_point(robot, self._height_fraction) - aimed))
        if off > OFF_CENTRE_TOLERANCE:
            raise GraspMissed(f"{self.args.obj} is held {100 * off:.1f} cm off the grasp point")

    def _side_rotation(self, robot: RobotController, point: np.ndarray) -> np.ndarray:
        """The side-grasp tool frame: approach from the arm's base, or at the yaw asked for."""
        if self.args.yaw is None:
            return grasp_frame(point - robot.world.arm_base(self.arm))
        yaw = np.radians(self.args.yaw)
        return grasp_frame(np.array([np.cos(yaw), np.sin(yaw), 0.0]))

    def _side_grasp(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        pre, point, rotation = self._side_plan(robot)
        if np.linalg.norm(robot.commanded_pose(arm).pos[:2] - pre[:2]) > 0.05:
            yield from self._clear_from_below(robot, pre[2] + 0.08)
        yield from approach(robot, arm, pose_from_matrix(pre, rotation))
        # Re-observe: the object may have moved while the arm approached.
        point = self._side_point(robot, self._height_fraction)
        yield from move_to(robot, arm, pose_from_matrix(point, rotation), speed=0.15)
        yield from self._close_and_check(robot)
        lift = robot.commanded_pose(arm).pos + np.array([0.0, 0.0, self.args.lift])
        yield from move_to(robot, arm, pose_from_matrix(lift, rotation), speed=0.15)

    def _top_frame(self, robot: RobotController) -> tuple[np.ndarray, np.ndarray]:
        """Tool rotation (approach down, fingers across the narrow side) and grasp point."""
        feats = robot.frame.objects[self.args.obj]
        rot = _matrix(feats.quat)
        # The object's horizontal principal direction: its axis if lying, else its longer side.
        if tilt_deg(feats.axis) >= self.FALLEN_DEG:
            long_dir = feats.axis
        else:
            long_dir = rot[:, 0] if feats.extent[0] >= feats.extent[1] else rot[:, 1]
        long_dir = np.array([long_dir[0], long_dir[1], 0.0])
        if np.linalg.norm(long_dir) < 1e-6:
            long_dir = np.array([1.0, 0.0, 0.0])
        long_dir /= np.linalg.norm(long_dir)
        # Of the two equivalent finger orientations, take the one facing away from the arm's base.
        outward = feats.pos - robot.world.arm_base(self.arm)
        if np.dot(long_dir[:2], outward[:2]) < 0:
            long_dir = -long_dir
        current = robot.rotation(self.arm)
        if current[2, 0] < -0.7:
            # Already top-down (a regrasp): the orientation nearer the tool's current one, unless
            # that would drive the wrist-rotate joint past its range.
            def turn(direction: np.ndarray) -> float:
                diff = np.arctan2(direction[1], direction[0]) - np.arctan2(current[1, 2], current[0, 2])
                return float((np.degrees(diff) + 180.0) % 360.0 - 180.0)

            near, far = sorted((long_dir, -long_dir), key=lambda d: abs(turn(d)))
            keep = _wrist_margin(robot, self.arm, turn(near), feats.pos)
            long_dir = far if keep < 0.0 and _wrist_margin(robot, self.arm, turn(far), feats.pos) > keep else near
        down = np.array([0.0, 0.0, -1.0])
        rotation = np.column_stack([down, np.cross(long_dir, down), long_dir])
        lying = tilt_deg(feats.axis) >= self.FALLEN_DEG
        top_z = feats.pos[2] + 0.5 * feats.extent[0] if lying else max(feats.top[2], feats.bottom[2])
        height = top_z - min(feats.bottom[2], feats.top[2]) if not lying else float(feats.extent[0])
        # Finger tips go 70% down the object (at most 3 cm), never closer than 4 mm to the table.
        tips_z = max(top_z - min(0.7 * height, 0.03), 0.004)
        point = np.r_[feats.pos[:2], tips_z + self.FINGERTIP_REACH]
        return rotation, point + self._offset(feats)

    def _offset(self, feats) -> np.ndarray:
        """The grasp offset in the world frame."""
        offset = np.asarray(self.args.offset, dtype=float)
        return _matrix(feats.quat) @ offset if self.args.offset_frame == "object" else offset

    def _top_grasp(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        rotation, point = self._top_frame(robot)
        above = point + np.array([0.0, 0.0, self.args.pre_grasp_dis])
        yield from self._clear_from_below(robot, above[2])
        yield from approach(robot, arm, pose_from_matrix(above, rotation))
        # A top-down tool often flips the forearm roll: let the IK converge before descending.
        yield from settle(robot, arm, tolerance=0.003, max_ticks=60, required=0.015)
        rotation, point = self._top_frame(robot)
        yield from move_to(robot, arm, pose_from_matrix(point, rotation), speed=0.08)
        yield from self._close_and_check(robot)
        # lift 0 leaves the object on the table (two arms grasping one tray lift it together afterwards).
        lift_by = 0.0 if self.args.lift == 0.0 else max(self.args.lift, 0.04)
        lift = robot.commanded_pose(arm).pos + np.array([0.0, 0.0, lift_by])
        yield from move_to(robot, arm, pose_from_matrix(lift, rotation), speed=0.15)

    def _fallen_frame(self, robot: RobotController) -> tuple[np.ndarray, np.ndarray]:
        """Tool rotation (approach down, fingers across the lying object's axis) and grasp point."""
        feats = robot.frame.objects[self.args.obj]
        top_dir = np.array([feats.axis[0], feats.axis[1], 0.0])
        top_dir /= max(np.linalg.norm(top_dir), 1e-9)
        down = np.array([0.0, 0.0, -1.0])
        rotation = np.column_stack([down, np.cross(top_dir, down), top_dir])
        radius = 0.5 * float(feats.extent[0])
        # The finger tips reach ~4 cm past the tool centre: stay high enough to miss the table.
        return rotation, np.r_[feats.pos[:2], max(feats.pos[2] + 0.35 * radius, self.FINGERTIP_REACH + 0.006)]

    def _fallen_grasp(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        feats = robot.frame.objects[self.args.obj]
        rotation, point = self._fallen_frame(robot)
        top_dir = rotation[:, 2]
        yield from self._clear_from_below(robot, point[2] + self.args.pre_grasp_dis + 0.05)
        yield from approach(robot, arm, pose_from_matrix(point + np.array([0, 0, self.args.pre_grasp_dis]), rotation))
        # A top-down tool often flips the forearm roll: let the IK converge before descending.
        yield from settle(robot, arm, tolerance=0.003, max_ticks=60, required=0.015)
        feats = robot.frame.objects[self.args.obj]
        point[:2] = feats.pos[:2]
        yield from move_to(robot, arm, pose_from_matrix(point, rotation), speed=0.08)
        yield from self._close_and_check(robot)
        half_length = 0.5 * float(np.linalg.norm(feats.top - feats.bottom))
        lifted = point + np.array([0.0, 0.0, half_length + 0.06])
        yield from move_to(robot, arm, pose_from_matrix(lifted, rotation), speed=0.15)
        # Swing the object's top to point away from the robot, then pitch it up: the tool
        # ends in the usual side-grasp frame with the object upright between the fingers.
        outward = grasp_frame(lifted - robot.world.arm_base(arm))[:, 0]
        yaw = np.arctan2(np.cross(top_dir, outward)[2], float(np.dot(top_dir, outward)))
        swung = Rotation.from_euler("z", yaw).as_matrix() @ rotation
        yield from move_to(robot, arm, pose_from_matrix(lifted, swung))
        upright = swung @ Rotation.from_euler("y", -90.0, degrees=True).as_matrix()
        yield from move_to(robot, arm, pose_from_matrix(lifted, upright), speed=0.15)
        yield from settle(robot, arm)


def _avoid(robot: RobotController, arm: str, exclude: tuple[str, ...]):
    """Obstacles (every object not held and not excluded) and what ``arm`` carries, from the latest frame."""
    frame = robot.frame
    return scene_spheres(frame, exclude=exclude), held_spheres(frame, arm)


class MoveToObj(ArmAction):
    """Move the tool (and what it holds) to an offset from an object's top point, upright."""

    name = "move_to_obj"
    args: catalog.MoveToObjArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        # A pushed target may still be sliding: aim at where it stops.
        yield from wait_for_rest(robot, self.args.obj)
        if self.args.keep_orientation:
            rotation = robot.rotation(arm)
        elif self.args.yaw is None:
            rotation = _level(robot.rotation(arm))
        else:
            yaw = np.radians(self.args.yaw)
            rotation = grasp_frame(np.array([np.cos(yaw), np.sin(yaw), 0.0]))
        target = robot.frame.objects[self.args.obj].top + np.asarray(self.args.offset)
        if self.args.path == "solved":
            # The object aimed at is the goal, not an obstacle.
            yield from move_along_solved_path(robot, arm, pose_from_matrix(target, rotation), lambda: _avoid(robot, arm, (self.args.obj,)))
        else:
            # Straight, unless what the arm carries would be driven through another object on the way.
            obstacles, carried = _avoid(robot, arm, ())
            for waypoint in lift_over(robot.commanded_pose(arm).pos, target, obstacles, carried):
                yield from move_to(robot, arm, pose_from_matrix(waypoint, rotation))
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


#: Largest extent (m) of a point feature (a cloth corner) rather than a body.
POINT_EXTENT = 0.01
#: A tall object tilted more than this in the hand (deg) is turned upright before it is put down,
#: with its bottom at least this high (m) while it turns.
LEVEL_IN_HAND_DEG = 4.0
LEVEL_CLEARANCE = 0.02
#: Finger gap beyond the object's width (m) when releasing it inside a rim.
RELEASE_MARGIN = 0.02
#: Height (m) by which a placed object clears the top of the object it is placed relative to.
RIM_CLEARANCE = 0.02


class Place(ArmAction):
    """Lower the held object onto the table, release it, retreat."""

    name = "place"
    args: catalog.PlaceArgs

    #: Ticks to wait before failing on an object that is not held: one dropped as the previous
    #: action ended is then reported by the edge's drop monitor (its persistence window) instead.
    DROP_GRACE_TICKS = 8

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        if not robot.frame.is_holding(arm, self.args.obj):
            if self.args.skip_if_placed and self._standing(robot):
                yield from self._release_and_retreat(robot)
                return
            for _ in range(self.DROP_GRACE_TICKS):
                yield
                if robot.frame.is_holding(arm, self.args.obj):
                    break  # finger contact flickered for a tick (a tray shifting in two grips): go on
            else:
                raise ActionFailed(f"{self.args.obj} is not held: nothing to place")
        if self.args.relative_to is not None and self.args.within_reach is None:
            # A pushed reference may still be sliding: aim at where it stops.
            yield from wait_for_rest(robot, self.args.relative_to)
        obj = robot.frame.objects[self.args.obj]
        tool = robot.commanded_pose(arm)
        rotation = _level(robot.rotation(arm))
        above = tool.pos.copy()
        target = None if self.args.target is None else np.asarray(self.args.target, dtype=float)
        if target is not None and self.args.relative_to is not None:
            target = target + robot.frame.objects[self.args.relative_to].pos[:2]
        if self.args.within_reach is not None:
            try:
                target = handoff_spot(robot.frame, self.args.obj, arm, self.args.within_reach)
            except NoHandoffSpotError as error:
                raise ActionFailed(str(error)) from None
        if self.args.yaw is not None:
            # Turn the tool about the vertical so the object's long axis ends at the asked yaw
            # (either direction), keeping the object's centre where it goes.
            goal = target if target is not None else obj.pos[:2]
            turn = _yaw_turn(robot, arm, _long_axis(obj), self.args.yaw, goal)
            held = obj.pos[:2] - tool.pos[:2]
            rotation = turn @ rotation
            above[:2] = goal - turn[:2, :2] @ held
        elif target is not None:
            # Put the object's centre, not the tool, over the target.
            above[:2] += target - obj.pos[:2]
        above[2] = max(above[2], tool.pos[2])
        if self.args.relative_to is not None and self.args.within_reach is None:
            # Carry the object over the reference's rim (into a cup, onto a block), not through it.
            host_top = robot.frame.objects[self.args.relative_to].top[2]
            above[2] = max(above[2], tool.pos[2] + host_top + RIM_CLEARANCE - obj.bottom[2])
        yield from move_to(robot, arm, pose_from_matrix(above, rotation))
        rotation = yield from self._upright_in_hand(robot, rotation)
        obj = robot.frame.objects[self.args.obj]
        drop = obj.bottom[2] - (self.args.z_offset + 0.004)
        down = robot.commanded_pose(arm).pos - np.array([0.0, 0.0, drop])
        yield from move_to(robot, arm, pose_from_matrix(down, rotation), speed=0.12)
        yield from settle(robot, arm, max_ticks=10)
        yield from grip(robot, arm, self._release_grip(robot), ticks=8)
        # Back off along the approach (straight up after a top grasp).
        retreat = down - 0.08 * rotation[:, 0] + np.array([0.0, 0.0, 0.04 if rotation[2, 0] > -0.7 else 0.0])
        yield from move_to(robot, arm, pose_from_matrix(retreat, rotation))
        if robot.targets[arm].grip > 0.0:
            yield from grip(robot, arm, 0.0, ticks=6)  # clear of the rim: open fully for the next grasp

    def _upright_in_hand(self, robot: RobotController, rotation: np.ndarray) -> Iterator[None]:
        """Over the spot, turn a tall object held askew (an off-centre regrasp) upright before lowering it.

        Released at a tilt, a tall object leans or topples. Measured where the transport ended (a weak
        hold may slip on the way): the smallest tool rotation that makes the object's axis vertical,
        about the object's centre, slowly, lifted clear of the table first if it hangs low. Returns the
        tool rotation to lower with.
        """
        obj = robot.frame.objects[self.args.obj]
        if obj.extent[2] <= 1.5 * max(obj.extent[0], obj.extent[1]):
            return rotation
        angle = tilt_deg(obj.axis)
        if angle < LEVEL_IN_HAND_DEG or angle > UPRIGHT_TOLERANCE_DEG:
            return rotation
        tool = robot.commanded_pose(self.arm).pos
        lift = max(0.0, LEVEL_CLEARANCE - float(min(obj.bottom[2], obj.top[2])))
        fix = Rotation.align_vectors([[0.0, 0.0, 1.0]], [obj.axis])[0].as_matrix()
        centre = obj.pos + np.array([0.0, 0.0, lift])
        turned = fix @ rotation
        goal = centre - fix @ (obj.pos - tool)
        yield from move_to(robot, self.arm, pose_from_matrix(goal, turned), speed=0.08)
        yield from settle(robot, self.arm, max_ticks=10)
        return turned

    def _release_grip(self, robot: RobotController) -> float:
        """Fully open, unless the object sits inside a rim (a cup): then just wider than the object,
        so the fingers do not press on the walls and lift the container on the way out."""
        if self.args.relative_to is None:
            return 0.0
        obj = robot.frame.objects[self.args.obj]
        if robot.frame.objects[self.args.relative_to].top[2] < obj.bottom[2] + 0.01:
            return 0.0
        gap = float(min(obj.extent[0], obj.extent[1])) + RELEASE_MARGIN
        lo, hi = FINGER_RANGE
        q = 0.5 * (gap + FINGER_GAP_OFFSET)
        return float(np.clip((hi - q) / (hi - lo), 0.0, 1.0))

    def _standing(self, robot: RobotController) -> bool:
        """Whether the object already stands upright on the table (an earlier place released it)."""
        feats = robot.frame.objects[self.args.obj]
        if float(np.max(feats.extent)) < POINT_EXTENT:
            return True  # a point feature (a cloth's corner) released is placed wherever it lies
        return tilt_deg(feats.axis) <= UPRIGHT_TOLERANCE_DEG and min(feats.bottom[2], feats.top[2]) < 0.01

    def _release_and_retreat(self, robot: RobotController) -> Iterator[None]:
        """Open (if still closed) and back off from where the tool is: the rest of an interrupted place."""
        arm = self.arm
        if robot.targets[arm].grip > 0.0:
            yield from grip(robot, arm, 0.0, ticks=8)
        rotation = _level(robot.rotation(arm))
        tool = robot.commanded_pose(arm).pos
        retreat = tool - 0.08 * rotation[:, 0] + np.array([0.0, 0.0, 0.04 if rotation[2, 0] > -0.7 else 0.0])
        yield from move_to(robot, arm, pose_from_matrix(retreat, rotation))


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
    cls.name: cls for cls in (Grasp, MoveToObj, MoveToTarget, MoveByOffset, RotateEef, Place, Back, OpenGripper, CloseGripper)
}


def make_action(fn: str, arm: str, args: dict) -> ArmAction:
    """Instantiate an atomic action from a graph's action call.

    Raises:
        KeyError: Unknown action (graph validation reports this earlier).
        pydantic.ValidationError: Arguments that do not fit the catalogue.
    """
    spec = catalog.ACTIONS[fn]
    return PROGRAMS[fn](arm, spec.args.model_validate(args))
