"""The wrist's two branches, and the fallen grasp's joint-space moves on the side-grasp one.

The ViperX wrist (forearm roll, wrist angle, wrist rotate) reaches every tool orientation two
ways: joints ``(r, p, w)`` and ``(r + pi, -p, w + pi)``. The side grasps' postures have the roll
near 0 (here: *unflipped*). Pitching the tool through the wrist's singularity (wrist angle 0,
where the roll and rotate axes line up) swaps the live IK's branch: a straight-line move from a
side posture to a tool pointing down ends with the roll near pi, and the turn of a fallen object
upright in hand crosses back, the solver swinging roll and rotate through pi in ~0.2 s with the
measured joints up to 0.7 rad behind. Measured on pours under pushes and pulls: every fallen
grasp was taken flipped, and the whip at the crossing pivoted the object between the finger
pads, leaving it 8-20 degrees askew in 8 of 16 (a pour from such a hold misses the cup).
A straight joint-space move on the unflipped branch passes wrist angle 0 smoothly: over the
object with the empty hand, then, holding it, to upright.
"""

from __future__ import annotations

from collections.abc import Generator, Iterator
from dataclasses import dataclass

import numpy as np

from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.finger_clearance import swept_hits
from agentchord.actions.joint_path import joint_path
from agentchord.actions.motion import ANGULAR_SPEED, EMPTY_HAND_JOINT_SPEED, line_poses, move_joints, pose_from_matrix
from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX
from agentchord.solvers.ik import ARM_CLEARANCE, BimanualIK, PoseTarget, solve_from_scratch
from agentchord.solvers.poses import quat_to_rotation

#: Forearm roll beyond this (rad) from 0: the flipped branch.
FLIPPED_ROLL = 0.5 * np.pi
#: Wrist rotate beyond this (rad) from 0: wound (a pour's roll would run it past its limit).
WOUND_ROTATE = 0.5 * np.pi
#: A joint-space move keeps the arms' collision proxies (which wrap the links) this far apart (m):
#: half the live IK's margin, which a straight line's solver needs to steer by.
PATH_CLEARANCE = 0.5 * ARM_CLEARANCE
#: Straight-line waypoints a scratch solve follows where one leap does not reach (the live IK's way).
LINE_WAYPOINTS = 4
#: An object turned upright in joint space keeps its lowest point this far (m) above the table:
#: a straight joint-space move leaves the tool's fixed point, dipping ~5 cm halfway.
TURN_TABLE_CLEARANCE = 0.03
#: The turn upright moves the wrist angle at most this fast (rad/s): it pitches the object about
#: the finger pads' normal, the axis they hold it least about. A lying bottle placed at 20 spots
#: and headings before the right arm: at 1.6 (the tool's usual turn speed) left up to 5.3 deg
#: askew (1 of 20 beyond the reseat's 5), at 1.4 up to 3.9, at 1.2 up to 2.8 (21 steps longer).
TURN_PITCH_SPEED = 1.4
_WRIST_ANGLE = ARM_JOINTS.index("wrist_angle")


def is_flipped(q6: np.ndarray) -> bool:
    """Whether an arm's joints are on the flipped wrist branch (forearm roll near pi)."""
    return abs(float(q6[3])) > FLIPPED_ROLL


def is_wound(q6: np.ndarray) -> bool:
    """Whether an arm's wrist is far from its side-grasp posture: flipped, or the rotate joint
    more than a quarter turn round."""
    return is_flipped(q6) or abs(float(q6[5])) > WOUND_ROTATE


def _wrap(angle: float) -> float:
    return float((angle + np.pi) % (2.0 * np.pi) - np.pi)


def other_branch(q6: np.ndarray) -> np.ndarray:
    """The same tool orientation on the wrist's other branch: roll and rotate by pi, wrist angle negated.

    The ViperX's wrist axes do not quite meet, so the tool lands a few millimetres off the
    original's: :func:`unflipped_solution` refines it.
    """
    q = np.array(q6, dtype=float)
    q[3], q[4], q[5] = _wrap(q[3] + np.pi), -q[4], _wrap(q[5] + np.pi)
    return q


