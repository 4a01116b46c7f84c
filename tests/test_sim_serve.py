"""The world server (``sim/serve.py``): one client's trial at a time, and what it is sent checked."""

from __future__ import annotations

import numpy as np
import pytest
import zmq

from agentchord.sim import serve as serve_module
from agentchord.sim.serve import MAX_CAMERAS, MAX_MESSAGE_BYTES, WorldServer, serve_in_thread
from agentchord.worlds.wire import pack, unpack

TASK = "single_arm_pour_water"


class Clock:
    """A clock the test moves."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def clock():
    return Clock()


@pytest.fixture
def server(clock):
    return WorldServer(TASK, release_after_s=60.0, clock=clock)


def _open(server, client="A", seed=0):
    reply = server.handle({"op": "open", "seed": seed, "client": client})
    assert reply["ok"], reply
    return reply["trial"]


def _home(server, trial):
    """Both arms' commands at reset (a valid step)."""
    world = server.world
    return {arm: {"q": world.commands[arm].q, "grip": world.commands[arm].grip} for arm in ("left", "right")}


def test_a_second_client_is_refused_naming_who_holds_the_world(server, clock):
    trial = _open(server, "client A")
    clock.now = 10.0
    reply = server.handle({"op": "open", "seed": 3, "client": "client B"})
    assert reply["ok"] is False and reply["type"] == "TrialBusyError"
    assert "this world is in use: client A holds its trial (seed 0), last request 10.0 s ago" in reply["error"]
    assert "released when that client closes it or after 60 s without a request" in reply["error"]
    # A's trial goes on untouched; B cannot step or close it.
    assert server.handle({"op": "step", "trial": trial, "commands": _home(server, trial)})["state"]["tick"] == 1
    for op in ({"op": "step"}, {"op": "close"}, {"op": "step", "trial": "guess"}, {"op": "camera", "name": "front"}):
        refused = server.handle(op)
        assert refused["ok"] is False and "is not open here: the world now serves client A's trial" in refused["error"]
    assert server.trial == trial and server.world.tick == 1


def test_a_closed_trial_frees_the_world_and_an_abandoned_one_is_released_after_the_stated_time(server, clock):
    trial = _open(server, "client A")
    assert server.handle({"op": "close", "trial": trial})["ok"]
    second = _open(server, "client B")
    clock.now = 59.0
    assert server.handle({"op": "open", "client": "client C"})["ok"] is False
    clock.now = 59.0 + 60.0  # B sent nothing for 60 s: abandoned
    third = _open(server, "client C")
    assert third != second
    late = server.handle({"op": "step", "trial": second, "commands": {}})
    assert late["ok"] is False and "now serves client C's trial" in late["error"]
    assert "released after 60 s without a request" in late["error"]


def test_every_request_of_the_holder_keeps_its_trial(server, clock):
    trial = _open(server)
    for t in (50.0, 100.0, 150.0):  # never 60 s idle
        clock.now = t
        assert server.handle({"op": "step", "trial": trial, "commands": {}})["ok"]
    assert server.handle({"op": "open", "client": "B"})["ok"] is False


@pytest.mark.parametrize(("command", "message"), [
    ({"q": [0.0, 0.0, float("nan"), 0.0, 0.0, 0.0], "grip": 0.0}, "right: q must be finite"),
    ({"q": [0.0, 0.0, float("inf"), 0.0, 0.0, 0.0], "grip": 0.0}, "right: q must be finite"),
    ({"q": [0.0, 0.0, 100.0, 0.0, 0.0, 0.0], "grip": 0.0}, "right: q is out of range (at most 6.28319 in magnitude)"),
    ({"q": [0.0] * 6, "grip": float("nan")}, "right: grip must be within [0, 1]"),
    ({"q": [0.0] * 6, "grip": 5.0}, "right: grip must be within [0, 1]"),
    ({"q": [0.0] * 6, "grip": "closed"}, "right: grip must be a number"),
    ({"q": ["a"] * 6, "grip": 0.0}, "right: q must be"),
    ({"q": [0.0] * 6}, "a command is a map with q (6 joint targets) and grip"),
    ([0.0] * 6, "a command is a map with q (6 joint targets) and grip"),
])
def test_a_step_with_a_bad_command_is_refused_and_changes_nothing(server, command, message):
    trial = _open(server)
    before = {arm: server.world.commands[arm] for arm in ("left", "right")}
    good = _home(server, trial)["left"]
    reply = server.handle({"op": "step", "trial": trial, "commands": {"left": good, "right": command}})
    assert reply["ok"] is False and message in reply["error"], reply
    assert server.world.tick == 0
    assert {arm: server.world.commands[arm] for arm in ("left", "right")} == before


def test_commands_must_be_a_map(server):
    trial = _open(server)
    reply = server.handle({"op": "step", "trial": trial, "commands": [1, 2]})
    assert reply["ok"] is False and "commands must be a map of arm -> {q, grip}" in reply["error"]


