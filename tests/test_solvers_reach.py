"""The reach shell of each arm: constants that match the robot model and its IK."""

import mujoco
import numpy as np
import pytest

from agentchord.actions.motion import grasp_frame, pose_from_matrix
from agentchord.solvers.ik import BimanualIK
from agentchord.solvers.reach import REACH, REACH_MAX, REACH_MIN, SHOULDER, ReachModel, measure_reach
from agentchord.robot.aloha import ARM_PREFIX
from agentchord.robot.model import build_robot_model


def test_shoulder_constants_match_the_robot_model():
    model = build_robot_model()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for arm, prefix in ARM_PREFIX.items():
        assert data.xpos[model.body(f"{prefix}/upper_arm_link").id] == pytest.approx(SHOULDER[arm], abs=1e-5)


def test_slack_is_positive_inside_the_shell_only():
    model = ReachModel(np.zeros(3), 0.3, 0.6)
    slack = model.slack(np.array([[0.45, 0, 0], [0.2, 0, 0], [0, 0.7, 0]]))
    assert slack == pytest.approx([0.15, -0.1, -0.1])
    assert model.contains(np.array([0.0, 0.0, 0.5])) and not model.contains(np.zeros(3))
    with pytest.raises(ValueError):
        ReachModel(np.zeros(3), 0.5, 0.4)


def _ik_residual(ik: BimanualIK, home: np.ndarray, arm: str, target: np.ndarray) -> float:
    pose = pose_from_matrix(target, grasp_frame(target - REACH[arm].shoulder))
    ik.reset(home)
    for _ in range(250):
        ik.solve({arm: pose})
    return ik.residual(arm, pose)


def test_the_ik_reaches_inside_the_shell_and_not_beyond_it():
    ik = BimanualIK(iterations=1, avoid_arm_collisions=False)
    home = ik.configuration.q.copy()
    for arm, sign in (("left", 1.0), ("right", -1.0)):
        shoulder = REACH[arm].shoulder
        for radius, height in ((REACH_MIN + 0.01, 0.12), (0.5, 0.05), (REACH_MAX - 0.01, 0.3)):
            dz = height - shoulder[2]
            target = shoulder + np.array([sign * np.sqrt(radius**2 - dz**2), 0.0, dz])
            assert _ik_residual(ik, home, arm, target) < 0.003, (arm, radius, height)
        far = shoulder + np.array([sign * 0.82, 0.0, 0.25])
        assert _ik_residual(ik, home, arm, far) > 0.05


@pytest.mark.slow
def test_a_fresh_measurement_reaches_everywhere_inside_the_constants():
    r_min, r_max, rows = measure_reach("right", samples=120, seed=3)
    assert r_min <= REACH_MIN and r_max >= REACH_MAX
    inside = (rows[:, 0] >= REACH_MIN) & (rows[:, 0] <= REACH_MAX)
    assert (rows[inside, 2] < 0.003).all()
