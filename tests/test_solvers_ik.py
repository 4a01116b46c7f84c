"""Bimanual IK with mink: reaches targets, and keeps the two arms apart."""

import mink
import mujoco
import numpy as np

from agentchord.solvers.ik import DAMPING, BimanualIK, PoseTarget


def _min_arm_distance(ik: BimanualIK) -> float:
    model, data = ik.model, ik.configuration.data
    ids = {arm: [i for i in range(model.ngeom) if model.geom(i).name.startswith(f"vx300s_{arm}/")
                 and not model.geom(i).name.endswith("1_base")] for arm in ("left", "right")}
    return min(mujoco.mj_geomDistance(model, data, a, b, 0.5, np.zeros(6)) for a in ids["left"] for b in ids["right"])


def _drive(ik: BimanualIK, goals: dict[str, np.ndarray], steps: int = 60) -> None:
    start = {arm: ik.tcp_pose(arm) for arm in goals}
    for k in range(steps):
        s = min(1.0, (k + 1) / (steps / 2))
        ik.solve({arm: PoseTarget(start[arm].pos + s * (goal - start[arm].pos), start[arm].quat) for arm, goal in goals.items()})


def test_reaches_a_reachable_target():
    ik = BimanualIK()
    goal = ik.tcp_pose("right").pos + np.array([-0.1, 0.05, -0.1])
    _drive(ik, {"right": goal})
    assert np.linalg.norm(ik.tcp_pose("right").pos - goal) < 0.003


class _MinkStep(BimanualIK):
    """The solver with each QP step taken by mink's own ``solve_ik`` and every target set anew: the
    reference of the lean step and of the targets kept while an arm holds still."""

    def _set_target(self, arm, task, target):
        task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3(np.asarray(target.quat)), np.asarray(target.pos)))

    def _qp_velocity(self, tasks, guarded, only=None):
        assert only is None
        limits = [*self.limits, self.arm_collision_limit] if guarded else self.limits
        return mink.solve_ik(self.configuration, tasks, self.dt, solver="daqp", damping=DAMPING, limits=limits), False


#: Every iteration, both arms in every QP: the solver as mink's own loop runs it.
_EVERY_ITERATION = dict(lean=False)


def test_the_lean_qp_step_moves_the_arms_as_mink_solve_ik_does_bit_for_bit():
    lean, reference = BimanualIK(**_EVERY_ITERATION), _MinkStep(**_EVERY_ITERATION)
    start = {arm: lean.tcp_pose(arm) for arm in ("left", "right")}
    goals = {"left": np.array([0.05, 0.5, 0.2]), "right": np.array([-0.05, 0.5, 0.2])}  # through each other
    guarded = 0
    for k in range(60):
        s = min(1.0, (k + 1) / 30)
        targets = {arm: PoseTarget(start[arm].pos + s * (goal - start[arm].pos), start[arm].quat) for arm, goal in goals.items()}
        if k % 7 == 3:
            del targets["left"]  # an arm without a target holds where it is
        guarded += lean.arms_close()
        assert all(np.array_equal(a, b) for a, b in zip(lean.solve(targets).values(), reference.solve(targets).values()))
        assert np.array_equal(lean.configuration.q, reference.configuration.q)
    assert 0 < guarded < 60  # both QPs were compared: with and without the arms' clearance rows
    # A target held for ticks (its task's target kept), then moved in place (the same arrays): set anew.
    held = {arm: PoseTarget(start[arm].pos.copy(), start[arm].quat.copy()) for arm in ("left", "right")}
    for k in range(12):
        if k == 6:
            held["right"].pos[2] += 0.02
        assert all(np.array_equal(a, b) for a, b in zip(lean.solve(held).values(), reference.solve(held).values()))
    assert np.array_equal(lean.configuration.q, reference.configuration.q)


def test_arms_sent_through_each_other_stop_short_of_colliding():
    goals = {"left": np.array([0.05, 0.5, 0.2]), "right": np.array([-0.05, 0.5, 0.2])}
    free = BimanualIK(avoid_arm_collisions=False)
    _drive(free, goals)
    assert _min_arm_distance(free) < -0.02  # without the limit the grippers interpenetrate
    guarded = BimanualIK()
    _drive(guarded, goals)
    assert _min_arm_distance(guarded) > -0.01
    assert guarded.tcp_pose("left").pos[0] < guarded.tcp_pose("right").pos[0]


