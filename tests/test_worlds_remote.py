"""A world in another process: the wire format, the server, the client, same seed same episode."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import zmq
import pytest
from click.testing import CliRunner

from agentchord.harness import DisturbanceSetting
from agentchord.cli import main
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.executor import ExecutorConfig
from agentchord.features.oracle import OracleExtractor
from agentchord.worlds.protocol import ArmCommand, GroundTruthWorld, World
from agentchord.worlds.remote import RemoteWorld, RemoteWorldError, check_address
from agentchord.sim.disturbances import ScriptedDisturbance
from agentchord.sim.serve import WorldServer, serve_in_thread
from agentchord.sim.trial import open_world
from agentchord.worlds.wire import WireError, pack, unpack

TASK = "single_arm_pour_water"


@pytest.fixture(scope="module")
def server():
    address, stop, thread = serve_in_thread(TASK)
    yield address
    stop.set()
    thread.join(5)


def _comparable(result) -> dict:
    """An episode's summary and trace, less what wall-clock time decides."""
    summary = {k: v for k, v in result.summary().items() if "wall" not in k and "compute" not in k and k != "exec_time_s"}
    return {"summary": summary, "trace": result.trace.events}


# ---------------------------------------------------------------------------- wire
def test_arrays_cross_the_wire_bit_for_bit():
    rng = np.random.default_rng(0)
    message = {
        "f64": rng.standard_normal((3, 4)),
        "f32": rng.standard_normal(5).astype(np.float32),
        "i32": np.arange(-3, 3, dtype=np.int32).reshape(2, 3),
        "flags": np.array([True, False]),
        "empty": np.zeros((0, 3)),
        "nested": {"list": [1, 2.5, "x", None], "scalar": np.float64(0.1)},
    }
    back = unpack(pack(message))
    for key in ("f64", "f32", "i32", "flags", "empty"):
        assert back[key].dtype == message[key].dtype and back[key].shape == message[key].shape
        np.testing.assert_array_equal(back[key], message[key])
    assert back["nested"] == {"list": [1, 2.5, "x", None], "scalar": 0.1}


def test_garbage_is_a_wire_error():
    with pytest.raises(WireError):
        unpack(b"\xc1 not msgpack")
    with pytest.raises(WireError, match="not a map"):
        unpack(pack([1, 2]))  # type: ignore[arg-type]


def test_addresses_are_checked():
    assert check_address("tcp://127.0.0.1:5555") == "tcp://127.0.0.1:5555"
    for bad in ("127.0.0.1:5555", "tcp://host", "tcp://:5555", "tcp://h:99999", "http://h:1"):
        with pytest.raises(ValueError, match="expected tcp://HOST:PORT"):
            check_address(bad)


# ---------------------------------------------------------------------------- server
def test_the_server_answers_errors_instead_of_dying():
    server = WorldServer(TASK)
    assert server.handle({"op": "nope"}) == {"ok": False, "type": "ProtocolError",
                                             "error": "unknown op 'nope' (ops: hello, open, step, camera, sim, close)"}
    assert "no trial is open" in server.handle({"op": "step"})["error"]
    assert "this server serves 'single_arm_pour_water'" in server.handle({"op": "open", "task": "handover_block"})["error"]
    assert server.handle({"op": "open", "seed": -1})["ok"] is False
    trial = server.handle({"op": "open", "seed": 1})["trial"]
    assert "unknown simulator call" in server.handle({"op": "sim", "method": "reset", "trial": trial})["error"]
    assert "6 joint targets" in server.handle({"op": "step", "trial": trial,
                                               "commands": {"left": {"q": [0.0], "grip": 0.0}}})["error"]


def test_a_refused_trial_and_a_missing_server_are_remote_world_errors(server):
    with pytest.raises(RemoteWorldError, match="refused 'open'.*this server serves"):
        RemoteWorld(server, "handover_block", 0)
    with pytest.raises(RemoteWorldError, match="no reply from the world at tcp://127.0.0.1:9 within 0.3 s"):
        RemoteWorld("tcp://127.0.0.1:9", TASK, 0, timeout_s=0.3)


