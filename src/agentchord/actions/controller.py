"""The robot controller between atomic actions and the world.

Actions set per-arm targets (a tool pose for the IK, or joint targets for a
joint-space move, and a gripper target); once per tick the controller solves
the IK for both arms together and sends joint targets to the world. The
commanded pose persists: an interrupted action leaves the arm holding still.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.features.frame import FeatureFrame
from agentchord.robot.aloha import ARM_PREFIX
from agentchord.solvers.ik import ARM_CLEARANCE, BimanualIK, PoseTarget
from agentchord.worlds.protocol import ArmCommand, World

#: QP iterations per call of a scratch (trial) IK solve.
SCRATCH_IK_ITERATIONS = 150
#: A scratch solve stops once a step moves no joint more than this (rad).
SCRATCH_IK_CONVERGED = 1e-4


@dataclass
class ArmTarget:
    """The current target of one arm.

    Attributes:
        pose: Tool-centre pose target (used when ``joints`` is None).
        joints: Joint-space target; overrides the pose for one tick.
        grip: Gripper target in [0, 1] (0 open).
        grip_closed_settled: The gripper was commanded closed and has stopped
            moving (the robot's "grasp done" signal, latched until opened).
    """

    pose: PoseTarget
    joints: np.ndarray | None = None
    grip: float = 0.0
    grip_closed_settled: bool = False


#: The grippers are apart again after a hand-off once their collision proxies are this far apart (m).
PASSING_APART = 2 * ARM_CLEARANCE


class RobotController:
    """Turns per-arm targets into joint commands every tick.

    Args:
        world: The simulated (or real) world to command.
        ik: The bimanual IK solver.
    """

    def __init__(self, world: World, ik: BimanualIK | None = None) -> None:
        self.world = world
        self.ik = ik or BimanualIK()
        self.targets: dict[str, ArmTarget] = {}
        #: The latest feature frame: what actions perceive (set by the executor each tick).
        self.frame: FeatureFrame | None = None
        #: Wall seconds of every receding-horizon path solve (for the benchmarks).
        self.path_solves: list[float] = []
        #: Arms no running action commands in the current step (set by the edge program while it
        #: updates): an action held back by one of them may move it out of its way. Empty outside a
        #: program, so an action run on its own never moves the other arm.
        self.free_arms: frozenset[str] = frozenset()
        self._scratch_ik: dict[bool, BimanualIK] = {}
        #: The object passed from hand to hand now (:meth:`pass_hand_to_hand`), if any.
        self.passing: str | None = None
        self._hands_met = False
        #: How fast the actions move, as a multiple of their speeds (2: every motion in half the time).
        self.pace = 1.0
        self.sync_from_world()

    def scratch_ik(self, avoid_other_arm: bool = True) -> BimanualIK:
        """A many-iteration IK solver for trial solves; the live solver's warm start stays untouched."""
        if avoid_other_arm not in self._scratch_ik:
            self._scratch_ik[avoid_other_arm] = BimanualIK(
                iterations=SCRATCH_IK_ITERATIONS, avoid_arm_collisions=avoid_other_arm, converged_step=SCRATCH_IK_CONVERGED,
            )
        return self._scratch_ik[avoid_other_arm]

    def sync_from_world(self) -> None:
        """Take the measured robot state as the commanded state (after a reset)."""
        q = self.ik.configuration.q.copy()
        for arm in ARM_PREFIX:
            q[self.ik._arm_qadr[arm]] = self.world.arm_q(arm)
        self.ik.reset(q)
        for arm in ARM_PREFIX:
            grip = self.world.commands[arm].grip
            self.targets[arm] = ArmTarget(pose=self.ik.tcp_pose(arm), grip=grip)

    # --------------------------------------------------------------- queries
    def commanded_pose(self, arm: str) -> PoseTarget:
        """The arm's commanded tool pose (the start of any new motion)."""
        pose = self.targets[arm].pose
        return PoseTarget(pos=pose.pos.copy(), quat=pose.quat.copy())

    def rotation(self, arm: str) -> np.ndarray:
        """Rotation matrix of the commanded tool pose."""
        w, x, y, z = self.targets[arm].pose.quat
        return Rotation.from_quat([x, y, z, w]).as_matrix()

    # ------------------------------------------------------------- commands
    def set_pose(self, arm: str, pose: PoseTarget) -> None:
        """Target a tool pose for this tick."""
        self.targets[arm].pose = pose
        self.targets[arm].joints = None

    def set_joints(self, arm: str, q: np.ndarray) -> None:
        """Target joint positions directly for this tick (joint-space moves)."""
        self.targets[arm].joints = np.asarray(q, dtype=float)

    def set_grip(self, arm: str, grip: float) -> None:
        """Gripper target in [0, 1]; opening clears the grasp-done signal."""
        target = self.targets[arm]
        if grip < target.grip or grip < 0.5:
            target.grip_closed_settled = False
        target.grip = float(np.clip(grip, 0.0, 1.0))

    def pass_hand_to_hand(self, obj: str) -> None:
        """Let the grippers meet while ``obj`` passes between them (the forearms still keep apart).

        The IK keeps its whole-arm guard off until the hands have met and parted again with ``obj``
        in one hand (or none): the giver must be free to open and withdraw from beside the taker's fingers.
        """
        self.passing = obj
        self._hands_met = False
        self.ik.hand_to_hand = True

    def end_passing(self) -> None:
        """Back to the whole-arm guard now if the grippers are apart (a hand-off given up before they met)."""
        if self.passing is not None and self.ik.whole_arm_clearance() > PASSING_APART:
            self.passing = None
            self.ik.hand_to_hand = False

    def _watch_passing(self) -> None:
        # The guard comes back once the hands have met and parted with the object in one hand.
        if self.passing is None or self.frame is None:
            return
        apart = self.ik.whole_arm_clearance() > PASSING_APART
        self._hands_met = self._hands_met or not apart
        held = sum(1 for _, name in self.frame.holding if name == self.passing)
        if self._hands_met and apart and held < 2:
            self.passing = None
            self.ik.hand_to_hand = False

    def step(self) -> None:
        """Solve the IK, send joint and gripper targets, advance the world one tick."""
        self._watch_passing()
        cartesian = {arm: t.pose for arm, t in self.targets.items() if t.joints is None}
        for arm, target in self.targets.items():
            if target.joints is not None:
                self.ik.set_arm_q(arm, target.joints)
        solution = self.ik.solve(cartesian)
        for arm, target in self.targets.items():
            if target.joints is not None:
                # Keep the pose target consistent with where the joints are sent.
                target.pose = self.ik.tcp_pose(arm)
            self.world.command(arm, ArmCommand(q=solution[arm], grip=target.grip))
        self.world.step()
