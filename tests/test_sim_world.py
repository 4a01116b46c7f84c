"""The MuJoCo world: real contacts, holding from finger contacts, gripper faults."""

import numpy as np

from agentchord.sim.world import ArmCommand, SimWorld


def test_objects_rest_on_the_table_after_reset(pour_scene):
    world = SimWorld(pour_scene)
    for _ in range(50):
        world.step()
    for name in world.object_names:
        assert world.on_table(name)
        assert world.object_velocity(name) < 1e-3
        _, rot = world.object_pose(name)
        assert rot[2, 2] > 0.999  # upright


def test_closing_on_nothing_holds_nothing_and_objects_do_not_move(pour_scene):
    world = SimWorld(pour_scene)
    before = {n: world.object_pose(n)[0] for n in world.object_names}
    world.command("right", ArmCommand(q=world.arm_q("right"), grip=1.0))
    for _ in range(40):
        world.step()
    assert world.gripper_width("right") < 0.005
    assert not world.holding("right", "bottle")
    for name, pos in before.items():
        assert np.allclose(world.object_pose(name)[0], pos, atol=1e-4)


def test_gripper_fault_forces_the_fingers_open_then_control_returns(pour_scene):
    world = SimWorld(pour_scene)
    world.command("right", ArmCommand(q=world.arm_q("right"), grip=1.0))
    for _ in range(30):
        world.step()
    closed = world.gripper_width("right")
    world.inject_gripper_fault("right", ticks=10)
    for _ in range(10):
        world.step()
    assert world.gripper_width("right") > closed + 0.03
    for _ in range(30):
        world.step()
    assert world.gripper_width("right") < closed + 0.002


def test_same_commands_give_the_same_state(pour_scene):
    states = []
    for _ in range(2):
        world = SimWorld(pour_scene)
        world.command("right", ArmCommand(q=world.arm_q("right") + 0.2, grip=0.5))
        for _ in range(40):
            world.step()
        states.append(world.data.qpos.copy())
    assert np.array_equal(states[0], states[1])
