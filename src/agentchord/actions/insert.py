"""Insertion in mid-air: the held object's axis aligned with another object's opening, then pushed in.

The held object (a peg) and the host (a socket the other hand holds) are both read from the latest
frame, as they are: the peg's pose in the hand, the socket where the other arm holds it now. The
peg is first brought, turned so that its long axis lies along the socket's, ``standoff`` before
the opening; there the arm's tracking error (a few millimetres under a soft controller) is
measured and corrected -- the command moves by what the measured peg still lacks -- before the
push along the axis. A push that stops short (jammed against a rim) backs off to the standoff,
measures again and retries, a few times.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.actions import catalog
from agentchord.actions.base import ActionFailed, ArmAction
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.geometry import quat_matrix
from agentchord.actions.motion import move_to, pose_from_matrix, settle
from agentchord.features.frame import FeatureFrame, ObjectFeatures

#: Speed (m/s) of the push along the axis.
PUSH_SPEED = 0.05
#: Length (m) of each aimed step of the push.
PUSH_STEP = 0.006
#: Tries of the push before the action fails.
TRIES = 3
#: Corrections of the aligned pose (measure, move by what is missing) before each push.
CORRECTIONS = 2
#: The tip counts as in once it is this share of ``depth`` past the opening.
IN_SHARE = 0.6


def long_axis(feats: ObjectFeatures) -> tuple[np.ndarray, float]:
    """An object's longest principal axis (unit, world frame) and its length (m)."""
    rotation = quat_matrix(feats.quat)
    k = int(np.argmax(feats.extent))
    return rotation[:, k], float(feats.extent[k])


def entry(frame: FeatureFrame, obj: str, into: str) -> tuple[np.ndarray, np.ndarray]:
    """The host's opening that faces the held object: its centre, and the direction into the host."""
    host = frame.objects[into]
    axis, length = long_axis(host)
    side = 1.0 if float(np.dot(frame.objects[obj].pos - host.pos, axis)) >= 0.0 else -1.0
    return host.pos + side * 0.5 * length * axis, -side * axis


def tip_depth(frame: FeatureFrame, obj: str, into: str) -> float:
    """How far (m) the held object's leading tip is past the host's opening (negative: short of it)."""
    opening, inward = entry(frame, obj, into)
    axis, length = long_axis(frame.objects[obj])
    centre = frame.objects[obj].pos
    tip = centre + 0.5 * length * (axis if float(np.dot(axis, inward)) > 0.0 else -axis)
    return float(np.dot(tip - opening, inward))


def _frame(robot: RobotController) -> FeatureFrame:
    if robot.frame is None:
        raise ActionFailed("no observation yet: the insertion measures the poses it aims from")
    return robot.frame


class Insert(ArmAction):
    """Insert the held object into another object's opening, in the air (see the module)."""

    name = "insert"
    args: catalog.InsertArgs

    def script(self, robot: RobotController) -> Iterator[None]:
        arm, obj, into = self.arm, self.args.obj, self.args.into
        for _ in range(TRIES):
            if not _frame(robot).is_holding(arm, obj):
                raise ActionFailed(f"{obj} is not held by the {arm} arm")
            for _ in range(CORRECTIONS + 1):
                yield from move_to(robot, arm, self._tool_goal(robot, -self.args.standoff))
                yield from settle(robot, arm, tolerance=0.002, max_ticks=15)
            # The push in short steps, each aimed anew from the latest measurement (the soft arm drifts
            # off the axis as it moves, and the host yields under contact). Slow whatever the pace.
            speed = PUSH_SPEED / robot.pace
            for depth in np.arange(-self.args.standoff + PUSH_STEP, self.args.depth + 1e-9, PUSH_STEP):
                yield from move_to(robot, arm, self._tool_goal(robot, float(depth)), speed=speed)
            yield from settle(robot, arm, tolerance=0.002, max_ticks=10)
            if tip_depth(_frame(robot), obj, into) >= IN_SHARE * self.args.depth:
                return
            yield from move_to(robot, arm, self._tool_goal(robot, -self.args.standoff), speed=speed)
        raise ActionFailed(f"{obj} did not go into {into}: its tip stopped {100 * tip_depth(_frame(robot), obj, into):.1f} cm past the opening")

    def _tool_goal(self, robot: RobotController, depth: float):
        """The tool command that puts the held object's tip ``depth`` past the opening (negative: before
        it), its axis along the host's; corrected by the error the measured pose shows now."""
        frame, arm = _frame(robot), self.arm
        opening, inward = entry(frame, self.args.obj, self.args.into)
        feats = frame.objects[self.args.obj]
        axis, length = long_axis(feats)
        leading = axis if float(np.dot(axis, inward)) > 0.0 else -axis
        turn = Rotation.align_vectors([inward], [leading])[0].as_matrix()
        centre_goal = opening + (depth - 0.5 * length) * inward
        measured_pos = frame.arms[arm].ee
        tool_goal = centre_goal + turn @ (measured_pos - feats.pos)
        # The arm tracks its command with an offset (a soft controller): command what the measured
        # tool lacks, on top of the command it tracks now.
        command = robot.commanded_pose(arm)
        offset = command.pos - measured_pos
        return pose_from_matrix(tool_goal + offset, turn @ robot.rotation(arm))
