"""Bimanual IK with mink: reaches targets, and keeps the two arms apart."""

import mujoco
import numpy as np

from agentchord.solvers.ik import BimanualIK, PoseTarget


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


def test_a_top_grasp_with_the_wrist_turned_back_is_reached_from_a_wound_wrist(monkeypatch):
    # Single-arm pour, stress seed 99: a cup knocked over lies with its top pointing back at the left
    # shoulder. Its fallen grasp comes down with the fingers' axis along the cup, towards its top: the
    # wrist turned half round. From where the arms were (the left at home, the right holding the
    # bottle up) the solver ran the waist into its limit, 25 cm off, and the cup was given up as out
    # of reach of both arms. The poses and the configuration are that episode's.
    from agentchord.solvers import ik as ik_module
    from agentchord.solvers.ik import solve_from_scratch

    ik = BimanualIK(iterations=150, avoid_arm_collisions=False, converged_step=1e-4)  # the feasibility check's
    q = np.array([0.0, -0.96, 1.16, 0.0, -0.3, 0.0, 0.021, -0.021, -0.1678, 0.1023, 1.0193, 0.0, -1.1216, 0.0, 0.021, -0.021])
    quat = np.array([0.07027212982180098, 0.7036063016846196, 0.07027212982180098, -0.7036063016846196])
    point = np.array([-0.17259403601980827, 0.6004038944172435, 0.045])
    poses = [PoseTarget(point + np.array([0.0, 0.0, 0.08]), quat), PoseTarget(point, quat)]
    joints = solve_from_scratch(ik, q, "left", poses)
    assert joints is not None
    ik.reset(q)
    ik.set_arm_q("left", joints)
    assert np.linalg.norm(ik.tcp_pose("left").pos - point) < 0.01
    monkeypatch.setattr(ik_module, "WOUND_HOMES", ())
    assert solve_from_scratch(ik, q, "left", poses) is None
