"""Making way: a free arm moves out of the way of the other arm's action.

An arm standing where the other one must reach (holding a cup beside a bottle that fell against
it) holds that arm back through the IK's arm-arm collision limit. When the arm in the way runs no
action of its own in the current step (its part of the step is done), the blocked action may move
it aside: straight back towards its own shoulder, its tool's orientation kept, so whatever it holds
stays as it was held.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from agentchord.actions.controller import RobotController
from agentchord.actions.motion import move_to, settle
from agentchord.robot.aloha import other_arm
from agentchord.solvers.ik import PoseTarget

#: How far (m, horizontally) a free arm steps back towards its shoulder to make way.
STEP_BACK = 0.10
#: ... but its tool stays at least this far (m, horizontally) from the shoulder (home is ~0.27):
#: nearer, the arm folds against itself.
NEAREST_TO_SHOULDER = 0.22
#: A step back shorter than this (m) would free nothing: the arm is left where it is.
SHORTEST_STEP = 0.02


def step_back_pose(robot: RobotController, arm: str) -> PoseTarget | None:
    """Where ``arm``'s tool goes to make way: :data:`STEP_BACK` towards its shoulder, its height and
    orientation kept; None where it is already as near its shoulder as it may go."""
    start = robot.commanded_pose(arm)
    out = start.pos[:2] - robot.world.arm_base(arm)[:2]
    reach = float(np.linalg.norm(out))
    kept = max(reach - STEP_BACK, NEAREST_TO_SHOULDER)
    if reach - kept < SHORTEST_STEP:
        return None
    pos = start.pos.copy()
    pos[:2] -= (reach - kept) * out / reach
    return PoseTarget(pos=pos, quat=start.quat)


def make_way(robot: RobotController, blocked: str, back_off: PoseTarget) -> Iterator[None]:
    """Step the other arm back out of ``blocked``'s way, if it is free to move (yields per tick).

    ``blocked`` first goes to ``back_off`` (clear of the other arm: the collision limit that bent
    the other arm off its own target lets go of it there); then the other arm steps back.

    Returns (as the generator's value) whether it moved: an arm still running an action of its own,
    one already as near its shoulder as it may go, or one the collision limit holds still, is left
    where it is.
    """
    arm = other_arm(blocked)
    # Arms whose collision proxies already overlap (a bottle caught on the hand at home, reached
    # for by the other arm) are both held still by the collision limit: no step back is followed.
    if arm not in robot.free_arms or robot.ik.arm_clearance() < 0.0:
        return False
    goal = step_back_pose(robot, arm)
    if goal is None:
        return False
    yield from move_to(robot, blocked, back_off)
    yield from settle(robot, arm)
    yield from move_to(robot, arm, goal)
    yield from settle(robot, arm)
    return True