def unflipped_solution(robot: RobotController, arm: str, pose: PoseTarget, start: np.ndarray | None = None) -> np.ndarray | None:
    """Joints that put ``arm``'s tool at ``pose`` on the unflipped branch, or None.

    A scratch IK from ``start``, and where that one leap stalls, along the straight line from
    the tool's pose there (as the live IK goes); a flipped result is carried to the other
    branch and refined there (a solve from that start stays on its branch).

    Args:
        robot: The robot (its live configuration is read, not changed).
        arm: ``left`` or ``right``.
        pose: The tool pose.
        start: The full configuration (IK model layout) to solve from; the live one by default.
    """
    ik = robot.scratch_ik()
    q_full = robot.ik.configuration.q.copy() if start is None else np.asarray(start, dtype=float)
    q6 = solve_from_scratch(ik, q_full, arm, [pose])
    if q6 is None:
        ik.reset(q_full)
        q6 = solve_from_scratch(ik, q_full, arm, line_poses(ik.tcp_pose(arm), pose, np.arange(1, LINE_WAYPOINTS + 1) / LINE_WAYPOINTS), from_home=False)
    if q6 is None or not is_flipped(q6):
        return q6
    mirrored = other_branch(q6)
    lower, upper = _arm_range(ik, arm)
    if np.any(mirrored < lower) or np.any(mirrored > upper):
        return None
    ik.reset(q_full)
    ik.set_arm_q(arm, mirrored)
    refined = solve_from_scratch(ik, ik.configuration.q.copy(), arm, [pose], from_home=False)
    return None if refined is None or is_flipped(refined) else refined


def _arm_range(ik: BimanualIK, arm: str) -> tuple[np.ndarray, np.ndarray]:
    model = ik.model
    ranges = np.array([model.joint(f"{ARM_PREFIX[arm]}/{name}").range for name in ARM_JOINTS])
    return ranges[:, 0], ranges[:, 1]


def _with_arm(robot: RobotController, arm: str, q6: np.ndarray) -> np.ndarray:
    """The live full configuration with ``arm``'s joints replaced (a scratch solve's start)."""
    ik = robot.scratch_ik()
    ik.reset(robot.ik.configuration.q.copy())
    ik.set_arm_q(arm, q6)
    return ik.configuration.q.copy()


@dataclass(frozen=True)
class UnflippedFallenGrasp:
    """A fallen grasp's moves on the unflipped branch, planned before the hand moves.

    Attributes:
        above: The arm's joints with the empty hand over the object (a tool pointing down).
        rise: How much higher (m) than asked the object is lifted for its turn upright, so the
            joint-space turn's dip keeps it clear of the table.
    """

    above: np.ndarray
    rise: float


