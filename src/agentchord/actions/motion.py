"""Motion primitives the atomic actions are written with.

Each primitive is a generator that sets targets on the controller and yields
once per control tick, so an action script reads as a plain sequence:
``yield from move_to(robot, arm, pose)``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from agentchord.actions.base import ActionFailed
from agentchord.actions.controller import RobotController
from agentchord.actions.joint_path import joint_path
from agentchord.robot.aloha import HOME_Q, TABLE_HALF
from agentchord.solvers.ik import PoseTarget, solve_from_scratch
from agentchord.solvers.obstacles import Spheres
from agentchord.solvers.poses import (  # noqa: F401  (grasp_frame, pose_from_matrix, UP: re-exported for the actions)
    UP,
    grasp_frame,
    pose_from_matrix,
    quat_to_rotation,
    rotation_to_quat,
)

#: Cartesian speed limits of the tool (m/s, rad/s).
LINEAR_SPEED = 0.30
ANGULAR_SPEED = 1.6
#: Joint speed (rad/s, largest joint) of joint-space moves with an empty hand: twice the usual.
EMPTY_HAND_JOINT_SPEED = 2.0
#: Workspace every pose target is clipped to (m): above the table, within reach.
WORKSPACE_LOW = np.array([-TABLE_HALF[0] + 0.05, 0.22, 0.015])
WORKSPACE_HIGH = np.array([TABLE_HALF[0] - 0.05, 0.95, 0.55])


def clip_to_workspace(pos: np.ndarray) -> np.ndarray:
    """Clip a tool position to the stated workspace."""
    return np.clip(pos, WORKSPACE_LOW, WORKSPACE_HIGH)


def min_jerk(s: float) -> float:
    """Minimum-jerk time scaling of a phase in [0, 1]."""
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


def line_poses(start: PoseTarget, goal: PoseTarget, phases) -> list[PoseTarget]:
    """Poses along the straight line from ``start`` to ``goal`` at ``phases`` in [0, 1]: position
    interpolated, orientation slerped (one vectorised slerp: a call per pose cost ~10% of an episode)."""
    r0, r1 = quat_to_rotation(start.quat), quat_to_rotation(goal.quat)
    quats_xyzw = Slerp([0.0, 1.0], Rotation.concatenate([r0, r1]))(phases).as_quat()
    return [
        PoseTarget(pos=start.pos + s * (goal.pos - start.pos), quat=np.array([w, x, y, z]))
        for s, (x, y, z, w) in zip(phases, quats_xyzw)
    ]


def move_to(robot: RobotController, arm: str, goal: PoseTarget, speed: float = LINEAR_SPEED) -> Iterator[None]:
    """Move the tool to ``goal`` along a straight line, position and orientation together."""
    start = robot.commanded_pose(arm)
    goal = PoseTarget(pos=clip_to_workspace(goal.pos), quat=goal.quat)
    angle = (quat_to_rotation(start.quat).inv() * quat_to_rotation(goal.quat)).magnitude()
    distance = float(np.linalg.norm(goal.pos - start.pos))
    # Min-jerk peaks at 1.875x the mean speed: size the duration for the peak.
    ticks = max(int(np.ceil(1.875 * max(distance / speed, angle / ANGULAR_SPEED) * 50 / robot.pace)), 5)
    for pose in line_poses(start, goal, [min_jerk(k / ticks) for k in range(1, ticks + 1)]):
        robot.set_pose(arm, pose)
        yield


#: A tool farther than this (m) from an approach pose once the move ends has stalled on the way.
APPROACH_TOLERANCE = 0.015
#: Whether the open fingers pass clear of every object along sampled tool poses (position, rotation matrix).
PathClear = Callable[[list[tuple[np.ndarray, np.ndarray]]], bool]
#: The live IK's tool farther than this (m) from the line it is sent along, and lower than it by
#: at least ``LINE_LOST_BELOW``, has lost it: a wrist joint at its limit, the IK trades the tool's
#: position for its turn, down towards the table. (Lagging above or beside the line, it is only
#: slow: re-planned approaches lag up to 6 cm, above the line, and catch up.)
LINE_LOST = 0.03
LINE_LOST_BELOW = 0.01


def _follow_line(robot: RobotController, arm: str, goal: PoseTarget, speed: float) -> Iterator[None]:
    """:func:`move_to`, stopped where the live IK loses the line; returns whether it did."""
    for _ in move_to(robot, arm, goal, speed=speed):
        yield
        off = robot.ik.tcp_pose(arm).pos - robot.commanded_pose(arm).pos
        if float(np.linalg.norm(off)) > LINE_LOST and off[2] < -LINE_LOST_BELOW:
            return True
    return False


def approach(
    robot: RobotController, arm: str, goal: PoseTarget, speed: float = LINEAR_SPEED, settle_ticks: int = 60,
    then: PoseTarget | None = None, clear: PathClear | None = None,
) -> Iterator[None]:
    """Move the tool to ``goal`` in a straight line; where it stalls, go round through home.

    The live IK follows the straight line a few iterations per tick and can stall in a local
    minimum (a joint limit) short of a pose that is reachable (an object pushed or set down
    beside the arm's own base). When a scratch IK from the current configuration stalls too
    but one from home reaches the pose, the arm goes there in joint space: back to home first,
    so the detour starts from a posture clear of the table. Otherwise nothing more happens
    here: the action's own checks judge the pose as they always did.

    The live IK can also lose the line on the way: a wrist joint at its limit, it trades the tool's
    position for its turn, and the tool leaves the line, down towards the table. The line then
    stops as soon as the tool is :data:`LINE_LOST` off it and :data:`LINE_LOST_BELOW` under it,
    and the same detour is taken where ``clear`` passes both of its joint-space moves (else the
    line goes on, as it always did).

    The same detour is taken where ``goal`` is reached on a wrist branch from which ``then``
    (the grasp point the tool moves to next, in a straight line) is not, but from home's branch
    it is: a block set down 26 cm from the right shoulder was approached with the wrist wound,
    and the line to the grasp point stalled at the pre-grasp, 7.5 cm short.

    Args:
        robot: The robot.
        arm: The arm.
        goal: The tool pose.
        speed: Straight-line speed (m/s).
        settle_ticks: Ticks the IK gets to converge at the end of the line (a tool turning
            its forearm roll needs many) before it counts as stalled.
        then: The pose the next straight move goes to from ``goal`` (None: no check).
        clear: Whether a detour taken where the live IK loses the line sweeps the open fingers
            through nothing (None: not checked).
    """
    if (yield from _follow_line(robot, arm, goal, speed)):
        # Lost on the way (the wrist-rotate joint at its limit as a tilted tool turned top-down
        # over a fork on its edge: the tool 12 cm under the line, down on the fork, and the
        # arm whipped back when it broke free): through home, where the goal is reached from there.
        q_goal = solve_from_scratch(
            robot.scratch_ik(), robot.ik.configuration.q.copy(), arm, [goal] if then is None else [goal, then],
            from_current=False, joints_at=0,
        )
        if q_goal is not None and (clear is None or _detour_clear(robot, arm, q_goal, clear)):
            yield from _through_home(robot, arm, goal, q_goal, settle_ticks)
            return
        yield from move_to(robot, arm, goal, speed=speed)  # the rest of the line, as it was
    yield from settle(robot, arm, tolerance=APPROACH_TOLERANCE, max_ticks=settle_ticks)
    reached = float(np.linalg.norm(robot.frame.arms[arm].ee - goal.pos)) < APPROACH_TOLERANCE
    if reached and then is None:
        return
    ik, q = robot.scratch_ik(), robot.ik.configuration.q.copy()  # only where a check is due
    if reached:
        if solve_from_scratch(ik, q, arm, [then], from_home=False) is not None:
            return
        q_goal = solve_from_scratch(ik, q, arm, [goal, then], from_current=False, joints_at=0)
    else:
        if solve_from_scratch(ik, q, arm, [goal], from_home=False) is not None:
            return  # slow, not stalled
        q_goal = solve_from_scratch(ik, q, arm, [goal], from_current=False)
    if q_goal is not None:
        yield from _through_home(robot, arm, goal, q_goal, settle_ticks)


def _detour_clear(
    robot: RobotController, arm: str, q_goal: np.ndarray, clear: PathClear
) -> bool:
    """Whether both joint-space moves of the detour, home and on to ``q_goal``, pass ``clear``."""
    home = joint_path(robot, arm, HOME_Q)
    return clear(list(home.tool_poses)) and clear(list(joint_path(robot, arm, q_goal, q_start=HOME_Q).tool_poses))


def _through_home(robot: RobotController, arm: str, goal: PoseTarget, q_goal: np.ndarray, settle_ticks: int) -> Iterator[None]:
    """The approach's detour: home, then to ``q_goal`` (the joints at ``goal``), in joint space."""
    # The hand is empty (it is on its way to grasp).
    yield from move_joints(robot, arm, HOME_Q, speed=EMPTY_HAND_JOINT_SPEED)
    yield from move_joints(robot, arm, q_goal, speed=EMPTY_HAND_JOINT_SPEED)
    robot.set_pose(arm, goal)
    yield from settle(robot, arm, tolerance=APPROACH_TOLERANCE, max_ticks=settle_ticks)


#: Receding-horizon path following: waypoints planned per solve, executed before re-solving.
PATH_HORIZON = 20
PATH_EXECUTE = 5
#: Longest tool move per tick on a solved path (m): the linear speed limit.
PATH_STEP = LINEAR_SPEED / 50.0
#: Solves before a solved path gives up and finishes with a straight move.
PATH_MAX_SOLVES = 120


def move_along_solved_path(
    robot: RobotController, arm: str, goal: PoseTarget, avoid: Callable[[], tuple[Spheres, Spheres]]
) -> Iterator[None]:
    """Move the tool to ``goal`` along a path re-planned every few ticks (paper Eq. 10).

    Every ``PATH_EXECUTE`` ticks the receding-horizon solver plans ``PATH_HORIZON`` waypoints
    from the commanded tool position on the latest frame (``avoid()`` returns the obstacle
    spheres and what the tool carries), warm-started from the last plan; the orientation
    turns toward the goal's in step with the distance covered. The last centimetres are a
    straight move, so the pose at the end is exactly ``goal``.
    """
    from agentchord.solvers.path import RecedingHorizonPathSolver  # scipy only when used

    start = robot.commanded_pose(arm)
    goal_pos = clip_to_workspace(goal.pos)
    total = max(float(np.linalg.norm(goal_pos - start.pos)), 1e-6)
    slerp = Slerp([0.0, 1.0], Rotation.concatenate([quat_to_rotation(start.quat), quat_to_rotation(goal.quat)]))
    warm = None
    previous = start.pos
    for _ in range(PATH_MAX_SOLVES):
        current = robot.commanded_pose(arm).pos
        if float(np.linalg.norm(goal_pos - current)) < 2 * PATH_STEP:
            break
        obstacles, held = avoid()
        solver = RecedingHorizonPathSolver(PATH_HORIZON, PATH_EXECUTE, step=PATH_STEP, arm=arm, held=held)
        plan = solver.step(current, goal_pos, obstacles, warm=warm, previous=previous)
        robot.path_solves.append(plan.seconds)
        for waypoint in plan.waypoints[:PATH_EXECUTE]:
            previous = robot.commanded_pose(arm).pos
            done = 1.0 - min(1.0, float(np.linalg.norm(goal_pos - waypoint)) / total)
            robot.set_pose(arm, PoseTarget(pos=waypoint, quat=rotation_to_quat(slerp(done))))
            yield
        warm = plan
    yield from move_to(robot, arm, PoseTarget(pos=goal_pos, quat=goal.quat), speed=0.15)


def settle(
    robot: RobotController, arm: str, tolerance: float = 0.004, max_ticks: int = 20, required: float | None = None
) -> Iterator[None]:
    """Hold the target until the measured tool is within ``tolerance`` (or time runs out).

    Raises:
        ActionFailed: If ``required`` is given and the tool ends farther than
            that from its target (the target is out of reach).
    """
    target = robot.commanded_pose(arm).pos
    for _ in range(max_ticks):
        if np.linalg.norm(robot.frame.arms[arm].ee - target) < tolerance:
            return
        yield
    error = float(np.linalg.norm(robot.frame.arms[arm].ee - target))
    if required is not None and error > required:
        raise ActionFailed(f"target {np.round(target, 3).tolist()} is out of reach (tool {100 * error:.1f} cm away)")


def wait_for_rest(robot: RobotController, obj: str, speed: float = 0.02, max_ticks: int = 75) -> Iterator[None]:
    """Wait until an object stops moving (a dropped bottle still rolling or falling)."""
    previous = robot.frame.objects[obj].pos.copy()
    for _ in range(max_ticks):
        yield
        current = robot.frame.objects[obj].pos
        if np.linalg.norm(current - previous) * 50.0 < speed:
            return
        previous = current.copy()


def grip(robot: RobotController, arm: str, value: float, ticks: int = 12, max_wait: int = 20) -> Iterator[None]:
    """Ramp the gripper to ``value`` (0 open, 1 closed), then wait for the fingers to stop."""
    start = robot.targets[arm].grip
    for k in range(1, ticks + 1):
        robot.set_grip(arm, start + (value - start) * k / ticks)
        yield
    previous = robot.world.gripper_width(arm)
    for _ in range(max_wait):
        yield
        width = robot.world.gripper_width(arm)
        if abs(width - previous) < 2e-4:
            break
        previous = width
    if value >= 0.5:
        robot.targets[arm].grip_closed_settled = True


def move_joints(robot: RobotController, arm: str, q_goal: np.ndarray, speed: float = 1.0) -> Iterator[None]:
    """Joint-space move at ``speed`` rad/s for the largest joint change."""
    q0 = robot.ik.arm_q(arm)
    span = float(np.max(np.abs(q_goal - q0)))
    ticks = max(int(np.ceil(1.875 * span / speed * 50 / robot.pace)), 5)
    for k in range(1, ticks + 1):
        robot.set_joints(arm, q0 + min_jerk(k / ticks) * (q_goal - q0))
        yield