def test_a_scratch_solve_from_home_reaches_what_a_stalled_start_does_not():
    from agentchord.actions.motion import grasp_frame, pose_from_matrix
    from agentchord.solvers.ik import solve_from_scratch
    from agentchord.solvers.reach import REACH

    ik = BimanualIK(iterations=150, avoid_arm_collisions=False)
    home = ik.configuration.q.copy()
    # A low side grasp beside the left arm's own base: reached with a short pre-grasp, not with the 8 cm one.
    point = np.array([-0.1, 0.57, 0.044])
    rotation = grasp_frame(point - np.r_[REACH["left"].shoulder[:2], 0.0])
    grasp = pose_from_matrix(point, rotation)
    q = solve_from_scratch(ik, home, "left", [pose_from_matrix(point - 0.04 * rotation[:, 0], rotation), grasp])
    assert q is not None
    ik.reset(home)
    ik.set_arm_q("left", q)
    assert np.linalg.norm(ik.tcp_pose("left").pos - point) < 0.01
    assert solve_from_scratch(ik, home, "left", [pose_from_matrix(point - 0.08 * rotation[:, 0], rotation), grasp]) is None
    far = PoseTarget(np.array([0.0, 2.0, 0.1]), grasp.quat)
    assert solve_from_scratch(ik, home, "left", [far]) is None
    assert solve_from_scratch(ik, home, "left", [grasp], from_current=False, from_home=False) is None


def test_a_scratch_solve_returns_the_joints_at_the_pose_asked_for():
    from agentchord.actions.motion import grasp_frame, pose_from_matrix
    from agentchord.solvers.ik import solve_from_scratch
    from agentchord.solvers.reach import REACH

    ik = BimanualIK(iterations=150, avoid_arm_collisions=False)
    home = ik.configuration.q.copy()
    point = np.array([-0.1, 0.57, 0.044])
    rotation = grasp_frame(point - np.r_[REACH["left"].shoulder[:2], 0.0])
    pre = point - 0.04 * rotation[:, 0]
    poses = [pose_from_matrix(pre, rotation), pose_from_matrix(point, rotation)]
    for index, where in ((0, pre), (-1, point)):
        q = solve_from_scratch(ik, home, "left", poses, joints_at=index)
        ik.reset(home)
        ik.set_arm_q("left", q)
        assert np.linalg.norm(ik.tcp_pose("left").pos - where) < 0.01


def test_aimed_home_turns_only_the_waist_to_face_the_point():
    from agentchord.robot.aloha import HOME_Q

    ik = BimanualIK()
    home = ik.configuration.q.copy()
    # The left arm stands at x = -0.469 facing +x, the right one at x = +0.469 facing -x (both at y = 0.5).
    cases = (("left", (0.0, 0.5), 0.0), ("left", (-0.469, 0.9), np.pi / 2), ("left", (-0.069, 0.1), -np.pi / 4),
             ("right", (0.0, 0.5), 0.0), ("right", (0.469, 0.9), -np.pi / 2), ("right", (0.069, 0.9), -np.pi / 4))
    for arm, (x, y), waist in cases:
        point = np.array([x, y, 0.1])
        q6 = ik.aimed_home(arm, point)
        assert abs(q6[0] - waist) < 1e-3, (arm, x, y, q6[0])
        assert np.allclose(q6[1:], HOME_Q[1:])
        # The tool, seen from above, now lies on the line from the waist's axis to the point.
        ik.reset(home)
        ik.set_arm_q(arm, q6)
        shoulder = np.array([-0.469 if arm == "left" else 0.469, 0.5])
        to_tool, to_point = ik.tcp_pose(arm).pos[:2] - shoulder, point[:2] - shoulder
        assert np.dot(to_tool, to_point) / np.linalg.norm(to_tool) / np.linalg.norm(to_point) > 0.9999