def plan_unflipped_fallen_grasp(
    robot: RobotController, arm: str, obj: str, pre: PoseTarget, grasp: PoseTarget, above_rise: float,
    lifted: PoseTarget, upright: np.ndarray, held: np.ndarray, radius: float,
) -> UnflippedFallenGrasp | None:
    """Plan the fallen grasp on the unflipped branch, or None where some move of it is not clear.

    The empty hand goes ``above_rise`` over the pre-grasp ``pre`` in joint space (its tool path
    no lower than ``pre``: the straight approach goes no lower, and below it the fingers could
    sweep into what stands beside the object), comes down to ``grasp`` on the same branch (near
    the arm's own base that branch may not reach down), is lifted to ``lifted`` (raised further
    by the plan's ``rise``) and turned there to ``upright`` in joint space (the object kept
    :data:`TURN_TABLE_CLEARANCE` clear of the table). No joint-space move may pass the other arm
    where it stands now, nor sweep the open fingers (or, turning, the object) into a neighbour.

    Args:
        robot: The robot (read only).
        arm: The grasping arm.
        obj: The fallen object.
        pre: The pre-grasp pose over the object.
        grasp: The grasp pose.
        above_rise: How far (m) over ``pre`` the joint-space move ends.
        lifted: The tool pose once the object is grasped and lifted (the grasp's rotation).
        upright: The tool rotation that holds the object upright.
        held: The object's axis ends (2 x 3, m) in the tool frame of the grasp.
        radius: The object's radius (m).
    """
    above = PoseTarget(pos=pre.pos + np.array([0.0, 0.0, above_rise]), quat=pre.quat)
    q_above = unflipped_solution(robot, arm, above)
    if q_above is None:
        return None
    approach = joint_path(robot, arm, q_above)
    if approach.clearance < PATH_CLEARANCE or approach.lowest_tool < float(pre.pos[2]):
        return None
    if swept_hits(robot.frame, obj, list(approach.tool_poses)):
        return None
    q_grasp = solve_from_scratch(robot.scratch_ik(), _with_arm(robot, arm, q_above), arm, [pre, grasp], from_home=False)
    if q_grasp is None or is_flipped(q_grasp):
        return None
    rise = 0.0
    for _ in range(2):
        lift = PoseTarget(pos=lifted.pos + np.array([0.0, 0.0, rise]), quat=lifted.quat)
        q_lift = unflipped_solution(robot, arm, lift, start=_with_arm(robot, arm, q_grasp))
        if q_lift is None:
            return None
        turned = pose_from_matrix(lift.pos, upright)
        q_turned = unflipped_solution(robot, arm, turned, start=_with_arm(robot, arm, q_lift))
        if q_turned is None:
            return None
        turn = joint_path(robot, arm, q_turned, held=held, q_start=q_lift)
        if turn.clearance < PATH_CLEARANCE or swept_hits(robot.frame, obj, list(turn.tool_poses), _along(held), radius):
            return None
        deficit = radius + TURN_TABLE_CLEARANCE - turn.lowest_held
        if deficit <= 0.0:
            return UnflippedFallenGrasp(above=q_above, rise=rise)
        rise += deficit + 0.005
    return None


def _along(ends: np.ndarray, count: int = 5) -> np.ndarray:
    """``count`` points from one end of a held object's axis to the other (tool frame)."""
    return ends[0] + np.linspace(0.0, 1.0, count)[:, None] * (ends[1] - ends[0])


def move_above(robot: RobotController, arm: str, plan: UnflippedFallenGrasp) -> Iterator[None]:
    """The plan's joint-space move of the empty hand over the object."""
    yield from move_joints(robot, arm, plan.above, speed=EMPTY_HAND_JOINT_SPEED)
    robot.set_pose(arm, robot.ik.tcp_pose(arm))


def turn_unflipped(robot: RobotController, arm: str, obj: str, upright: np.ndarray) -> Generator[None, None, bool]:
    """Turn the held ``obj`` upright where the tool is, by a joint-space move on the unflipped branch.

    Checked again as the hand is now (the hold, the other arm): where the arm came to be
    flipped, no unflipped solution exists, the move would pass the other arm or bring the
    object within :data:`TURN_TABLE_CLEARANCE` of the table, nothing moves.

    Returns:
        Whether it turned.
    """
    if is_flipped(robot.ik.arm_q(arm)):
        return False
    frame = robot.frame
    feats = frame.objects[obj]
    measured = quat_to_rotation(frame.arms[arm].ee_quat).as_matrix()
    held = (np.array([feats.bottom, feats.top]) - frame.arms[arm].ee) @ measured  # in the tool frame
    goal = pose_from_matrix(robot.commanded_pose(arm).pos, upright)
    q_goal = unflipped_solution(robot, arm, goal)
    if q_goal is None:
        return False
    path = joint_path(robot, arm, q_goal, held=held)
    radius = 0.5 * float(feats.extent[0])
    if path.clearance < PATH_CLEARANCE or path.lowest_held < radius + TURN_TABLE_CLEARANCE:
        return False
    if swept_hits(frame, obj, list(path.tool_poses), _along(held), radius):
        return False
    change = np.abs(q_goal - robot.ik.arm_q(arm))
    largest = float(np.max(change))
    duration = max(largest / ANGULAR_SPEED, float(change[_WRIST_ANGLE]) / TURN_PITCH_SPEED)
    yield from move_joints(robot, arm, q_goal, speed=largest / duration if duration > 0.0 else ANGULAR_SPEED)
    robot.set_pose(arm, goal)
    return True
