"""The World protocol: the simulator implements it, ground truth is asked for, camera geometry."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from agentchord.features.extractors import make_extractor
from agentchord.features.oracle import OracleExtractor
from agentchord.features.pointcloud import backproject, quat_from_matrix
from agentchord.features.rgbd import RgbdExtractor
from agentchord.worlds.protocol import (
    ArmCommand,
    CameraFrame,
    GroundTruthUnavailableError,
    GroundTruthWorld,
    World,
    require_ground_truth,
)
from agentchord.sim.world import SimWorld


class NoGroundTruth:
    """A world as a real robot's driver would give it: robot signals, no object poses."""

    def __init__(self, sim: SimWorld) -> None:
        self._sim = sim
        self.commands = sim.commands
        self.tick = sim.tick

    def __getattr__(self, name):
        if name in ("object_pose", "object_quat", "cloth_point", "cloth_radius"):
            raise AttributeError(name)
        return getattr(self._sim, name)

    time = property(lambda self: self._sim.time)
    object_names = property(lambda self: self._sim.object_names)
    cloth_point_names = property(lambda self: self._sim.cloth_point_names)
    camera_names = property(lambda self: self._sim.camera_names)

    def object_spec(self, name): return self._sim.object_spec(name)  # noqa: E704
    def command(self, arm, command): self._sim.command(arm, command)  # noqa: E704
    def step(self): self._sim.step()  # noqa: E704
    def arm_q(self, arm): return self._sim.arm_q(arm)  # noqa: E704
    def tcp_pose(self, arm): return self._sim.tcp_pose(arm)  # noqa: E704
    def gripper_width(self, arm): return self._sim.gripper_width(arm)  # noqa: E704
    def holding(self, arm, obj): return self._sim.holding(arm, obj)  # noqa: E704
    def arm_base(self, arm): return self._sim.arm_base(arm)  # noqa: E704
    def open_camera(self, name, width=320, height=240): return self._sim.open_camera(name, width, height)  # noqa: E704


@pytest.fixture
def world(pour_scene):
    return SimWorld(pour_scene)


def test_the_simulator_is_a_world_with_ground_truth(world):
    assert isinstance(world, World) and isinstance(world, GroundTruthWorld)
    assert require_ground_truth(world, "test") is world
    assert set(world.camera_names) >= {"front", "side", "top"}
    world.command("right", ArmCommand(q=world.arm_q("right"), grip=0.0))
    world.step()
    assert world.tick == 1


def test_oracle_features_on_a_world_without_ground_truth_is_a_clear_error(world):
    robot = NoGroundTruth(world)
    assert isinstance(robot, World) and not isinstance(robot, GroundTruthWorld)
    with pytest.raises(GroundTruthUnavailableError, match=r"oracle perception reads the objects' true state.*--perception rgbd"):
        OracleExtractor(robot)
    with pytest.raises(GroundTruthUnavailableError):
        make_extractor("oracle", robot, lambda arm: False)
    assert OracleExtractor.needs_ground_truth and not RgbdExtractor.needs_ground_truth


def test_rgbd_features_need_no_ground_truth(world):
    with RgbdExtractor(NoGroundTruth(world), width=160, height=120) as extractor:
        pos, _ = world.object_pose("bottle")
        assert np.linalg.norm(extractor.frame.objects["bottle"].pos - pos) < 0.005


def test_camera_frame_intrinsics_and_extrinsics_project_back_to_the_pixel(world):
    camera = world.open_camera("front", width=160, height=120)
    try:
        frame = camera.capture()
    finally:
        camera.close()
    assert isinstance(frame, CameraFrame) and frame.labels is not None and frame.labels.shape == frame.depth.shape
    rows, cols = np.array([10, 60, 100]), np.array([20, 80, 150])
    mask = np.zeros(frame.depth.shape, dtype=bool)
    mask[rows, cols] = True
    points = backproject(frame.depth, frame.fovy, frame.pos, frame.rot, mask)
    # World -> camera (x right, y up, looking along -z) -> image (u right, v down) through K.
    local = (np.linalg.inv(frame.extrinsics) @ np.c_[points, np.ones(len(points))].T)[:3]
    uvw = frame.intrinsics @ np.vstack([local[0], -local[1], -local[2]])
    np.testing.assert_allclose(uvw[0] / uvw[2], cols + 0.5, atol=1e-6)  # row-major: already in mask order
    np.testing.assert_allclose(uvw[1] / uvw[2], rows + 0.5, atol=1e-6)


def test_unknown_camera_is_a_key_error(world):
    with pytest.raises(KeyError, match="no camera 'nope'"):
        world.open_camera("nope")


def test_quat_from_matrix_is_mujocos_to_the_bit():
    rng = np.random.default_rng(0)
    mats = [Rotation.random(random_state=k).as_matrix() for k in range(500)]
    mats += [np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    mats += [m + 1e-3 * rng.standard_normal((3, 3)) for m in mats[:100]]
    for m in mats:
        expected = np.empty(4)
        mujoco.mju_mat2Quat(expected, np.ascontiguousarray(m).reshape(-1))
        np.testing.assert_array_equal(quat_from_matrix(m), expected)
