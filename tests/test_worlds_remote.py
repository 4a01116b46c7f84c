"""A world in another process: the wire format, the server, the client, same seed same episode."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

from agentchord.cli import main
from agentchord.execution.episode import EpisodeSpec, run_episode
from agentchord.execution.executor import ExecutorConfig
from agentchord.features.oracle import OracleExtractor
from agentchord.worlds.protocol import ArmCommand, GroundTruthWorld, World
from agentchord.worlds.remote import RemoteWorld, RemoteWorldError, check_address
from agentchord.worlds.sim.disturbances import ScriptedDisturbance
from agentchord.worlds.sim.serve import WorldServer, serve_in_thread
from agentchord.worlds.sim.trial import open_world
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
    assert server.handle({"op": "open", "seed": 1})["ok"] is True
    assert "unknown simulator call" in server.handle({"op": "sim", "method": "reset"})["error"]
    assert "6 joint targets" in server.handle({"op": "step", "commands": {"left": {"q": [0.0], "grip": 0.0}}})["error"]


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
    ("single_arm_pour_water", 3, {"p": 0.1}),
    ("handover_block", 2, {"protocol": True, "disturb": ("perturb", "pull")}),
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