def test_a_scratch_solve_aimed_at_the_pose_reaches_a_top_down_grasp_a_solve_from_home_stalls_on():
    from agentchord.actions.controller import SCRATCH_IK_CONVERGED, SCRATCH_IK_ITERATIONS
    from agentchord.actions.motion import pose_from_matrix
    from agentchord.solvers.ik import solve_from_scratch
    from agentchord.solvers.poses import top_down_rotation

    ik = BimanualIK(iterations=SCRATCH_IK_ITERATIONS, converged_step=SCRATCH_IK_CONVERGED, avoid_arm_collisions=False)
    home = ik.configuration.q.copy()
    # 15 cm above the table, 37 cm from the left arm's waist: from home the solve swings the waist round.
    pose = pose_from_matrix(np.array([-0.1, 0.7, 0.15]), top_down_rotation(np.array([1.0, 0.0, 0.0])))
    ik.solve({"left": pose})
    assert ik.residual("left", pose) > 0.1
    q = solve_from_scratch(ik, home, "left", [pose])
    assert q is not None
    ik.reset(home)
    ik.set_arm_q("left", q)
    assert ik.residual("left", pose) < 0.01


def _counting_qps(ik: BimanualIK) -> list:
    calls, solve = [], ik._qp_velocity

    def counted(tasks, guarded, only=None):
        calls.append(only)
        return solve(tasks, guarded, only)

    ik._qp_velocity = counted
    return calls


def test_an_arm_that_holds_still_is_left_out_of_the_qp_and_does_not_move():
    ik = BimanualIK()
    calls = _counting_qps(ik)
    hold = ik.tcp_pose("left")
    start = ik.tcp_pose("right")
    goal = start.pos + np.array([0.1, 0.05, -0.1])  # away from the left arm: the clearance guard stays off
    for k in range(60):
        s = min(1.0, (k + 1) / 30)
        before = ik.arm_q("left")
        ik.solve({"left": hold, "right": PoseTarget(start.pos + s * (goal - start.pos), start.quat)})
        assert not ik.arms_close()
        if k >= 2:
            assert np.array_equal(ik.arm_q("left"), before)
    assert np.linalg.norm(ik.tcp_pose("right").pos - goal) < 0.003
    assert calls[0] is None and set(calls[2:]) == {"right"}  # both at first, then the right arm's joints alone


def test_a_still_arm_joins_the_qp_once_the_arms_clearance_holds_the_moving_one_back():
    ik = BimanualIK()
    calls = _counting_qps(ik)
    hold, start = ik.tcp_pose("left"), ik.tcp_pose("right")
    goal = hold.pos + np.array([0.02, 0.0, 0.0])  # the right tool driven onto the left one
    one_arm_while_guarded, left_moved = False, 0.0
    for k in range(40):
        s = min(1.0, (k + 1) / 30)
        calls.clear()
        guarded, before = ik.arms_close(), ik.arm_q("left")
        ik.solve({"left": hold, "right": PoseTarget(start.pos + s * (goal - start.pos), start.quat)})
        one_arm_while_guarded |= guarded and calls == ["right", "right"]  # near, but the limit not yet binding
        left_moved = max(left_moved, float(np.abs(ik.arm_q("left") - before).max()))
    assert one_arm_while_guarded
    assert left_moved > 0.01  # once it binds, the still arm is in the QP and makes way
    assert ik.arm_clearance() > 0.0

def test_the_one_arm_qp_moves_that_arm_as_the_whole_qp_does():
    lean, whole = BimanualIK(iterations=1), BimanualIK(iterations=1, lean=False)  # one QP a tick each
    hold = lean.tcp_pose("left")
    start = lean.tcp_pose("right")
    goal = start.pos + np.array([-0.12, 0.08, -0.12])
    for k in range(60):
        s = min(1.0, (k + 1) / 30)
        targets = {"left": hold, "right": PoseTarget(start.pos + s * (goal - start.pos), start.quat)}
        assert np.allclose(lean.solve(targets)["right"], whole.solve(targets)["right"], atol=1e-6)


def test_a_tick_whose_arms_have_arrived_solves_no_qp_and_a_small_move_takes_one():
    ik = BimanualIK()
    calls = _counting_qps(ik)
    poses = {arm: ik.tcp_pose(arm) for arm in ("left", "right")}
    for _ in range(3):
        ik.solve(poses)
    calls.clear()
    ik.solve(poses)
    assert calls == []
    nudged = PoseTarget(poses["right"].pos + np.array([0.0, 0.0, 0.001]), poses["right"].quat)
    ik.solve({"left": poses["left"], "right": nudged})
    assert calls == ["right"]
    assert ik.residual("right", nudged) < 1e-4
