"""The place action: carry the held object over its spot, stand it upright in hand, lower, release
(and tip a thin one set down on its edge flat), retreat."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions import catalog
from agentchord.actions.base import ActionFailed, ArmAction, ObjectGone
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.geometry import level_frame, yaw_turn
from agentchord.actions.grasp import UPRIGHT_TOLERANCE_DEG, Grasp
from agentchord.actions.motion import grip, move_to, pose_from_matrix, settle, wait_for_rest
from agentchord.actions.grasping.tip_flat import PUSH_SPEED, push_length, standing_height, tip_push, tip_start
from agentchord.actions.grasping.top_grasp import long_axis, on_its_edge, plain_top_grasp
from agentchord.features.frame import FeatureFrame, ObjectFeatures, tilt_deg
from agentchord.solvers.exceptions import NoHandoffSpotError
from agentchord.solvers.handoff import TAKER_MARGIN, handoff_spot
from agentchord.solvers.ik import solve_from_scratch
from agentchord.solvers.poses import top_down_rotation
from agentchord.robot.aloha import FINGER_GAP_OFFSET, FINGER_RANGE

#: Extra reach slack (m) tried in turn for a hand-off spot until the IK confirms the taker's top-down grasp there.
HANDOFF_EXTRA_MARGINS = (0.0, 0.02, 0.04, 0.06, 0.08)
#: A tall object tilted more than this in the hand (deg) is turned upright before it is put down,
#: with its bottom at least this high (m) while it turns.
LEVEL_IN_HAND_DEG = 4.0
#: ... and at most this tilted (deg): more is a hold across the object (a fork, a bottle lying), not askew.
#: A hand-over grasp pushed as it closed held the block at 39 deg; the bound was the upright
#: tolerance (25 deg) and the block, set down askew, leant on the fingers.
UPRIGHT_IN_HAND_MAX_DEG = 50.0
LEVEL_CLEARANCE = 0.02
#: Finger gap beyond the object's width (m) when releasing it inside a rim.
RELEASE_MARGIN = 0.02
#: Height (m) by which a placed object clears the top of the object it is placed relative to.
RIM_CLEARANCE = 0.02
#: A released object whose centre is within this (m, horizontally) of the place's target, and whose
#: long axis is within PLACED_YAW_DEG of the asked yaw, lies placed (the task graphs' sub-goal tolerances).
PLACED_TOLERANCE = 0.03
PLACED_YAW_DEG = 20.0
#: ... resting: its lower end below this height (m) (on the table, or on a tray or plate).
PLACED_HEIGHT = 0.05


def _top_grasp_reaches(robot: RobotController, arm: str, feats: ObjectFeatures, spot: np.ndarray) -> bool:
    """Whether the IK puts ``arm``'s tool above and at a top-down grasp of the object set down at ``spot``."""
    shift = np.r_[spot - feats.pos[:2], -min(feats.bottom[2], feats.top[2])]
    there = replace(feats, pos=feats.pos + shift, top=feats.top + shift, bottom=feats.bottom + shift)
    long_dir, point = plain_top_grasp(there)
    if np.dot(long_dir[:2], there.pos[:2] - robot.world.arm_base(arm)[:2]) < 0:
        long_dir = -long_dir  # the finger orientation facing away from the arm's base, as the grasp takes
    rotation = top_down_rotation(long_dir)
    above = point + np.array([0.0, 0.0, catalog.GraspArgs.model_fields["pre_grasp_dis"].default])
    poses = [pose_from_matrix(above, rotation), pose_from_matrix(point, rotation)]
    ik = robot.scratch_ik(avoid_other_arm=False)
    return solve_from_scratch(ik, robot.ik.configuration.q.copy(), arm, poses) is not None


