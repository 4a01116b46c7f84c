"""The simulator served in its own process: ``agentchord serve --task T --port P``.

A ZeroMQ REP socket answers one request with one reply, in the messages of
``docs/world_protocol.md`` (:mod:`agentchord.worlds.wire`): ``hello``, ``open`` (a trial:
task and seed), ``step`` (both arms' commands; the reply is the state after the tick),
``camera`` (a depth frame with its geometry and labels), ``sim`` (the simulator's own
means, which only disturbances and success checks use: forces, gripper faults, a
person's hand, contact queries) and ``close``. The client is
:class:`agentchord.worlds.remote.RemoteWorld`: the shape of a real robot's driver.

One trial at a time: ``open`` replaces the current one. Errors are replies
(``ok: false`` with the error's type and message), never a dead server.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from typing import Any

import numpy as np
import zmq
from scipy.spatial.transform import Rotation

from agentchord.robot.aloha import ARMS
from agentchord.worlds.protocol import CONTROL_HZ, ArmCommand
from agentchord.worlds.sim.cameras import DepthCamera
from agentchord.worlds.sim.hand import Waypoint
from agentchord.worlds.sim.tasks import SIM_TASKS
from agentchord.worlds.sim.trial import open_world
from agentchord.worlds.sim.world import SimWorld
from agentchord.worlds.wire import PROTOCOL_VERSION, WireError, pack, unpack

#: The simulator's own calls a client may make (``sim``), and whether each changes the world.
SIM_CALLS: dict[str, bool] = {
    "object_velocity": False,
    "on_table": False,
    "touching": False,
    "touching_cloth": False,
    "cloth_speed": False,
    "gripper_faulted": False,
    "cloth_vertices": False,
    "push": True,
    "knock": True,
    "inject_gripper_fault": True,
    "hand_carry": True,
}


class ProtocolError(ValueError):
    """A request the server cannot act on (unknown op, missing field, no trial open)."""


def snapshot(world: SimWorld) -> dict[str, Any]:
    """What the client needs to answer every state query until the next tick."""
    names = [*world.object_names, *world.cloth_point_names]
    tcp = {arm: world.tcp_pose(arm) for arm in ARMS}
    poses = [world.object_pose(name) for name in world.object_names]
    cloth = [world.cloth_point(name) for name in world.cloth_point_names]
    return {
        "tick": world.tick,
        "arm_q": np.stack([world.arm_q(arm) for arm in ARMS]),
        "tcp_pos": np.stack([tcp[arm][0] for arm in ARMS]),
        "tcp_rot": np.stack([tcp[arm][1] for arm in ARMS]),
        "width": np.array([world.gripper_width(arm) for arm in ARMS]),
        "holding": [[arm, name] for arm in ARMS for name in names if world.holding(arm, name)],
        "obj_pos": np.stack([p for p, _ in poses]) if poses else np.zeros((0, 3)),
        "obj_rot": np.stack([r for _, r in poses]) if poses else np.zeros((0, 3, 3)),
        "obj_quat": np.stack([world.object_quat(n) for n in world.object_names]) if poses else np.zeros((0, 4)),
        "cloth_pos": np.stack([p for p, _ in cloth]) if cloth else np.zeros((0, 3)),
        "cloth_out": np.stack([o for _, o in cloth]) if cloth else np.zeros((0, 3)),
        "hand_busy": world.hand_busy,
    }


def describe(world: SimWorld) -> dict[str, Any]:
    """The trial's fixed facts: objects, cloth points, cameras, the arms' bases, the commands at reset."""
    return {
        "control_hz": CONTROL_HZ,
        "objects": [dataclasses.asdict(world.object_spec(name)) for name in world.object_names],
        "cloth_points": world.cloth_point_names,
        "cloth_radius": world.cloth_radius,
        "cameras": world.camera_names,
        "arm_base": {arm: world.arm_base(arm) for arm in ARMS},
        "commands": {arm: {"q": world.commands[arm].q, "grip": world.commands[arm].grip} for arm in ARMS},
        "ground_truth": True,
    }


class WorldServer:
    """Answers world-protocol requests on a simulated task's trials.

    Args:
        task: The task served.
        seed: The seed of a trial opened without one.
    """

    def __init__(self, task: str, seed: int = 0) -> None:
        if task not in SIM_TASKS:
            raise KeyError(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})")
        self.task = task
        self.seed = seed
        self.world: SimWorld | None = None
        self._cameras: dict[tuple[str, int, int], DepthCamera] = {}

    # ------------------------------------------------------------------ dispatch
    def handle(self, request: dict[str, Any]) -> dict[str, Any]:
        """One reply for one request; an error is a reply too."""
        try:
            op = request.get("op")
            handler = getattr(self, f"_op_{op}", None) if isinstance(op, str) else None
            if handler is None:
                raise ProtocolError(f"unknown op {op!r} (ops: hello, open, step, camera, sim, close)")
            return {"ok": True, **handler(request)}
        except Exception as exc:  # noqa: BLE001  (every error goes back to the client)
            return {"ok": False, "type": type(exc).__name__, "error": str(exc)}

    def _world(self) -> SimWorld:
        if self.world is None:
            raise ProtocolError("no trial is open: send 'open' first")
        return self.world

    def _op_hello(self, request: dict[str, Any]) -> dict[str, Any]:
        return {"protocol": PROTOCOL_VERSION, "server": "agentchord-sim", "task": self.task, "seed": self.seed}

    def _op_open(self, request: dict[str, Any]) -> dict[str, Any]:
        task = request.get("task", self.task)
        if task != self.task:
            raise ProtocolError(f"this server serves {self.task!r}, not {task!r} (start one with --task {task})")
        seed = request.get("seed", self.seed)
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            raise ProtocolError(f"seed must be a non-negative integer, got {seed!r}")
        self._close_trial()
        self.world = open_world(task, seed)
        return {"task": task, "seed": seed, "world": describe(self.world), "state": snapshot(self.world)}

    def _op_step(self, request: dict[str, Any]) -> dict[str, Any]:
        world = self._world()
        for arm, command in (request.get("commands") or {}).items():
            if arm not in ARMS:
                raise ProtocolError(f"unknown arm {arm!r} (arms: {', '.join(ARMS)})")
            q = np.asarray(command["q"], dtype=float)
            if q.shape != (6,):
                raise ProtocolError(f"{arm}: q must hold 6 joint targets, got shape {q.shape}")
            world.command(arm, ArmCommand(q=q, grip=float(command["grip"])))
        world.step()
        return {"state": snapshot(world)}

    def _op_camera(self, request: dict[str, Any]) -> dict[str, Any]:
        world = self._world()
        name, width, height = request["name"], int(request.get("width", 320)), int(request.get("height", 240))
        key = (name, width, height)
        if key not in self._cameras:
            self._cameras[key] = world.open_camera(name, width, height)
        frame = self._cameras[key].capture()
        return {"frame": {"camera": frame.camera, "depth": frame.depth, "fovy": frame.fovy, "pos": frame.pos,
                          "rot": frame.rot, "far": frame.far, "labels": frame.labels}}

    def _op_sim(self, request: dict[str, Any]) -> dict[str, Any]:
        world = self._world()
        method = request.get("method")
        if method not in SIM_CALLS:
            raise ProtocolError(f"unknown simulator call {method!r} (calls: {', '.join(SIM_CALLS)})")
        args = list(request.get("args") or [])
        kwargs = dict(request.get("kwargs") or {})
        if method == "hand_carry":
            args[1] = [Waypoint(np.asarray(w["pos"], dtype=float), Rotation(np.asarray(w["quat"], dtype=float), normalize=False),
                                float(w["seconds"])) for w in args[1]]
        result = getattr(world, method)(*args, **kwargs)
        if method == "hand_carry":
            result = None
        reply: dict[str, Any] = {"result": result}
        if SIM_CALLS[method]:
            reply["state"] = snapshot(world)
        return reply

    def _op_close(self, request: dict[str, Any]) -> dict[str, Any]:
        self._close_trial()
        return {}

    def _close_trial(self) -> None:
        for camera in self._cameras.values():
            camera.close()
        self._cameras.clear()
        self.world = None

    # ------------------------------------------------------------------ loop
    def serve(self, address: str, ready: Callable[[str], None] | None = None, stop: threading.Event | None = None,
              context: zmq.Context | None = None) -> None:
        """Answer requests on ``address`` (``tcp://host:port``; port ``*``: any free one) until ``stop``.

        Args:
            address: Where to bind.
            ready: Called with the bound endpoint once requests are accepted.
            stop: Set it to stop (checked every 100 ms); None: serve until interrupted.
            context: The ZeroMQ context (default: the process's).
        """
        context = context or zmq.Context.instance()
        socket = context.socket(zmq.REP)
        socket.setsockopt(zmq.LINGER, 0)
        try:
            socket.bind(address)
            if ready is not None:
                ready(socket.getsockopt_string(zmq.LAST_ENDPOINT))
            while stop is None or not stop.is_set():
                if not socket.poll(100):
                    continue
                data = socket.recv()
                try:
                    reply = self.handle(unpack(data))
                except WireError as exc:
                    reply = {"ok": False, "type": type(exc).__name__, "error": str(exc)}
                socket.send(pack(reply))
        finally:
            socket.close(0)
            self._close_trial()


def serve_in_thread(task: str, seed: int = 0, host: str = "127.0.0.1") -> tuple[str, threading.Event, threading.Thread]:
    """A server on a free port of ``host`` in a background thread (tests, benchmarks).

    Returns:
        ``(address, stop, thread)``: set ``stop`` and join ``thread`` to end it.
    """
    server = WorldServer(task, seed)
    stop, bound = threading.Event(), threading.Event()
    endpoint: list[str] = []

    def ready(address: str) -> None:
        endpoint.append(address)
        bound.set()

    thread = threading.Thread(target=server.serve, args=(f"tcp://{host}:*",), kwargs={"ready": ready, "stop": stop},
                              daemon=True, name=f"world-server-{task}")
    thread.start()
    if not bound.wait(30):
        stop.set()
        raise RuntimeError("the world server did not start within 30 s")
    return endpoint[0], stop, thread
