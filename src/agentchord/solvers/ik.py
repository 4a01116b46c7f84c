"""Differential inverse kinematics for both arms with mink.

The solver works on a robot-only copy of the model (no free-floating objects),
warm-started from the last commanded configuration: each control tick moves
the tool-centre targets a little, so one or two QP iterations converge.
The arms never collide: when their tools come within ``ARM_PROXIMITY`` of
each other, mink's collision-avoidance limit between the two arms' geoms joins
the QP, on capsule proxies of the distal links (cheap analytic distances).
"""

from __future__ import annotations

from dataclasses import dataclass

import daqp
import mink
import mujoco
import numpy as np

from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX, COLLISION_PROXIES, HOME_Q
from agentchord.robot.model import build_robot_model


@dataclass
class PoseTarget:
    """A tool-centre pose target: position (m) and orientation quaternion (w, x, y, z)."""

    pos: np.ndarray
    quat: np.ndarray


#: Tool-to-tool distance (m) under which arm-arm collision avoidance is active.
ARM_PROXIMITY = 0.35
#: Clearance (m) the collision-avoidance limit keeps between the arms.
ARM_CLEARANCE = 0.02
#: Levenberg-Marquardt damping of every QP (mink's ``damping``).
DAMPING = 1e-4
#: The collision proxies from this index on are the gripper's (``robot.aloha.COLLISION_PROXIES``).
HAND_PROXIES_FROM = 2
#: Whether a solver built without saying otherwise solves leanly: an arm that holds still left out of
#: the QP, and no more iterations once the arms are at their targets or a step is negligible
#: (:data:`STILL_STEP`, :data:`ARRIVED_POSITION`, :data:`LIVE_CONVERGED_STEP`). False: every
#: iteration with both arms, the solver the scenes pinned by regression tests before it were recorded with.
LEAN_SOLVES = True
#: An arm holds still when its target is the one it was solved for last tick and that solve moved
#: none of its joints more than this (rad): it is then left out of the QP (see :meth:`BimanualIK.solve`).
STILL_STEP = 1e-6
#: The live solver stops iterating once a QP step moves no joint more than this (rad; ~2 µm at the tool).
LIVE_CONVERGED_STEP = 1e-5
#: A solve stops iterating once every arm it moves is this close to its target: position (m) and
#: rotation (rad). One QP step from last tick's solution usually lands there; the next would move
#: the tool by microns.
ARRIVED_POSITION = 1e-4
ARRIVED_ROTATION = 1e-3
#: A clearance row of the IK's QP binds the solution when its slack (its bound minus the row times the
#: step, in the bound's units) is under this.
CLEARANCE_ACTIVE = 1e-9
#: DAQP's "no lower bound" on a constraint row (what qpsolvers passes for ``G x <= h``).
NO_LOWER_BOUND = -1e30


