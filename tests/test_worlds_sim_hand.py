"""A person's hand: carries an object out of the gripper and sets it down, physically."""

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.worlds.sim.hand import min_jerk, set_down_path
from agentchord.worlds.sim.tasks import SIM_TASKS
from agentchord.worlds.sim.world import SimWorld


def _world() -> SimWorld:
    return SimWorld(SIM_TASKS["single_arm_pour_water"].sample_scene(np.random.default_rng([1, 0x5CE7E])))


def _carry(world: SimWorld, spot, lying: bool) -> list[np.ndarray]:
    pos, matrix = world.object_pose("bottle")
    spec = world.object_spec("bottle")
    rest = Rotation.from_euler("y", 90, degrees=True) if lying else Rotation.identity()
    height = 0.5 * spec.width if lying else 0.5 * spec.height
    hand = world.hand_carry("bottle", set_down_path(pos, Rotation.from_matrix(matrix), np.array([0.0, 1.0, 0.0]),
                                                    np.asarray(spot), height, rest))
    trail = []
    for _ in range(int(hand.duration * 50) + 60):
        world.step()
        trail.append(world.object_pose("bottle")[0])
    assert not world.hand_busy
    return trail


def test_min_jerk_runs_from_zero_to_one():
    assert min_jerk(0.0) == 0.0 and min_jerk(1.0) == 1.0 and abs(min_jerk(0.5) - 0.5) < 1e-12


def test_an_object_is_set_down_upright_at_the_spot_moving_continuously():
    world = _world()
    trail = _carry(world, (-0.05, 0.75), lying=False)
    pos, matrix = world.object_pose("bottle")
    assert np.linalg.norm(pos[:2] - [-0.05, 0.75]) < 0.02
    assert matrix[2, 2] > 0.99  # upright
    steps = np.linalg.norm(np.diff(np.array(trail), axis=0), axis=1)
    assert steps.max() < 0.03  # forces, not a teleport: at most ~1.5 m/s


def test_a_tall_object_is_laid_on_its_side_and_stays_there():
    world = _world()
    _carry(world, (0.0, 0.7), lying=True)
    pos, matrix = world.object_pose("bottle")
    assert abs(matrix[2, 2]) < 0.1  # its axis is horizontal
    assert np.linalg.norm(pos[:2] - [0.0, 0.7]) < 0.05  # set down still: it did not roll away
