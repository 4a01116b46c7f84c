"""Feasibility before motion: can the arms make the grasps an edge starts with?

Checked when a recovery edge is bound (and when a nominal edge that grasps starts),
before the robot moves: the object must still be on the table, the arm's hand free,
and the grasp's tool poses inside the arm's reach shell (``solvers.reach``) and
confirmed by the IK. An object no arm can take any more is unrecoverable: the
episode ends at once with the reason, rather than slowly after budgets run out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.actions.controller import RobotController
from agentchord.actions.library import Grasp
from agentchord.actions.catalog import GraspArgs
from agentchord.execution.edge_program import EdgeProgram
from agentchord.features.frame import ARMS, FeatureFrame
from agentchord.solvers.ik import PoseTarget, solve_from_scratch
from agentchord.solvers.reach import REACH

#: An object whose centre is this far below the table top (m) has left the table.
OFF_TABLE_Z = -0.05
#: How far (m) beyond the reach shell's outer radius a pose is ruled out by the model alone; nearer, the IK decides.
REACH_BEYOND_LIMIT = 0.12


@dataclass(frozen=True)
class GraspCheck:
    """Whether one arm can make one grasp now.

    Attributes:
        arm: The arm.
        obj: The object.
        reason: Why not; empty when it can.
    """

    arm: str
    obj: str
    reason: str = ""

    @property
    def feasible(self) -> bool:
        """Whether the grasp can be made."""
        return not self.reason


def off_table(frame: FeatureFrame, objects: list[str]) -> list[str]:
    """The rigid objects among ``objects`` that have left the table (on the floor, falling)."""
    lost = []
    for name in objects:
        feats = frame.objects.get(name)
        if feats is not None and not feats.is_point and feats.pos[2] < OFF_TABLE_Z:
            lost.append(name)
    return lost


def _both_corners(frame: FeatureFrame, held: str, wanted: str) -> bool:
    """Whether ``held`` and ``wanted`` are both a cloth's corners (point features).

    A hand pinching one corner is not busy for another: the grasp opens it first. A corner that
    slipped onto its neighbour is re-pinched with it (the left hand "held" the top-left corner the
    bottom-left one had been laid on, and its grasp of the bottom-left one was refused).
    """
    return frame.objects[held].is_point and frame.objects[wanted].is_point


def others_move_first(program: EdgeProgram, grasp: Grasp) -> bool:
    """Whether another arm acts before or with ``grasp`` (it may be moving out of the way)."""
    for step in program.steps:
        if any(action.arm != grasp.arm for action in step):
            return True
        if grasp in step:
            return False
    return False


#: Actions after which an arm's hand is (still) free for a grasp: a place sets its object down.
FREEING_ACTIONS = ("open_gripper", "back", "place")


def first_grasps(program: EdgeProgram) -> list[Grasp]:
    """The grasps made from the state at the program's start: each arm's first grasp, before which it
    only opens, goes home or sets its object down, of an object no earlier step of the program has
    handled (a hand-off sets it down for a later grasp)."""
    busy: set[str] = set()
    taken: set[str] = set()
    handled: set[str] = set()
    grasps = []
    for step in program.steps:
        for action in step:
            obj = getattr(action.args, "obj", None)
            if action.arm not in busy | taken and isinstance(action, Grasp) and obj not in handled:
                grasps.append(action)
                taken.add(action.arm)
            elif action.name not in FREEING_ACTIONS:
                busy.add(action.arm)
        handled |= {o for o in (getattr(action.args, "obj", None) for action in step) if o is not None}
    return grasps


def _acts_before(program: EdgeProgram, grasp: Grasp, arm: str, names: tuple[str, ...]) -> bool:
    """Whether ``arm`` runs one of the actions ``names`` in a step before ``grasp``'s."""
    for step in program.steps:
        if grasp in step:
            return False
        if any(action.arm == arm and action.name in names for action in step):
            return True
    return False


def releases_first(program: EdgeProgram, grasp: Grasp, arm: str) -> bool:
    """Whether ``arm`` lets go of what it holds (opens, sets it down, or goes home, which opens the
    hand) in a step before ``grasp``'s."""
    return _acts_before(program, grasp, arm, FREEING_ACTIONS)


def places_first(program: EdgeProgram, grasp: Grasp) -> bool:
    """Whether ``grasp``'s arm sets an object down earlier in the program (its hand is freed for it)."""
    return _acts_before(program, grasp, grasp.arm, ("place",))


def _frame(robot: RobotController) -> FeatureFrame:
    """The robot's latest feature frame: the executor sets it before anything is checked."""
    assert robot.frame is not None, "feasibility checked before the first feature frame"
    return robot.frame