class Place(ArmAction):
    """Lower the held object onto the table, release it, retreat."""

    name = "place"
    args: catalog.PlaceArgs

    #: Ticks to wait before failing on an object that is not held: one dropped as the previous
    #: action ended is then reported by the edge's drop monitor (its persistence window) instead.
    DROP_GRACE_TICKS = 8

    #: Set by the executor on a recovery's places: whether the released object already meets what
    #: the recovery's merge sub-goal asks of it. A towel corner is released 4 cm short of where it
    #: settles, so "at the place's target" is the wrong test for a corner that fell and settled.
    meets_subgoal: Callable[[FeatureFrame], bool] | None = None
    #: Set by the edge program on a hand-off place: the table points its later steps move a tool to
    #: (``move_to_target``), where a held object is carried (kept clear of the spot).
    carried_to: tuple[np.ndarray, ...] = ()

    def script(self, robot: RobotController) -> Iterator[None]:
        arm = self.arm
        if not robot.frame.is_holding(arm, self.args.obj):
            if self.args.skip_if_placed and (self._standing(robot) or self.lies_at_target(robot)):
                yield from self._release_and_retreat(robot)
                return
            for _ in range(self.DROP_GRACE_TICKS):
                yield
                if robot.frame.is_holding(arm, self.args.obj):
                    break  # finger contact flickered for a tick (a tray shifting in two grips): go on
            else:
                if self.args.free_hand:
                    # Only a free hand was asked for, and the hand is free: the object fell on its own.
                    yield from self._release_and_retreat(robot)
                    return
                raise ObjectGone(f"{self.args.obj} is not held: nothing to place")
        if self.args.relative_to is not None and self.args.within_reach is None:
            # A pushed reference may still be sliding: aim at where it stops.
            yield from wait_for_rest(robot, self.args.relative_to)
        obj = robot.frame.objects[self.args.obj]
        tool = robot.commanded_pose(arm)
        rotation = level_frame(robot.rotation(arm))
        above = tool.pos.copy()
        target = None if self.args.target is None else np.asarray(self.args.target, dtype=float)
        if target is not None and self.args.relative_to is not None:
            target = target + robot.frame.objects[self.args.relative_to].pos[:2]
        if self.args.within_reach is not None:
            target = self._handoff_target(robot)
        if self.args.yaw is not None:
            # Turn the tool about the vertical so the object's long axis ends at the asked yaw
            # (either direction), keeping the object's centre where it goes.
            goal = target if target is not None else obj.pos[:2]
            turn = yaw_turn(robot, arm, long_axis(obj), self.args.yaw, goal)
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
        tool = robot.commanded_pose(arm).pos
        # A flat object held on its edge (a fork) is tipped flat once released: set down short of its spot.
        tip = tip_push(robot.frame, self.args.obj, tool, rotation, self.args.z_offset)
        lowest = obj.bottom[2] if tip is None else obj.pos[2] - 0.5 * standing_height(obj)
        down = tool - np.array([0.0, 0.0, lowest - (self.args.z_offset + 0.004)])
        if tip is not None:
            push, short = tip
            down -= short * push
        yield from move_to(robot, arm, pose_from_matrix(down, rotation), speed=0.12)
        yield from settle(robot, arm, max_ticks=10)
        yield from grip(robot, arm, self._release_grip(robot), ticks=8)
        if tip is not None:
            down = yield from self._tip_over(robot, push, rotation)
        # Back off along the approach (straight up after a top grasp).
        retreat = down - 0.08 * rotation[:, 0] + np.array([0.0, 0.0, 0.04 if rotation[2, 0] > -0.7 else 0.0])
        yield from move_to(robot, arm, pose_from_matrix(retreat, rotation))
        if robot.targets[arm].grip > 0.0:
            yield from grip(robot, arm, 0.0, ticks=6)  # clear of the rim: open fully for the next grasp

    def _handoff_target(self, robot: RobotController) -> np.ndarray:
        """Where to set the object down for the other arm: the nearest spot both arms reach.

        The reach shell was measured for side grasps; a top-down tool reaches less far (a capsule
        set down 0.60 m from the taker's shoulder: its grasp fell 2 cm short). An object the taker
        will take from above gets a spot the IK confirms, moved towards the middle of the taker's
        shell until one is; none confirmed, the nearest spot it is.
        """
        frame, taker = robot.frame, self.args.within_reach
        feats = frame.objects[self.args.obj]
        from_above = not Grasp.is_tall(feats)
        nearest = None
        for extra in HANDOFF_EXTRA_MARGINS:
            try:
                spot = handoff_spot(frame, self.args.obj, self.arm, taker, taker_margin=TAKER_MARGIN + extra,
                                    carried_to=self.carried_to)
            except NoHandoffSpotError as error:
                if nearest is None:
                    raise ActionFailed(str(error)) from None
                break
            nearest = spot if nearest is None else nearest
            if not from_above or _top_grasp_reaches(robot, taker, feats, spot):
                return spot
        return nearest

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
        if angle < LEVEL_IN_HAND_DEG or angle > UPRIGHT_IN_HAND_MAX_DEG:
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

    def _tip_over(self, robot: RobotController, push: np.ndarray, rotation: np.ndarray) -> Iterator[None]:
        """Push the top edge of the released object, standing on its edge, across with the open fingers,
        so it falls on its face (:mod:`~agentchord.actions.grasping.tip_flat`). Returns where the tool ends."""
        tool = robot.commanded_pose(self.arm).pos
        feats = robot.frame.objects[self.args.obj]
        if not on_its_edge(feats):
            return tool  # it fell flat as it was let go
        start = tip_start(tool, feats, self.args.z_offset)
        yield from move_to(robot, self.arm, pose_from_matrix(start, rotation), speed=0.1)
        end = start + push_length(tool, feats, push) * push
        yield from move_to(robot, self.arm, pose_from_matrix(end, rotation), speed=PUSH_SPEED)
        return end

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
        if feats.is_point:
            return True  # a point feature (a cloth's corner) released is placed wherever it lies
        return tilt_deg(feats.axis) <= UPRIGHT_TOLERANCE_DEG and min(feats.bottom[2], feats.top[2]) < 0.01

    def lies_at_target(self, robot: RobotController) -> bool:
        """Whether the object already lies released where this place puts it (a drop that finished it).

        Where the executor gave this place a sub-goal check (:attr:`meets_subgoal`), released where
        that check holds. Otherwise at rest low on the table (or on the object it is placed on), its
        centre within :data:`PLACED_TOLERANCE` of the target, its long axis at the asked yaw, and a
        tall object upright.
        """
        args = self.args
        frame = robot.frame
        if any(frame.is_holding(arm, args.obj) for arm in frame.arms):
            return False
        if self.meets_subgoal is not None and self.meets_subgoal(frame):
            return True
        if args.target is None or args.within_reach is not None:
            return False
        feats = frame.objects[args.obj]
        target = np.asarray(args.target, dtype=float)
        if args.relative_to is not None:
            target = target + frame.objects[args.relative_to].pos[:2]
        if float(np.linalg.norm(feats.pos[:2] - target)) > PLACED_TOLERANCE:
            return False
        if min(feats.bottom[2], feats.top[2]) > PLACED_HEIGHT:
            return False
        if Grasp.is_tall(feats) and tilt_deg(feats.axis) > UPRIGHT_TOLERANCE_DEG:
            return False
        if args.yaw is not None:
            axis = long_axis(feats)
            off = (np.degrees(np.arctan2(axis[1], axis[0])) - args.yaw) % 180.0
            if min(off, 180.0 - off) > PLACED_YAW_DEG:
                return False
        return True

    def _release_and_retreat(self, robot: RobotController) -> Iterator[None]:
        """Open (if still closed) and back off from where the tool is: the rest of an interrupted place."""
        arm = self.arm
        if robot.targets[arm].grip > 0.0:
            yield from grip(robot, arm, 0.0, ticks=8)
        rotation = level_frame(robot.rotation(arm))
        tool = robot.commanded_pose(arm).pos
        retreat = tool - 0.08 * rotation[:, 0] + np.array([0.0, 0.0, 0.04 if rotation[2, 0] > -0.7 else 0.0])
        yield from move_to(robot, arm, pose_from_matrix(retreat, rotation))
