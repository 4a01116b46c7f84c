"""A person's hand: carries an object out of the gripper and sets it down, physically."""

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.sim.hand import min_jerk, set_down_path
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


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


def test_out_of_a_moving_gripper_the_object_is_held_clear_of_it_until_it_stops():
    # The arm carries on while a person pulls (a baseline that does not stop): the out-of-the-fingers
    # segment follows the gripper, and the carry waits while the gripper still moves, so the arm does
    # not run into the object again.
    from agentchord.sim.hand import OUT_S, PersonHand

    world = _world()
    body = world.model.body("bottle").id
    pos, matrix = world.object_pose("bottle")
    gripper = {"pos": pos - np.array([0.0, 0.03, 0.0])}
    path = set_down_path(pos, Rotation.from_matrix(matrix), np.array([0.0, 1.0, 0.0]), np.array([0.1, 0.7]), 0.1, Rotation.identity())
    def tool():
        return gripper["pos"].copy(), np.eye(3)

    hand = PersonHand(world.model, world.data, body, path, tool=tool)
    dt, moving_until = 0.002, OUT_S + 0.4
    offsets, elapsed = [], 0.0
    while elapsed < moving_until:
        gripper["pos"] = gripper["pos"] + np.array([0.0, 0.2 * dt, 0.0])  # 0.2 m/s along the pull
        hand.apply(dt)
        offsets.append(hand._reference(tool())[0] - gripper["pos"])
        elapsed += dt
    # Out of the fingers: 10 cm beyond where it was held, in the moving gripper's frame; then held there.
    assert np.allclose(offsets[-1], offsets[int(OUT_S / dt) + 5], atol=1e-3)
    assert abs(offsets[-1][1] - (0.03 + 0.10)) < 1e-3
    assert hand._t <= OUT_S + 1e-9
    # The gripper stops: the carry goes on, along the world's path from where the object was held.
    for _ in range(int(2.0 / dt)):
        hand.apply(dt)
    assert hand.done


def test_a_gripper_that_never_stops_is_waited_for_at_most_the_stated_time():
    from agentchord.sim.hand import MAX_CLEAR_HOLD_S, PersonHand

    world = _world()
    pos, matrix = world.object_pose("bottle")
    gripper = {"pos": pos.copy()}
    path = set_down_path(pos, Rotation.from_matrix(matrix), np.array([0.0, 1.0, 0.0]), np.array([0.1, 0.7]), 0.1, Rotation.identity())
    hand = PersonHand(world.model, world.data, world.model.body("bottle").id, path, tool=lambda: (gripper["pos"].copy(), np.eye(3)))
    dt, elapsed = 0.002, 0.0
    while not hand.done and elapsed < 10.0:
        gripper["pos"] = gripper["pos"] + np.array([0.2 * dt, 0.0, 0.0])
        hand.apply(dt)
        elapsed += dt
    assert hand.done
    assert abs(elapsed - (hand.duration + MAX_CLEAR_HOLD_S)) < 0.01


def test_a_carry_with_something_in_the_way_lifts_over_it_and_one_without_goes_straight():
    from agentchord.sim.hand import RISE_S

    pos, start = np.array([0.1, 0.5, 0.1]), Rotation.identity()
    args = (pos, start, np.array([0.0, 1.0, 0.0]), np.array([-0.2, 0.7]), 0.05, Rotation.identity())
    straight = set_down_path(*args)
    assert [w.seconds for w in straight] == [0.3, 0.9, 0.3, 0.3]
    # Lower than both ends of the carry: nothing changes.
    assert [tuple(w.pos) for w in set_down_path(*args, over=0.09)] == [tuple(w.pos) for w in straight]
    lifted = set_down_path(*args, over=0.25)
    assert len(lifted) == len(straight) + 2
    up, across, down = lifted[1:4]
    assert np.allclose(up.pos, [straight[0].pos[0], straight[0].pos[1], 0.25]) and up.seconds == RISE_S
    assert np.allclose(across.pos, [-0.2, 0.7, 0.25])
    assert np.allclose(down.pos, straight[1].pos)  # then down over the spot, as before
    assert np.allclose(lifted[-1].pos, straight[-1].pos)