# ---------------------------------------------------------------------------- client
def test_the_remote_world_is_the_local_one_tick_for_tick(server):
    local = open_world(TASK, 5)
    with RemoteWorld(server, TASK, 5) as remote:
        assert isinstance(remote, World) and isinstance(remote, GroundTruthWorld)
        assert remote.object_names == local.object_names and remote.camera_names == local.camera_names
        assert remote.object_spec("bottle").height == local.object_spec("bottle").height
        q = local.arm_q("right") + np.array([0.2, 0.1, -0.1, 0.0, 0.1, 0.0])
        for world in (local, remote):
            world.command("right", ArmCommand(q=q, grip=0.5))
            for _ in range(20):
                world.step()
        assert remote.tick == local.tick == 20
        for arm in ("left", "right"):
            np.testing.assert_array_equal(remote.arm_q(arm), local.arm_q(arm))
            for a, b in zip(remote.tcp_pose(arm), local.tcp_pose(arm)):
                np.testing.assert_array_equal(a, b)
            assert remote.gripper_width(arm) == local.gripper_width(arm)
            np.testing.assert_array_equal(remote.arm_base(arm), local.arm_base(arm))
        for name in local.object_names:
            for a, b in zip(remote.object_pose(name), local.object_pose(name)):
                np.testing.assert_array_equal(a, b)
            assert remote.object_velocity(name) == local.object_velocity(name)
            assert remote.on_table(name) == local.on_table(name)
        assert OracleExtractor(remote).frame.holding == OracleExtractor(local).frame.holding
        remote_camera, local_camera = remote.open_camera("front", 80, 60), local.open_camera("front", 80, 60)
        try:
            a, b = remote_camera.capture(), local_camera.capture()
        finally:
            local_camera.close()
        np.testing.assert_array_equal(a.depth, b.depth)
        np.testing.assert_array_equal(a.labels, b.labels)
        np.testing.assert_array_equal(a.extrinsics, b.extrinsics)


def test_one_short_episode_is_the_same_local_and_remote(server):
    config = ExecutorConfig(tick_limit=200)

    def spec(world):  # a push during the grasp: the disturbance acts through the simulator's own calls
        disturbance = ScriptedDisturbance("grasp", kind="perturb", after=15)
        return EpisodeSpec(task=TASK, seed=4, config=config, disturbance=disturbance, world=world)

    local, remote = run_episode(spec(None)), run_episode(spec(server))
    assert any(e["event"] == "disturbance" for e in local.trace.events)
    assert _comparable(remote) == _comparable(local)


def test_run_refuses_video_and_bad_addresses_with_the_world_option(tmp_path):
    runner = CliRunner()
    result = runner.invoke(main, ["run", TASK, "--world", "localhost:5555"])
    assert result.exit_code == 2 and "expected tcp://HOST:PORT" in result.output
    result = runner.invoke(main, ["run", TASK, "--world", "tcp://127.0.0.1:9", "--video", str(tmp_path / "v.mp4")])
    assert result.exit_code == 2 and "--video" in result.output
    result = runner.invoke(main, ["demo", "--world", "tcp://127.0.0.1:9", "--workers", "2", "--trials", "1"])
    assert result.exit_code == 2 and "--workers 1" in result.output


# ---------------------------------------------------------------------------- end to end, slow
@pytest.mark.slow
@pytest.mark.parametrize(("task", "seed", "options"), [
    ("single_arm_pour_water", 3, {"disturbances": DisturbanceSetting(p=0.1)}),
    ("handover_block", 2, {"disturbances": DisturbanceSetting.from_options(disturb=("perturb", "pull"), protocol="custom")}),
])
def test_same_seed_same_episode_local_and_remote(task, seed, options):
    address, stop, thread = serve_in_thread(task)
    try:
        local = run_episode(EpisodeSpec(task=task, seed=seed, **options))
        remote = run_episode(EpisodeSpec(task=task, seed=seed, world=address, **options))
    finally:
        stop.set()
        thread.join(5)
    assert _comparable(remote) == _comparable(local)