class BimanualIK:
    """Solve joint targets of both arms for tool-centre pose targets.

    Args:
        iterations: QP iterations per call (each ~0.1 ms, ~0.8 ms with collision avoidance).
        dt: Integration step of the differential IK.
        avoid_arm_collisions: Keep the two arms apart.
        converged_step: Stop before ``iterations`` once a QP step moves the joints less than
            this (rad): a scratch solve that converges in 30 of its 150 iterations (or stalls
            against a limit) costs a fifth. None: :data:`LIVE_CONVERGED_STEP` when lean, else every iteration.
        lean: Leave an arm that holds still (:data:`STILL_STEP`) out of the QP (a tick with one arm
            moving solves that arm's six joints, a tick with none solves nothing) and stop iterating
            once every arm solved for is at its target (:data:`ARRIVED_POSITION`,
            :data:`ARRIVED_ROTATION`): a live tick then takes one QP, not two. None: :data:`LEAN_SOLVES`.
    """

    def __init__(self, iterations: int = 2, dt: float = 0.05, avoid_arm_collisions: bool = True,
                 converged_step: float | None = None, lean: bool | None = None) -> None:
        self.model = build_robot_model()
        self.configuration = mink.Configuration(self.model)
        self.iterations = iterations
        self.converged_step = converged_step
        self.dt = dt
        self.tasks = {
            arm: mink.FrameTask(frame_name=f"{arm}_tcp", frame_type="site", position_cost=1.0, orientation_cost=0.3, lm_damping=1e-3)
            for arm in ARM_PREFIX
        }
        self.posture = mink.PostureTask(self.model, cost=1e-3)
        self.limits = [mink.ConfigurationLimit(self.model)]
        self.arm_collision_limit = None
        if avoid_arm_collisions:
            # Capsule proxies around forearm, wrist and gripper (robot.aloha.COLLISION_PROXIES).
            geoms = {arm: [f"{arm}_proxy_{k}" for k in range(len(COLLISION_PROXIES))] for arm in ARM_PREFIX}
            self._proxy_pairs = [
                (self.model.geom(a).id, self.model.geom(b).id) for a in geoms["left"] for b in geoms["right"]
            ]
            self._fromto = np.zeros(6)
            self._all_pairs = self._proxy_pairs
            self.arm_collision_limit = self._whole_arms_limit = mink.CollisionAvoidanceLimit(
                self.model, [(geoms["left"], geoms["right"])],
                minimum_distance_from_collisions=ARM_CLEARANCE, collision_detection_distance=0.2, gain=0.5,
            )
            # Hand to hand (a small object passed between the grippers): the hands may meet (the
            # grippers and wrists), the forearms still keep apart.
            forearms = {arm: names[:HAND_PROXIES_FROM] for arm, names in geoms.items()}
            self._hand_to_hand_pairs = [
                (self.model.geom(a).id, self.model.geom(b).id) for a in forearms["left"] for b in forearms["right"]
            ]
            self._hand_to_hand_limit = mink.CollisionAvoidanceLimit(
                self.model, [(forearms["left"], forearms["right"])],
                minimum_distance_from_collisions=ARM_CLEARANCE, collision_detection_distance=0.2, gain=0.5,
            )
        self._hand_to_hand = False
        self._arm_qadr = {
            arm: np.array([self.model.joint(f"{prefix}/{name}").qposadr[0] for name in ARM_JOINTS])
            for arm, prefix in ARM_PREFIX.items()
        }
        self._tcp_site = {arm: self.model.site(f"{arm}_tcp").id for arm in ARM_PREFIX}
        # Per arm, the pose (quaternion and position bytes) its frame task's target was last set to.
        self._targets_set: dict[str, tuple[bytes, bytes]] = {}
        self._target_position = {arm: np.zeros(3) for arm in ARM_PREFIX}
        self._target_rotation = {arm: np.zeros(9) for arm in ARM_PREFIX}  # row-major, as MuJoCo's site_xmat
        self.lean = LEAN_SOLVES if lean is None else lean
        if converged_step is None and self.lean:
            self.converged_step = LIVE_CONVERGED_STEP
        # Arms that held still at the last solve: their target unchanged and their joints unmoved by it.
        self._still: set[str] = set()
        # What every QP shares (see _qp_velocity): the posture task's weighted Jacobian (its Jacobian
        # is the identity) and the joint limits' constraint rows, built as mink builds them.
        nv = self.model.nv
        self._posture_jacobian = self.posture.cost[:, None] * np.eye(nv)
        joint_limit = self.limits[0]
        self._limit_rows = np.vstack([joint_limit.projection_matrix, -joint_limit.projection_matrix])
        self._daqp_rows_of: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        # Every joint a hinge or a slide: mink's mj_differentiatePos of a joint limit is a difference.
        assert self.model.nq == nv and not np.isin(self.model.jnt_type, (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL)).any()
        # The same for one arm's QP: which joint-limit rows are its joints', those rows and the
        # posture Jacobian on its columns.
        self._one_arm_qp = {}
        for arm, dofs in self._arm_qadr.items():  # hinges and slides: an arm's qpos indices are its QP columns
            mask = np.isin(joint_limit.indices, dofs)
            rows = joint_limit.projection_matrix[mask][:, dofs]
            self._one_arm_qp[arm] = (mask, np.vstack([rows, -rows]), self._posture_jacobian[np.ix_(dofs, dofs)])
        q0 = self.configuration.q.copy()
        for arm in ARM_PREFIX:
            q0[self._arm_qadr[arm]] = HOME_Q
        self.reset(q0)
        # Where each arm's waist axis stands and which way its tool points at home: what
        # :meth:`aimed_home` turns the waist from.
        data = self.configuration.data
        self._shoulder = {arm: data.xpos[self.model.body(f"{prefix}/shoulder_link").id][:2].copy()
                          for arm, prefix in ARM_PREFIX.items()}
        self._home_heading = {arm: _heading(self.tcp_pose(arm).pos[:2] - self._shoulder[arm]) for arm in ARM_PREFIX}

    def reset(self, q: np.ndarray) -> None:
        """Warm start from a full robot configuration (IK model layout)."""
        self.configuration.update(q)
        self.posture.set_target(q)
        self._still.clear()

    def set_arm_q(self, arm: str, q6: np.ndarray) -> None:
        """Overwrite one arm's joints in the warm start (e.g. after a joint-space move)."""
        q = self.configuration.q.copy()
        q[self._arm_qadr[arm]] = q6
        self.configuration.update(q)
        self._still.discard(arm)

    def aimed_home(self, arm: str, point: np.ndarray) -> np.ndarray:
        """The arm's home joints with its waist turned to face ``point`` (world frame).

        A start for a scratch solve: from home itself the differential IK can swing the waist
        the long way round and stall at its limit on a top-down pose beside the arm (a fallen cup
        at 30 cm, reachable with the waist turned 0.3 rad).
        """
        q6 = HOME_Q.copy()
        turn = _heading(np.asarray(point, dtype=float)[:2] - self._shoulder[arm]) - self._home_heading[arm]
        q6[0] = HOME_Q[0] + (turn + np.pi) % (2.0 * np.pi) - np.pi
        return q6

    def arm_q(self, arm: str) -> np.ndarray:
        """The solver's current joint solution for one arm."""
        return self.configuration.q[self._arm_qadr[arm]].copy()

    @property
    def hand_to_hand(self) -> bool:
        """Whether the grippers may meet (a small object passed from hand to hand); the forearms keep apart."""
        return self._hand_to_hand

    @hand_to_hand.setter
    def hand_to_hand(self, value: bool) -> None:
        if self.arm_collision_limit is None or value == self._hand_to_hand:
            return
        self._hand_to_hand = value
        self.arm_collision_limit = self._hand_to_hand_limit if value else self._whole_arms_limit
        self._proxy_pairs = self._hand_to_hand_pairs if value else self._all_pairs

    def tcp_pose(self, arm: str) -> PoseTarget:
        """Forward kinematics of the current solution."""
        transform = self.configuration.get_transform_frame_to_world(f"{arm}_tcp", "site")
        return PoseTarget(pos=transform.translation().copy(), quat=transform.rotation().wxyz.copy())

    def solve(self, targets: dict[str, PoseTarget]) -> dict[str, np.ndarray]:
        """Move the solution toward the targets; arms without a target hold still.

        Returns:
            Joint targets (6 per arm) for every arm.
        """
        tasks, moving = [self.posture], []
        for arm, task in self.tasks.items():
            target = targets.get(arm)
            if target is None:
                # Hold: the current solution is the target.
                task.set_target_from_configuration(self.configuration)
                changed = self._targets_set.pop(arm, None) is not None
            else:
                changed = self._set_target(arm, task, target)
            if changed or arm not in self._still or not self.lean:
                tasks.append(task)
                moving.append(arm)
        if not moving:
            return {arm: self.arm_q(arm) for arm in ARM_PREFIX}
        self.posture.set_target(self.configuration.q)
        guarded = self.arm_collision_limit is not None and self.arms_close()
        # Both arms: the whole QP, every joint (the fingers' included, as mink solves it); one arm: its joints only.
        only = None if len(moving) == len(ARM_PREFIX) else moving[0]
        start = self.configuration.q.copy()
        for _ in range(self.iterations):
            velocity, held_back = self._qp_velocity(tasks, guarded, only)
            if held_back:
                # The arms' clearance stopped the moving arm: the still arm joins the QP so that both
                # make way, as the whole QP has them (alone, the moving arm's approach is slower).
                tasks, moving, only = [self.posture, *self.tasks.values()], list(self.tasks), None
                velocity, _ = self._qp_velocity(tasks, guarded, only)
            self.configuration.integrate_inplace(velocity, self.dt)
            if self.converged_step is not None and float(np.max(np.abs(velocity))) * self.dt < self.converged_step:
                break
            if self.lean and all(self._arrived(arm) for arm in moving):
                break
        if guarded and self.arm_clearance() < 0.0:
            # The linearised limit can still be stepped through when targets cross: then both
            # arms hold their last configuration rather than collide.
            self.configuration.update(start)
        moved = np.abs(self.configuration.q - start)
        self._still = {arm for arm in ARM_PREFIX if float(np.max(moved[self._arm_qadr[arm]])) < STILL_STEP}
        return {arm: self.arm_q(arm) for arm in ARM_PREFIX}

    def _set_target(self, arm: str, task: mink.FrameTask, target: PoseTarget) -> bool:
        """Set a frame task's target, unless it holds the same pose already (an arm holding still).

        Returns:
            Whether the target changed.
        """
        quat, pos = np.asarray(target.quat), np.asarray(target.pos)
        key = (quat.tobytes(), pos.tobytes())
        if self._targets_set.get(arm) == key:
            return False
        task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3(quat), pos))
        self._targets_set[arm] = key
        mujoco.mju_quat2Mat(self._target_rotation[arm], quat)
        self._target_position[arm] = pos.copy()
        return True

    def _arrived(self, arm: str) -> bool:
        """Whether the arm's tool is at its target (:data:`ARRIVED_POSITION`, :data:`ARRIVED_ROTATION`).

        An arm without a target of its own (held where it is) has arrived when nothing moved it.
        """
        if arm not in self._targets_set:
            return False
        data, site = self.configuration.data, self._tcp_site[arm]
        if float(np.linalg.norm(data.site_xpos[site] - self._target_position[arm])) > ARRIVED_POSITION:
            return False
        # The angle of R_target^T R from its trace.
        cosine = 0.5 * (float(self._target_rotation[arm] @ data.site_xmat[site]) - 1.0)
        return cosine > np.cos(ARRIVED_ROTATION)

    def _qp_velocity(self, tasks: list[mink.Task], guarded: bool, only: str | None = None) -> tuple[np.ndarray, bool]:
        """One differential-IK step: what ``mink.solve_ik(configuration, tasks, dt, solver="daqp",
        damping=DAMPING, limits=...)`` returns, bit for bit.

        mink assembles each QP through generic layers (a limits check that only logs, a
        ``qpsolvers`` problem and its dispatch), twice per tick and more than the physics costs;
        here the parts that never change are built once (``__init__``) and the rest by the same
        operations in the same order, then DAQP is called as ``qpsolvers`` calls it.
        ``tests/test_solvers_ik.py`` holds it to mink's own solve.

        Args:
            tasks: The posture task, then the frame tasks, targets set.
            guarded: Whether the arm-collision limit joins the joint limits.
            only: Solve this arm's joints alone, every other joint held (its velocity 0): the same
                QP with the other columns, their joint-limit rows and the still arm's frame task
                taken out (``tasks`` then holds only this arm's frame task).

        Returns:
            The joint velocity, and whether the arms' clearance held the one arm ``only`` solves
            back (a clearance row binds its solution; always False for the whole QP).

        Raises:
            mink.NoSolutionFound: DAQP found no solution.
        """
        configuration, posture = self.configuration, self.posture
        # The objective: mink's _compute_qp_objective with the posture task's constant Jacobian.
        error = posture.cost * (-posture.gain * posture.compute_error(configuration))
        mu_total = 0.0 + posture.lm_damping * float(error @ error)
        if only is None:
            dofs, jacobians, errors = slice(None), [self._posture_jacobian], [error]
        else:
            dofs = self._arm_qadr[only]
            limit_mask, limit_rows, posture_jacobian = self._one_arm_qp[only]
            jacobians, errors = [posture_jacobian], [error[dofs]]
        for task in tasks[1:]:
            jacobian, error, mu = task.compute_qp_residual(configuration)
            jacobians.append(jacobian[:, dofs] if only is not None else jacobian)
            errors.append(error)
            mu_total += mu
        stacked = np.vstack(jacobians)
        hessian = stacked.T @ stacked
        gradient = -(np.concatenate(errors) @ stacked)
        hessian.flat[:: hessian.shape[0] + 1] += DAMPING + mu_total
        # The inequalities: the joint limits' (ConfigurationLimit), then the arms' clearance.
        # (mink's mj_differentiatePos at dt = 1: for the robot's hinge and slide joints, a difference.)
        joint_limit, q, nv = self.limits[0], configuration.q, self.model.nv
        limited = joint_limit.indices
        upper = joint_limit.gain * (joint_limit.upper[limited] - q[limited])
        lower = joint_limit.gain * (q[limited] - joint_limit.lower[limited])
        if only is None:
            rows, bounds = self._limit_rows, np.hstack([upper, lower])
        else:
            rows, bounds = limit_rows, np.hstack([upper[limit_mask], lower[limit_mask]])
        if guarded:
            clearance = self.arm_collision_limit.compute_qp_inequalities(configuration, self.dt)
            rows, bounds = np.vstack([rows, clearance.G[:, dofs]]), np.hstack([bounds, clearance.h])
        no_lower, kinds = self._daqp_rows(bounds.size)
        step, _, exitflag, _ = daqp.solve(hessian, gradient, rows, bounds, no_lower, kinds, primal_start=None)
        if exitflag <= 0:
            raise mink.NoSolutionFound("daqp")
        if only is None:
            return step / self.dt, False
        velocity = np.zeros(nv)
        velocity[dofs] = step / self.dt
        held_back = False
        if guarded and clearance.h.size:
            slack = bounds[-clearance.h.size :] - rows[-clearance.h.size :] @ step
            held_back = bool(np.min(slack) < CLEARANCE_ACTIVE)
        return velocity, held_back

    def _daqp_rows(self, count: int) -> tuple[np.ndarray, np.ndarray]:
        """DAQP's lower bounds (none) and constraint kinds (plain inequalities) of ``count`` rows, built once per count."""
        rows = self._daqp_rows_of.get(count)
        if rows is None:
            rows = self._daqp_rows_of[count] = (np.full(count, NO_LOWER_BOUND), np.zeros(count, dtype=np.intc))
        return rows

    def whole_arm_clearance(self) -> float:
        """Smallest distance (m) between the two arms' proxies, the grippers' included even hand to hand."""
        if self.arm_collision_limit is None:
            return float("inf")
        pairs, self._proxy_pairs = self._proxy_pairs, self._all_pairs
        try:
            return self.arm_clearance()
        finally:
            self._proxy_pairs = pairs

    def arm_clearance(self) -> float:
        """Smallest distance (m) between the two arms' collision proxies (negative: overlap)."""
        data = self.configuration.data
        return min(
            mujoco.mj_geomDistance(self.model, data, a, b, 0.5, self._fromto) for a, b in self._proxy_pairs
        )

    def arms_close(self) -> bool:
        """Whether the two tools are near enough for the arms to touch."""
        xpos = self.configuration.data.site_xpos  # what tcp_pose reads, without building two poses
        return float(np.linalg.norm(xpos[self._tcp_site["left"]] - xpos[self._tcp_site["right"]])) < ARM_PROXIMITY

    def residual(self, arm: str, target: PoseTarget) -> float:
        """Position error (m) of the current solution to a target."""
        return float(np.linalg.norm(self.tcp_pose(arm).pos - target.pos))