class FeasibilityChecker:
    """Checks grasps against both arms' reach and the IK, on the robot's current state.

    Args:
        robot: The robot (its frame and commanded configuration).
    """

    def __init__(self, robot: RobotController) -> None:
        self.robot = robot

    def _ik_reaches(self, arm: str, poses: list[PoseTarget], avoid_other_arm: bool = True) -> bool:
        """Whether the IK reaches every pose (from the current configuration, else from home).

        Args:
            arm: The arm.
            poses: The poses, in order.
            avoid_other_arm: Keep clear of the other arm where it is now (unless it moves away first).
        """
        ik = self.robot.scratch_ik(avoid_other_arm)
        current = self.robot.ik.configuration.q.copy()
        return solve_from_scratch(ik, current, arm, poses) is not None

    def check_grasp(self, grasp: Grasp, *, hand_free: bool = True, confirm_ik: bool = True,
                    avoid_other_arm: bool = True) -> GraspCheck:
        """Whether ``grasp`` (bound to its arm) can be made from the current state.

        Args:
            grasp: The grasp, bound to its arm.
            hand_free: Also require the arm to hold nothing else.
            confirm_ik: Confirm a pose the reach model accepts with the IK (~10-50 ms).
            avoid_other_arm: The IK keeps clear of the other arm where it is now.
        """
        arm, obj = grasp.arm, grasp.args.obj
        frame = _frame(self.robot)
        if off_table(frame, [obj]):
            return GraspCheck(arm, obj, f"{obj} has left the table (z = {frame.objects[obj].pos[2]:.2f} m)")
        busy = sorted(o for a, o in frame.holding if a == arm and o != obj and not _both_corners(frame, o, obj))
        if hand_free and busy:
            return GraspCheck(arm, obj, f"the {arm} arm holds {', '.join(busy)}")
        if (arm, obj) in frame.holding:
            # It rests on this arm's open fingers (dropped onto them): the grasp lets it fall free
            # and takes it from there, whatever pose the IK would find for it now.
            return GraspCheck(arm, obj)
        try:
            poses = grasp.target_poses(self.robot)
        except (ValueError, FloatingPointError) as error:
            return GraspCheck(arm, obj, f"no grasp pose for {obj}: {error}")
        # The shell was measured for side grasps: it rules out only what lies far beyond its outer
        # radius; anything nearer (a top-down grasp close to the base) is for the IK to judge.
        reach = REACH[arm]
        beyond = max(float(np.linalg.norm(pose.pos - reach.shoulder)) - reach.r_max for pose in poses)
        if beyond > REACH_BEYOND_LIMIT:
            return GraspCheck(arm, obj, f"{obj} is out of the {arm} arm's reach ({100 * beyond:.0f} cm beyond its shell)")
        if confirm_ik and not self._ik_reaches(arm, poses, avoid_other_arm):
            return GraspCheck(arm, obj, f"the IK finds no {arm}-arm grasp of {obj} where it lies")
        return GraspCheck(arm, obj)

    def check_program(self, program: EdgeProgram) -> list[GraspCheck]:
        """The infeasible first grasps of ``program`` (empty: it can start)."""
        checks = (self.check_grasp(g, hand_free=not places_first(program, g), avoid_other_arm=self._other_arm_stays(program, g))
                  for g in first_grasps(program))
        return [check for check in checks if not check.feasible]

    def _other_arm_stays(self, program: EdgeProgram, grasp: Grasp) -> bool:
        """Whether the other arm stays where it is for ``grasp``: it does not act first, or it holds
        the very object and does not let it go in an earlier step (wherever it moves, the object goes
        with it).

        A bottle dropped onto the right arm's open fingers rode home on them; a re-plan's left-arm
        grasp of it there, beside the right hand, was taken as feasible (the right arm only going
        home), and the left arm was held back three times.
        """
        holders = {arm for arm, obj in _frame(self.robot).holding if arm != grasp.arm and obj == grasp.args.obj}
        keeps_it = any(not releases_first(program, grasp, arm) for arm in holders)
        return keeps_it or not others_move_first(program, grasp)

    def unreachable(self, obj: str, *, confirm_ik: bool = True) -> list[GraspCheck]:
        """Why no arm can take ``obj`` (off the table, beyond both shells); empty when some arm can.

        A busy hand does not count: an object a busy arm could reach is not beyond recovery.
        """
        # model_validate, not GraspArgs(obj=obj): mypy takes the positional Field defaults for required.
        checks = [self.check_grasp(Grasp(arm, GraspArgs.model_validate({"obj": obj})), hand_free=False, confirm_ik=confirm_ik,
                                   avoid_other_arm=False)
                  for arm in ARMS]
        return [] if any(c.feasible for c in checks) else checks

    def where(self, obj: str) -> str:
        """Where an object is, for messages: ``(x, y, z) m``."""
        x, y, z = _frame(self.robot).objects[obj].pos
        return f"({x:.2f}, {y:.2f}, {z:.2f}) m"