@pytest.mark.parametrize(("args", "message"), [
    ({"method": "push", "args": ["bottle", [float("nan"), 0.0, 0.0], 10]}, "sim push: the force must be finite"),
    ({"method": "push", "args": ["bottle", [1e9, 0.0, 0.0], 10]}, "sim push: the force is out of range"),
    ({"method": "push", "args": ["bottle", [1.0, 0.0, 0.0], 10**9]}, "sim push: ticks must be within [0, 10000]"),
    ({"method": "push", "args": ["bottle", [1.0, 0.0, 0.0], -5]}, "sim push: ticks must be within [0, 10000]"),
    ({"method": "knock", "args": ["bottle", [0.0, 0.0, 0.0]]}, "sim knock: the direction must not be zero"),
    ({"method": "inject_gripper_fault", "args": ["right", 1.5]}, "ticks must be an integer"),
    ({"method": "push", "args": [7, [1.0, 0.0, 0.0], 1]}, "the object or arm must be a name"),
    ({"method": "hand_carry", "args": ["bottle", [{"pos": [0, 0, float("inf")], "quat": [0, 0, 0, 1], "seconds": 1}]]},
     "waypoint 0 pos must be finite"),
    ({"method": "hand_carry", "args": ["bottle", [{"pos": [0, 0, 1], "quat": [0, 0, 0, 0], "seconds": 1}]]},
     "waypoint 0 quat must be a unit quaternion"),
    ({"method": "hand_carry", "args": ["bottle", [{"pos": [0, 0, 1], "quat": [0, 0, 0, 1], "seconds": 1e6}]]},
     "waypoint 0 seconds must be within [0, 60]"),
    ({"method": "hand_carry", "args": ["bottle", "nowhere"]}, "sim hand_carry takes"),
    ({"method": "touching", "args": "bottle"}, "args must be a list"),
])
def test_simulator_calls_with_bad_numbers_are_refused(server, args, message):
    trial = _open(server)
    reply = server.handle({"op": "sim", "trial": trial, **args})
    assert reply["ok"] is False and message in reply["error"], reply
    assert server.world.tick == 0


def test_camera_sizes_are_bounded_and_the_renderer_cache_too(server):
    trial = _open(server)
    for width, height, message in ((10**6, 240, "width must be within [16, 1920]"), (320, 0, "height must be within"),
                                   (320.5, 240, "width must be an integer"), (True, 240, "width must be an integer")):
        reply = server.handle({"op": "camera", "trial": trial, "name": "front", "width": width, "height": height})
        assert reply["ok"] is False and message in reply["error"], reply
    assert "no camera 'nope'" in server.handle({"op": "camera", "trial": trial, "name": "nope"})["error"]
    for k in range(MAX_CAMERAS + 4):  # a client asking for ever new sizes
        reply = server.handle({"op": "camera", "trial": trial, "name": "front", "width": 16 + 8 * k, "height": 16})
        assert reply["ok"], reply
        assert len(server._cameras) <= MAX_CAMERAS
    assert list(server._cameras)[-1] == ("front", 16 + 8 * (MAX_CAMERAS + 3), 16)


def test_an_oversized_message_is_dropped_and_the_server_keeps_serving(monkeypatch):
    monkeypatch.setattr(serve_module, "MAX_MESSAGE_BYTES", 64 * 1024)
    address, stop, thread = serve_in_thread(TASK)
    context = zmq.Context.instance()
    try:
        big = context.socket(zmq.REQ)
        big.setsockopt(zmq.LINGER, 0)
        big.connect(address)
        big.send(pack({"op": "hello", "junk": b"x" * (128 * 1024)}))
        assert big.poll(1000) == 0  # no reply: ZeroMQ dropped it unread
        big.close(0)
        small = context.socket(zmq.REQ)
        small.setsockopt(zmq.LINGER, 0)
        small.connect(address)
        small.send(pack({"op": "hello"}))
        assert small.poll(5000)
        assert unpack(small.recv())["ok"] is True
        small.close(0)
    finally:
        stop.set()
        thread.join(5)
    assert MAX_MESSAGE_BYTES >= 1024 * 1024  # the default leaves room for any request of the protocol


def test_release_after_must_be_positive():
    with pytest.raises(ValueError, match="release_after_s must be a positive number"):
        WorldServer(TASK, release_after_s=float("nan"))


def test_a_served_ipv6_world_is_reachable_in_brackets():
    from agentchord.worlds.remote import RemoteWorld

    try:
        address, stop, thread = serve_in_thread(TASK, host="::1")
    except (RuntimeError, zmq.ZMQError):
        pytest.skip("no IPv6 loopback here")
    try:
        assert address.startswith("tcp://[::1]:")
        with RemoteWorld(address, TASK, 0, timeout_s=10) as world:
            assert world.tick == 0 and np.all(np.isfinite(world.arm_q("left")))
    finally:
        stop.set()
        thread.join(5)


def test_a_released_trial_whose_successor_closed_is_named_as_released(server, clock):
    trial = _open(server, "A")
    clock.now = 100.0
    other = _open(server, "B")
    assert server.handle({"op": "close", "trial": other})["ok"]
    reply = server.handle({"op": "step", "trial": trial, "commands": {}})
    assert reply["ok"] is False
    assert f"trial {trial!r} is not open here: it was closed, or released after 60 s without a request" in reply["error"]