def _heading(direction: np.ndarray) -> float:
    """Angle (rad) of a horizontal direction about the vertical, from the world's x axis."""
    return float(np.arctan2(direction[1], direction[0]))


#: Position residual (m) under which a scratch solve counts a pose as reached: the feasibility check
#: before a recovery binds and the hand-off's check of the taker's grasp use the same.
REACHED_TOLERANCE = 0.01


def solve_from_scratch(
    ik: BimanualIK, q: np.ndarray, arm: str, poses: list[PoseTarget], tolerance: float = REACHED_TOLERANCE,
    from_current: bool = True, from_home: bool = True, joints_at: int = -1,
) -> np.ndarray | None:
    """Joints that put ``arm`` at the last of ``poses``, reached through the others in order.

    Tries from the configuration ``q`` (full robot, IK model layout), then with the arm at
    home: the live solver follows straight tool lines a few iterations per tick and can stall
    against a joint limit that a solve from home goes around. Last, home with the waist turned to
    face the first pose (:meth:`BimanualIK.aimed_home`), where a solve from home itself swings the
    waist round and stalls.

    Args:
        ik: A scratch solver (many iterations per call); its state is overwritten.
        q: The robot's current configuration.
        arm: The arm.
        poses: The tool poses, in order.
        tolerance: Position residual (m) under which a pose counts as reached.
        from_current: Try the start ``q``.
        from_home: Try ``q`` with the arm at home (then aimed at the first pose).
        joints_at: Index of the pose whose joints are returned (the last by default).

    Returns:
        The arm's six joints at ``poses[joints_at]``, or None where no start reaches every pose.
    """
    starts: list[np.ndarray | None] = [None] if from_current else []
    if from_home and poses:
        starts += [HOME_Q, ik.aimed_home(arm, poses[0].pos)]
    for start in starts:
        ik.reset(q)
        if start is not None:
            ik.set_arm_q(arm, start)
        reached, joints = True, []
        for pose in poses:
            ik.solve({arm: pose})
            if ik.residual(arm, pose) >= tolerance:
                reached = False
                break
            joints.append(ik.arm_q(arm))
        if reached:
            return joints[joints_at]
    return None