@pytest.mark.slow
def test_agentchord_serve_and_run_with_world(tmp_path):
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    serve = subprocess.Popen([sys.executable, "-m", "agentchord.cli", "serve", "--task", TASK, "--port", "0"],
                             stdout=subprocess.PIPE, text=True, env=env)
    try:
        line = serve.stdout.readline()
        address = re.search(r"tcp://[0-9.]+:\d+", line).group(0)
        outputs = {}
        for name, extra in (("local", []), ("remote", ["--world", address])):
            path = tmp_path / f"{name}.json"
            done = subprocess.run([sys.executable, "-m", "agentchord.cli", "run", TASK, "--seed", "1", "--p", "0.1",
                                   "--json", str(path), *extra], capture_output=True, text=True, env=env, timeout=300)
            assert done.returncode in (0, 1), done.stderr
            outputs[name] = path.read_text()
    finally:
        serve.terminate()
        serve.wait(10)
    import json

    local, remote = (json.loads(outputs[n]) for n in ("local", "remote"))
    for summary in (local, remote):
        for key in [k for k in summary if "wall" in k or "compute" in k or k == "exec_time_s"]:
            del summary[key]
    assert remote == local


# ---------------------------------------------------------------------------- hardening (issue 43)
class CorruptingServer(WorldServer):
    """A world server whose replies are bent by ``corrupt(op, reply)`` (or raw bytes returned)."""

    def __init__(self, corrupt, **kwargs) -> None:
        super().__init__(TASK, **kwargs)
        self.corrupt = corrupt
        self.ticks = 0

    def handle(self, request):
        reply = super().handle(request)
        return self.corrupt(request.get("op"), reply, self)


def _serve(server):
    import threading

    stop, bound, endpoint = threading.Event(), threading.Event(), []

    def ready(address):
        endpoint.append(address)
        bound.set()

    thread = threading.Thread(target=server.serve, args=("tcp://127.0.0.1:*",), kwargs={"ready": ready, "stop": stop},
                              daemon=True)
    thread.start()
    assert bound.wait(30)
    return endpoint[0], stop, thread


class _RawReply(dict):
    """A marker: the server sends these bytes instead of a message."""


def _nan_arm_q_after(ticks):
    def corrupt(op, reply, server):
        if op == "step" and reply.get("ok") and reply["state"]["tick"] >= ticks:
            reply["state"]["arm_q"] = reply["state"]["arm_q"].copy()
            reply["state"]["arm_q"][1, 2] = np.nan
        return reply
    return corrupt


def _drop(path):
    def corrupt(op, reply, server):
        if op == "open" and reply.get("ok"):
            node = reply
            *parents, last = path.split(".")
            for key in parents:
                node = node[key]
            del node[last]
        return reply
    return corrupt


def _replace(op_name, key, value):
    def corrupt(op, reply, server):
        if op == op_name and reply.get("ok"):
            if key in reply.get("state", {}):
                reply["state"][key] = value
            else:
                reply[key] = value
        return reply
    return corrupt


@pytest.mark.parametrize(("corrupt", "message"), [
    (_drop("world.objects"), "malformed 'open' reply: world.objects: missing"),
    (_drop("world.control_hz"), "malformed 'open' reply: world.control_hz: missing"),
    (_drop("state"), "malformed 'open' reply: state: missing"),
    (_drop("trial"), "malformed 'open' reply: trial: missing"),
    (_drop("state.arm_q"), "malformed 'open' reply: state.arm_q: missing"),
    (_replace("open", "arm_q", np.zeros((2, 5))), "state.arm_q: expected shape 2x6, got 2x5"),
    (_replace("open", "arm_q", "joints"), "state.arm_q: expected ndarray or list or tuple, got str"),
    (_replace("open", "tcp_pos", np.full((2, 3), np.inf)), "state.tcp_pos: not finite (inf at index (0, 0))"),
    (_replace("open", "obj_pos", np.full((2, 3), np.nan)), "state.obj_pos: not finite (nan at index (0, 0))"),
    (_replace("open", "tick", -1), "state.tick: -1 is out of range"),
    (_replace("open", "holding", [["right", "ghost"]]), "state.holding: expected [arm, object] pairs of this scene"),
    (_replace("open", "world", [1, 2]), "malformed 'open' reply: world: expected dict, got list"),
    (_replace("open", "seed", "zero"), "malformed 'open' reply: seed: expected int, got str"),
    (lambda op, reply, server: {"result": 1} if op == "open" else reply, "malformed 'open' reply: ok: missing"),
    (lambda op, reply, server: {**reply, "ok": "yes"} if op == "open" else reply, "ok: expected true or false, got 'yes'"),
    (lambda op, reply, server: {**reply, "protocol": 99} if op == "hello" else reply, "speaks world protocol 99"),
])
def test_a_malformed_or_non_finite_reply_is_a_remote_world_error_naming_the_field(corrupt, message):
    address, stop, thread = _serve(CorruptingServer(corrupt))
    try:
        with pytest.raises(RemoteWorldError, match=re.escape(message)):
            RemoteWorld(address, TASK, 0, timeout_s=10)
    finally:
        stop.set()
        thread.join(5)


