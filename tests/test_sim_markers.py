"""What a disturbance looks like: markers read from the wrench on an object, drawn without changing the episode."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.sim.hand import set_down_path
from agentchord.sim.markers import LINGER_TICKS, DisturbanceMarkers, read_marker
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


def _world() -> SimWorld:
    return SimWorld(SIM_TASKS["single_arm_pour_water"].sample_scene(np.random.default_rng([1, 0x5CE7E])))


def _carry(world: SimWorld) -> None:
    pos, matrix = world.object_pose("bottle")
    spec = world.object_spec("bottle")
    path = set_down_path(pos, Rotation.from_matrix(matrix), np.array([0.0, 1.0, 0.0]), np.array([-0.05, 0.75]),
                         0.5 * spec.height, Rotation.identity())
    world.hand_carry("bottle", path)


def test_nothing_acts_nothing_is_drawn():
    world = _world()
    assert read_marker(world, "bottle") is None and DisturbanceMarkers(world).update() == []


def test_a_push_at_the_foot_is_a_push_from_behind_and_a_knock_is_high():
    world = _world()
    pos = world.object_pose("cup")[0]
    world.push("cup", np.array([0.0, 2.0, 0.0]), ticks=5)
    push = read_marker(world, "cup")
    assert push is not None and push.kind == "push" and np.allclose(push.direction, [0.0, 1.0, 0.0])
    assert push.contact[1] < pos[1] and push.contact[2] < pos[2]  # behind it (against the push), low
    world.knock("bottle", np.array([1.0, 0.0, 0.0]))
    knock = read_marker(world, "bottle")
    assert knock is not None and knock.kind == "knock" and knock.contact[2] > world.object_pose("bottle")[0][2]
    assert {s.kind for s in push.shapes()} == {"capsule", "ellipsoid", "arrow"}


def test_a_carrying_hand_is_over_its_object_and_leaves_a_trail():
    world = _world()
    _carry(world)
    markers = DisturbanceMarkers(world)
    for _ in range(40):
        world.step()
        markers.update()
    (hand,) = markers.markers
    pos = world.object_pose("bottle")[0]
    assert hand.kind == "hand" and hand.obj == "bottle" and hand.acting
    assert np.allclose(hand.contact[:2], pos[:2]) and hand.contact[2] > pos[2]
    assert len(markers.trails["bottle"]) >= 10
    assert any(s.rgba != hand.shapes()[0].rgba for s in markers.shapes())  # the trail's segments


def test_a_push_lingers_a_moment_then_goes():
    world = _world()
    world.push("cup", np.array([2.0, 0.0, 0.0]), ticks=3)
    markers = DisturbanceMarkers(world)
    shown = []
    for _ in range(3 + LINGER_TICKS + 5):
        shown.append([m.acting for m in markers.update()])
        world.step()
    assert shown[0] == [True] and shown[4] == [False] and shown[-1] == []


def test_filming_the_markers_changes_nothing_in_the_simulation(tmp_path):
    from agentchord.sim.render import VideoRecorder

    plain, filmed = _world(), _world()
    recorder = VideoRecorder(filmed, tmp_path / "v.mp4", size=(160, 120))
    try:
        for world in (plain, filmed):
            _carry(world)
            world.push("cup", np.array([2.0, 0.0, 0.0]), ticks=5)
        banners = []
        for tick in range(60):
            plain.step()
            filmed.step()
            recorder.capture("c")
            if tick == 0:
                recorder.announce("DISTURBANCE: pull bottle")
            banners.append(recorder.disturbance_banner())
        assert np.array_equal(plain.data.qpos, filmed.data.qpos) and np.array_equal(plain.data.qvel, filmed.data.qvel)
        # Named as announced; the push (nobody named it) by what it is, for its 5 ticks and the moment after.
        assert "DISTURBANCE: pull bottle (a person's hand" in banners[10] and "push cup (a person pushes it)" in banners[10]
        assert "push cup" not in banners[-1] and "pull bottle" in banners[-1]
    finally:
        recorder.close()


def test_the_hand_is_drawn_into_the_frame(tmp_path):
    from agentchord.sim.render import VideoRecorder

    world = _world()
    recorder = VideoRecorder(world, tmp_path / "v.mp4", every=1, size=(320, 240))
    try:
        world.step()
        recorder.capture()
        before = recorder.frames[-1]
        _carry(world)
        world.step()
        recorder.capture()
        after = recorder.frames[-1]
        # The skin-coloured hand (and the orange banner) appear; the scene barely moved in one tick.
        skin = np.all(np.abs(after[44:].astype(int) - [237, 181, 143]) < 40, axis=-1).sum()
        skin_before = np.all(np.abs(before[44:].astype(int) - [237, 181, 143]) < 40, axis=-1).sum()
        assert skin > skin_before + 100
        assert np.abs(after[42, 317].astype(int) - [255, 140, 0]).max() < 10  # the banner
    finally:
        recorder.close()


def test_the_last_frame_shows_the_outcome_held_whatever_the_tick(tmp_path):
    from agentchord.sim.render import VideoRecorder

    world = _world()
    recorder = VideoRecorder(world, tmp_path / "v.mp4", every=2, size=(160, 120))
    try:
        world.step()  # tick 1: not a filmed tick
        recorder.capture("c")
        assert recorder.frames == []
        recorder.final("node v6 (task complete)", "SUCCESS", seconds=1.0)
        assert len(recorder.frames) == 25 and all(f is recorder.frames[0] for f in recorder.frames)
        assert np.abs(recorder.frames[-1][-2, 80].astype(int) - [227, 119, 194]).max() < 10  # the outcome's band
    finally:
        recorder.close()
