"""Where a side grasp goes: its grasp point, tool frame and pre-grasp, reachable and clear on the way in.

A side grasp (a tall upright object: a bottle, a cup) comes in horizontally from the arm's base,
or at the yaw the graph asks for, to a share of the object's height. Two things can stand in its
way. An object beside the arm's own base puts the pre-grasp, 8 cm further back, where the elbow
folds past its limit: then a shorter or higher pre-grasp, or a higher grasp point
(:data:`REACH_VARIANTS`). An object lying beside this one puts the open fingers in it on their
way in (the cup's grasps pushed a bottle lying beside it and closed on the cup 3.9 cm off
centre): then the approach turned about the object, or a grasp higher up, over a neighbour
lying on its side (:data:`CLEAR_TURNS_DEG`, :data:`CLEAR_HEIGHT`).

The plan is a pure function of the frame and the arm's configuration: the same on every frame
that shows the same scene, so feasibility checks and the grasp itself agree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions.catalog import GraspArgs
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.finger_clearance import side_approach_blocking
from agentchord.actions.motion import grasp_frame, pose_from_matrix
from agentchord.actions.grasping.top_grasp import FINGERTIP_REACH
from agentchord.features.frame import ObjectFeatures, tilt_deg
from agentchord.solvers.ik import solve_from_scratch

#: Side grasps tried in order where the asked one cannot be reached: (share of the pre-grasp
#: distance, rise of the pre-grasp pose in m, grasp height as a share of the object's or None for
#: the asked one; a higher one is only ever taken).
REACH_VARIANTS = ((1.0, 0.0, None), (1.0, 0.03, None), (0.5, 0.0, None), (0.5, 0.03, None), (0.5, 0.03, 0.8))
#: Where the open fingers of the asked grasp would sweep into a neighbour on the way in, these
#: turns (deg) of the approach about the object are tried, nearest first ...
CLEAR_TURNS_DEG = (15.0, -15.0, 30.0, -30.0, 45.0, -45.0)
#: ... then, over a neighbour lying on its side (tilted at least this far, deg), a grasp this high
#: (share of the object's height).
LYING_DEG = 60.0
CLEAR_HEIGHT = 0.8
#: The open gripper's footprint around the tool centre (m): from the palm behind it to the finger
#: tips ahead of it, and across the open fingers.
PALM_BEHIND = 0.06
FINGERS_ACROSS = 0.05
#: The band (m) around an object's top in which a descending gripper over it strikes it.
TOP_BAND = (-0.03, 0.015)


@dataclass(frozen=True)
class SidePlan:
    """A side grasp's poses.

    Attributes:
        pre: The pre-grasp tool position.
        point: The grasp's tool position (the tool centre on the object's axis).
        rotation: The tool frame: x along the horizontal approach, z up.
        height_fraction: The grasp's height as a share of the object's; None for the asked one.
    """

    pre: np.ndarray
    point: np.ndarray
    rotation: np.ndarray
    height_fraction: float | None


def side_point(robot: RobotController, args: GraspArgs, offset: np.ndarray, height_fraction: float | None = None) -> np.ndarray:
    """The tool centre of a side grasp of ``args.obj``: on its axis at ``height_fraction`` (default:
    the asked height) of its height, moved by the grasp ``offset`` (world frame)."""
    feats = robot.frame.objects[args.obj]
    height = float(np.linalg.norm(feats.top - feats.bottom))
    fraction = args.height if height_fraction is None else height_fraction
    return feats.bottom + fraction * height * feats.axis + offset


def side_rotation(robot: RobotController, arm: str, args: GraspArgs, point: np.ndarray, turn_deg: float = 0.0) -> np.ndarray:
    """The side-grasp tool frame: approach from the arm's base, or at the yaw asked for; turned
    ``turn_deg`` about the vertical."""
    if args.yaw is None:
        approach = point - robot.world.arm_base(arm)
    else:
        yaw = np.radians(args.yaw)
        approach = np.array([np.cos(yaw), np.sin(yaw), 0.0])
    if turn_deg:
        approach = Rotation.from_euler("z", turn_deg, degrees=True).as_matrix() @ approach
    return grasp_frame(approach)


class SidePlanner:
    """Plans one side grasp of ``args.obj`` by ``arm`` on the current frame.

    Args:
        robot: The robot (its frame, configuration and scratch IK are read).
        arm: The grasping arm.
        args: The grasp's arguments.
        offset: The grasp offset in the world frame.
    """

    def __init__(self, robot: RobotController, arm: str, args: GraspArgs, offset: np.ndarray) -> None:
        self.robot, self.arm, self.args, self.offset = robot, arm, args, offset
        self._q = robot.ik.configuration.q.copy()
        self._ik = robot.scratch_ik(avoid_other_arm=False)

    def plan(self) -> SidePlan:
        """The asked grasp, unless the IK reaches it neither from the current configuration nor from
        home: then the first of :data:`REACH_VARIANTS` it reaches. Where that one's open fingers
        would sweep into a neighbour on the way in, the nearest clear one (:meth:`clear`)."""
        chosen = self.reachable(0.0, None) or self.variant(REACH_VARIANTS[0])
        if self.blocked(chosen):
            chosen = self.clear() or chosen
        return chosen

    def variant(self, variant: tuple[float, float, float | None], turn_deg: float = 0.0) -> SidePlan:
        """The plan of one (pre-grasp share, rise, height share) variant at a turn of the approach."""
        scale, rise, fraction = variant
        if fraction is not None:
            fraction = max(fraction, self.args.height)
        point = side_point(self.robot, self.args, self.offset, fraction)
        rotation = side_rotation(self.robot, self.arm, self.args, point, turn_deg)
        pre = point - scale * self.args.pre_grasp_dis * rotation[:, 0] + np.array([0.0, 0.0, rise])
        return SidePlan(pre, point, rotation, fraction)

    def reachable(self, turn_deg: float, fraction: float | None) -> SidePlan | None:
        """The first of :data:`REACH_VARIANTS` (at this turn, and at ``fraction`` of the object's
        height where given) the IK reaches, or None."""
        for index, variant in enumerate(REACH_VARIANTS):
            if fraction is not None:
                variant = (variant[0], variant[1], max(fraction, variant[2] or 0.0))
            plan = self.variant(variant, turn_deg)
            poses = [pose_from_matrix(plan.pre, plan.rotation), pose_from_matrix(plan.point, plan.rotation)]
            # The asked grasp from where the arm is, every other from home: the same choice on every frame.
            from_current = index == 0 and turn_deg == 0.0 and fraction is None
            if solve_from_scratch(self._ik, self._q, self.arm, poses, from_current=from_current) is not None:
                return plan
        return None

    def blocked(self, plan: SidePlan) -> bool:
        """Whether the open fingers sweep into a neighbour between the pre-grasp and the grasp."""
        return bool(side_approach_blocking(self.robot.frame, self.args.obj, plan.pre, plan.point, plan.rotation))

    def clear(self) -> SidePlan | None:
        """The reachable side grasp nearest the asked one whose open fingers clear every neighbour on
        the way in, or None.

        Tried nearest first: the approach turned about the object (:data:`CLEAR_TURNS_DEG`; not
        when the graph asked for a yaw), then, where what is in the way lies on its side, a higher
        grasp over it (:data:`CLEAR_HEIGHT`) with each turn. A neighbour standing beside the object
        is only nudged by the passing fingers and slides (a bottle's grasp sweeping 1.8 cm into
        the cup standing behind it holds as asked); one lying there rolls ahead of them and the
        object is caught off centre. The rule reads the scene alone, so every method's grasps
        choose alike.
        """
        turns = (0.0,) + (CLEAR_TURNS_DEG if self.args.yaw is None else ())
        heights: tuple[float | None, ...] = (None,)
        if CLEAR_HEIGHT > self.args.height and self._lying_in_the_way():
            heights += (CLEAR_HEIGHT,)
        for fraction in heights:
            for turn in turns:
                if fraction is None and turn == 0.0:
                    continue  # the blocked one
                if self.blocked(self.variant((1.0, 0.0, fraction), turn)):
                    continue  # checked before the IK: the sweep is cheap, a solve is not
                plan = self.reachable(turn, fraction)
                if plan is not None and not self.blocked(plan):
                    return plan
        return None

    def _lying_in_the_way(self) -> bool:
        """Whether a neighbour the asked grasp's fingers sweep into lies on its side."""
        plan = self.variant(REACH_VARIANTS[0])
        hit = side_approach_blocking(self.robot.frame, self.args.obj, plan.pre, plan.point, plan.rotation)
        return any(tilt_deg(self.robot.frame.objects[name].axis) >= LYING_DEG for name in hit)


def strikes_top(start: np.ndarray, end: np.ndarray, approach_dir: np.ndarray, feats: ObjectFeatures, top: float) -> bool:
    """Whether the open gripper, moved in a straight line from ``start`` to ``end`` with its fingers
    pointing along ``approach_dir``, crosses the object's top (at height ``top``) with its footprint over it."""
    radius = 0.5 * float(max(feats.extent[0], feats.extent[1]))
    ahead = np.array([approach_dir[0], approach_dir[1], 0.0])
    ahead /= max(float(np.linalg.norm(ahead)), 1e-9)
    across = np.array([-ahead[1], ahead[0], 0.0])
    for s in np.linspace(0.0, 1.0, 41):
        tool = start + s * (end - start)
        if not TOP_BAND[0] <= tool[2] - top <= TOP_BAND[1]:
            continue
        to_axis = feats.pos - tool
        along, side = float(np.dot(to_axis, ahead)), float(np.dot(to_axis, across))
        if -PALM_BEHIND - radius < along < FINGERTIP_REACH + radius and abs(side) < FINGERS_ACROSS + radius:
            return True
    return False