def test_a_reply_that_is_not_the_protocol_is_a_remote_world_error():
    context = zmq.Context.instance()
    socket = context.socket(zmq.REP)
    socket.setsockopt(zmq.LINGER, 0)
    port = socket.bind_to_random_port("tcp://127.0.0.1")
    import threading

    def answer():
        if socket.poll(10000):
            socket.recv()
            socket.send(b"HTTP/1.1 200 OK\r\n\r\nhello")

    thread = threading.Thread(target=answer, daemon=True)
    thread.start()
    try:
        with pytest.raises(RemoteWorldError, match="does not speak the world protocol: its reply to 'hello' is not a world-protocol message"):
            RemoteWorld(f"tcp://127.0.0.1:{port}", TASK, 0, timeout_s=10)
    finally:
        thread.join(5)
        socket.close(0)


def test_a_nan_reading_mid_episode_ends_run_with_exit_2_not_a_verdict():
    address, stop, thread = _serve(CorruptingServer(_nan_arm_q_after(30)))
    try:
        result = CliRunner().invoke(main, ["run", TASK, "--world", address])
    finally:
        stop.set()
        thread.join(5)
    assert result.exit_code == 2, result.output
    assert "malformed 'step' reply: state.arm_q: not finite (nan at index (1, 2))" in result.output
    assert "SUCCESS" not in result.output and "internal error" not in result.output


def test_a_non_finite_simulator_answer_is_refused():
    def corrupt(op, reply, server):
        if op == "sim" and reply.get("ok"):
            reply["result"] = float("nan") if isinstance(reply["result"], float) else "yes"
        return reply

    address, stop, thread = _serve(CorruptingServer(corrupt))
    try:
        with RemoteWorld(address, TASK, 0, timeout_s=10) as world:
            with pytest.raises(RemoteWorldError, match=r"malformed 'sim object_velocity' reply: result: not finite \(nan\)"):
                world.object_velocity("bottle")
            with pytest.raises(RemoteWorldError, match="malformed 'sim on_table' reply: result: expected bool, got str"):
                world.on_table("bottle")
    finally:
        stop.set()
        thread.join(5)


def test_a_second_client_is_refused_and_the_first_episode_equals_the_local_one():
    address, stop, thread = serve_in_thread(TASK)
    refused = []

    def intrude(executor):
        if executor.world.tick == 40:
            with pytest.raises(RemoteWorldError, match="this world is in use: agentchord on .* holds its trial") as info:
                RemoteWorld(address, TASK, 9, timeout_s=10)
            refused.append(str(info.value))

    try:
        config = ExecutorConfig(tick_limit=150)
        remote = run_episode(EpisodeSpec(task=TASK, seed=2, config=config, world=address), on_tick=intrude)
        local = run_episode(EpisodeSpec(task=TASK, seed=2, config=config))
        assert refused and "(seed 2)" in refused[0]
        assert _comparable(remote) == _comparable(local)
        # The first closed its trial: the world is free again.
        with RemoteWorld(address, TASK, 9, timeout_s=10) as again:
            assert again.seed == 9
    finally:
        stop.set()
        thread.join(5)


def test_the_reply_timeout_is_configurable_and_checked(monkeypatch):
    from agentchord.worlds.remote import ENV_TIMEOUT, RemoteWorldSettingError, timeout_from_env

    assert timeout_from_env({}) == 120.0
    assert timeout_from_env({ENV_TIMEOUT: "2.5"}) == 2.5
    for bad in ("abc", "nan", "inf", "-1", "0", "1e12"):
        with pytest.raises(RemoteWorldSettingError, match=re.escape(f"{ENV_TIMEOUT}={bad!r}: expected seconds")):
            timeout_from_env({ENV_TIMEOUT: bad})
    with pytest.raises(RemoteWorldSettingError, match="reply timeout must be seconds within"):
        RemoteWorld("tcp://127.0.0.1:9", TASK, 0, timeout_s=1e12)
    monkeypatch.setenv(ENV_TIMEOUT, "0.3")
    with pytest.raises(RemoteWorldError, match=r"no reply from the world at tcp://127.0.0.1:9 within 0.3 s .*AGENTCHORD_WORLD_TIMEOUT"):
        RemoteWorld("tcp://127.0.0.1:9", TASK, 0)
    monkeypatch.setenv(ENV_TIMEOUT, "1e400")
    result = CliRunner().invoke(main, ["run", TASK, "--world", "tcp://127.0.0.1:9"])
    assert result.exit_code == 2 and "AGENTCHORD_WORLD_TIMEOUT='1e400': expected seconds" in result.output


@pytest.mark.parametrize(("address", "message"), [
    ("tcp://::1:5555", "an IPv6 address goes in brackets, tcp://[::1]:5555"),
    ("tcp://[::zz]:5555", "[::zz] is not an IPv6 address"),
    ("tcp://*:5555", "'*' is not a host a client can connect to"),
    ("tcp://no-such-host.invalid:5555", "cannot resolve 'no-such-host.invalid'"),
])
def test_an_address_the_client_cannot_use_is_refused_at_once(address, message):
    import time

    start = time.monotonic()
    result = CliRunner().invoke(main, ["run", TASK, "--world", address])
    assert result.exit_code == 2 and message in result.output, result.output
    assert time.monotonic() - start < 5


def test_a_seed_the_protocol_cannot_carry_is_refused_before_anything_is_sent():
    result = CliRunner().invoke(main, ["run", TASK, "--world", "tcp://127.0.0.1:9", "--seed", str(2**64)])
    assert result.exit_code == 2, result.output
    assert "the world protocol carries seeds from 0 to 2^63 - 1" in result.output


def test_a_client_interrupted_while_waiting_for_a_reply_still_closes_its_trial():
    """Issue 58: a ``run --world`` client stopped by Ctrl-C in the middle of a request left its trial open
    (its close was sent on a REQ socket still waiting for the reply, and failed), so every other client
    was refused until the server released it (300 s)."""
    address, stop, thread = serve_in_thread(TASK)
    try:
        world = RemoteWorld(address, TASK, 0, timeout_s=10)
        world._socket.send(pack({"op": "hello"}))  # a request in flight: the socket now waits for its reply
        world.close()
        with RemoteWorld(address, TASK, 1, timeout_s=10) as other:  # the world is free again at once
            assert other.tick == 0
    finally:
        stop.set()
        thread.join(5)


def test_a_pull_on_a_served_world_is_the_same_episode_as_on_the_local_one():
    """Issue 58 (an adversarial pass): every pull over ``--world`` ended in an internal error, exit 3
    (the pull read ``half_extent_along`` of the object's model, which only the simulator's had)."""
    setting = DisturbanceSetting.from_options(protocol="real")
    address, stop, thread = serve_in_thread(TASK)
    try:
        remote = run_episode(EpisodeSpec(task=TASK, seed=1, disturbances=setting, world=address))
    finally:
        stop.set()
        thread.join(5)
    local = run_episode(EpisodeSpec(task=TASK, seed=1, disturbances=setting))
    assert "pull" in remote.disturbances and remote.success, remote.reason
    assert _comparable(remote) == _comparable(local)
