"""The simulator served in its own process: ``agentchord serve --task T --port P``.

A ZeroMQ REP socket answers one request with one reply, in the messages of
``docs/world_protocol.md`` (:mod:`agentchord.worlds.wire`): ``hello``, ``open`` (a trial:
task and seed), ``step`` (both arms' commands; the reply is the state after the tick),
``camera`` (a depth frame with its geometry and labels), ``sim`` (the simulator's own
means, which only disturbances and success checks use: forces, gripper faults, a
person's hand, contact queries) and ``close``. The client is
:class:`agentchord.worlds.remote.RemoteWorld`: the shape of a real robot's driver.

A served world is one client's at a time: ``open`` hands out a trial token that every later
request of that trial carries; another client's ``open`` is refused (naming who holds the
world) until the holder closes its trial or sends nothing for ``release_after_s``. What a
client sends is checked: finite joint targets within range, grips in [0, 1], bounded simulator
calls, camera sizes within limits (at most :data:`MAX_CAMERAS` renderers kept), messages of
at most :data:`MAX_MESSAGE_BYTES`. Errors are replies (``ok: false`` with the error's type and
message), never a dead server.
"""

from __future__ import annotations

import dataclasses
import math
import secrets
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

import numpy as np
import zmq
from scipy.spatial.transform import Rotation

from agentchord.robot.aloha import ARMS
from agentchord.worlds.protocol import CONTROL_HZ, ArmCommand
from agentchord.sim.cameras import DepthCamera
from agentchord.sim.hand import Waypoint
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world
from agentchord.sim.world import SimWorld
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


#: Seconds a trial may go without a request before another client may take the world over.
DEFAULT_RELEASE_AFTER_S = 300.0
#: Largest request accepted (bytes); ZeroMQ drops a client that sends more, before it is read.
MAX_MESSAGE_BYTES = 4 * 1024 * 1024
#: Camera renderers kept per trial (one per camera and image size); the least recently used is closed.
MAX_CAMERAS = 8
#: Image sizes a ``camera`` request may ask for.
CAMERA_WIDTHS, CAMERA_HEIGHTS = (16, 1920), (16, 1080)
#: Largest joint target (rad): a revolute joint's target beyond a full turn is not a command.
MAX_JOINT_TARGET = 2 * math.pi
#: Bounds of the simulator calls' arguments: ticks, force (N), a carry's position (m) and leg (s).
MAX_SIM_TICKS, MAX_FORCE_N, MAX_POSITION_M, MAX_LEG_S = 10_000, 1_000.0, 10.0, 60.0


class ProtocolError(ValueError):
    """A request the server cannot act on (unknown op, missing field, no trial open)."""


class TrialBusyError(ProtocolError):
    """Another client holds the world: its trial is open and it is still sending requests."""


def _finite_array(value: Any, what: str, shape: tuple[int, ...], bound: float) -> np.ndarray:
    """``value`` as a float array of ``shape`` whose entries are finite and within ``±bound``."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ProtocolError(f"{what} must be {shape[0] if shape else 'a'} number(s), got {value!r:.80}") from None
    if array.shape != shape:
        raise ProtocolError(f"{what} must have shape {shape}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ProtocolError(f"{what} must be finite, got {array.tolist()}")
    if np.any(np.abs(array) > bound):
        raise ProtocolError(f"{what} is out of range (at most {bound:g} in magnitude), got {array.tolist()}")
    return array


def _number(value: Any, what: str, low: float, high: float, integer: bool = False) -> float:
    """``value`` as a finite number within ``[low, high]`` (an integer where ``integer``)."""
    kinds = (int,) if integer else (int, float)
    if isinstance(value, bool) or not isinstance(value, kinds):
        raise ProtocolError(f"{what} must be {'an integer' if integer else 'a number'}, got {value!r:.80}")
    if (isinstance(value, float) and not math.isfinite(value)) or not low <= value <= high:
        raise ProtocolError(f"{what} must be within [{low:g}, {high:g}], got {value!r}")
    return value


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
        release_after_s: Seconds without a request after which another client may open a trial
            in place of the current one (its client then gets "trial ... is not open").
        clock: Seconds, monotonic (tests).
    """

    def __init__(self, task: str, seed: int = 0, release_after_s: float = DEFAULT_RELEASE_AFTER_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if task not in SIM_TASKS:
            raise KeyError(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})")
        if not (math.isfinite(release_after_s) and release_after_s > 0):
            raise ValueError(f"release_after_s must be a positive number of seconds, got {release_after_s!r}")
        self.task = task
        self.seed = seed
        self.release_after_s = release_after_s
        self.clock = clock
        self.world: SimWorld | None = None
        self._cameras: OrderedDict[tuple[str, int, int], DepthCamera] = OrderedDict()
        #: The open trial's token, its client's name, its seed, and when it last sent a request.
        self.trial: str | None = None
        self.holder = ""
        self._trial_seed = 0
        self._last_request = 0.0

    # ------------------------------------------------------------------ dispatch
    def handle(self, request: dict[str, Any]) -> dict[str, Any]:
        """One reply for one request; an error is a reply too."""
        try:
            op = request.get("op")
            handler = getattr(self, f"_op_{op}", None) if isinstance(op, str) else None
            if handler is None:
                raise ProtocolError(f"unknown op {op!r} (ops: hello, open, step, camera, sim, close)")
            return {"ok": True, **handler(request)}
        except Exception as exc:  # every error goes back to the client
            return {"ok": False, "type": type(exc).__name__, "error": str(exc)}

    def _world(self, request: dict[str, Any]) -> SimWorld:
        """The open trial's world, if ``request`` carries its token."""
        token = request.get("trial")
        if self.world is None:
            if token is not None:  # its client was away: another one took the world and is done with it
                raise ProtocolError(f"trial {token!r} is not open here: it was closed, or released after "
                                    f"{self.release_after_s:g} s without a request")
            raise ProtocolError("no trial is open: send 'open' first")
        if token != self.trial:
            raise ProtocolError(f"trial {token!r} is not open here: the world now serves {self.holder}'s trial "
                                f"(a trial is released after {self.release_after_s:g} s without a request)")
        self._last_request = self.clock()
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
        client = str(request.get("client") or "an unnamed client")[:200]
        if self.world is not None and request.get("trial") != self.trial:
            idle = self.clock() - self._last_request
            if idle < self.release_after_s:
                raise TrialBusyError(
                    f"this world is in use: {self.holder} holds its trial (seed {self._trial_seed}), last request "
                    f"{idle:.1f} s ago; it is released when that client closes it or after {self.release_after_s:g} s "
                    "without a request (start another `agentchord serve` on another port to run both at once)")
        self._close_trial()
        self.world = open_world(task, seed)
        self.trial, self.holder, self._trial_seed = secrets.token_hex(8), client, seed
        self._last_request = self.clock()
        return {"task": task, "seed": seed, "trial": self.trial, "world": describe(self.world), "state": snapshot(self.world)}

    def _op_step(self, request: dict[str, Any]) -> dict[str, Any]:
        world = self._world(request)
        commands = request.get("commands") or {}
        if not isinstance(commands, dict):
            raise ProtocolError(f"commands must be a map of arm -> {{q, grip}}, got {type(commands).__name__}")
        checked = {}
        for arm, command in commands.items():
            if arm not in ARMS:
                raise ProtocolError(f"unknown arm {arm!r} (arms: {', '.join(ARMS)})")
            if not isinstance(command, dict) or "q" not in command or "grip" not in command:
                raise ProtocolError(f"{arm}: a command is a map with q (6 joint targets) and grip, got {command!r:.80}")
            try:
                q = np.asarray(command["q"], dtype=object)
            except ValueError:
                q = np.empty(0)
            if q.shape != (6,):
                raise ProtocolError(f"{arm}: q must hold 6 joint targets, got shape {q.shape}")
            q = _finite_array(command["q"], f"{arm}: q", (6,), MAX_JOINT_TARGET)
            grip = _number(command["grip"], f"{arm}: grip", 0.0, 1.0)
            checked[arm] = ArmCommand(q=q, grip=float(grip))
        for arm, command in checked.items():  # all or nothing: a refused step changes no target
            world.command(arm, command)
        world.step()
        return {"state": snapshot(world)}

    def _op_camera(self, request: dict[str, Any]) -> dict[str, Any]:
        world = self._world(request)
        name = request.get("name")
        if name not in world.camera_names:
            raise ProtocolError(f"no camera {name!r} in the scene (cameras: {', '.join(world.camera_names)})")
        width = int(_number(request.get("width", 320), "width", *CAMERA_WIDTHS, integer=True))
        height = int(_number(request.get("height", 240), "height", *CAMERA_HEIGHTS, integer=True))
        key = (name, width, height)
        if key in self._cameras:
            self._cameras.move_to_end(key)
        else:
            while len(self._cameras) >= MAX_CAMERAS:  # bounded: a client asking for many sizes reuses the slots
                self._cameras.popitem(last=False)[1].close()
            self._cameras[key] = world.open_camera(name, width, height)
        frame = self._cameras[key].capture()
        return {"frame": {"camera": frame.camera, "depth": frame.depth, "fovy": frame.fovy, "pos": frame.pos,
                          "rot": frame.rot, "far": frame.far, "labels": frame.labels}}

    def _op_sim(self, request: dict[str, Any]) -> dict[str, Any]:
        world = self._world(request)
        method = request.get("method")
        if method not in SIM_CALLS:
            raise ProtocolError(f"unknown simulator call {method!r} (calls: {', '.join(SIM_CALLS)})")
        args = request.get("args") or []
        kwargs = request.get("kwargs") or {}
        if not isinstance(args, list) or not isinstance(kwargs, dict):
            raise ProtocolError(f"sim {method}: args must be a list and kwargs a map")
        args, kwargs = list(args), dict(kwargs)
        _check_sim_args(method, args, kwargs)
        if method == "hand_carry":
            # Not normalised again (checked to be unit): the local world's rotation, bit for bit.
            args[1] = [Waypoint(w["pos"], Rotation(w["quat"], normalize=False), float(w["seconds"])) for w in args[1]]
        result = getattr(world, method)(*args, **kwargs)
        if method == "hand_carry":
            result = None
        reply: dict[str, Any] = {"result": result}
        if SIM_CALLS[method]:
            reply["state"] = snapshot(world)
        return reply

    def _op_close(self, request: dict[str, Any]) -> dict[str, Any]:
        if self.world is not None:
            self._world(request)  # only its own client closes a trial
        self._close_trial()
        return {}

    def _close_trial(self) -> None:
        for camera in self._cameras.values():
            camera.close()
        self._cameras.clear()
        self.world = None
        self.trial, self.holder = None, ""

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
        socket.setsockopt(zmq.MAXMSGSIZE, MAX_MESSAGE_BYTES)
        if "[" in address:  # tcp://[::1]:5555 (set only then: an IPv4 endpoint would print as [::ffff:a.b.c.d])
            socket.setsockopt(zmq.IPV6, 1)
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


def _check_sim_args(method: str, args: list, kwargs: dict) -> None:
    """Refuse a simulator call whose numbers are not finite or beyond what a disturbance uses."""
    if kwargs and set(kwargs) - {"out_of", "ticks"}:
        raise ProtocolError(f"sim {method}: unknown keyword arguments {sorted(set(kwargs) - {'out_of', 'ticks'})}")
    out_of = args[2] if method == "hand_carry" and len(args) > 2 else kwargs.get("out_of")
    for name, value in (("object or arm", args[0] if args else None), ("out_of", out_of)):
        if value is not None and not isinstance(value, str):
            raise ProtocolError(f"sim {method}: the {name} must be a name, got {value!r:.80}")
    if method in ("push", "knock"):
        if len(args) not in (2, 3):
            raise ProtocolError(f"sim {method} takes (obj, vector, ticks), got {len(args)} arguments")
        _finite_array(args[1], f"sim {method}: the {'force' if method == 'push' else 'direction'}", (3,), MAX_FORCE_N)
        if method == "knock" and not np.any(np.asarray(args[1], dtype=float)):
            raise ProtocolError("sim knock: the direction must not be zero")
    ticks = kwargs.get("ticks", args[2] if method in ("push", "knock") and len(args) > 2
                       else args[1] if method == "inject_gripper_fault" and len(args) > 1 else None)
    if ticks is not None:
        _number(ticks, f"sim {method}: ticks", 0, MAX_SIM_TICKS, integer=True)
    if method == "hand_carry":
        if len(args) < 2 or not isinstance(args[1], list) or not args[1]:
            raise ProtocolError("sim hand_carry takes (obj, [{pos, quat, seconds}, ...], out_of)")
        for k, leg in enumerate(args[1]):
            if not isinstance(leg, dict) or not {"pos", "quat", "seconds"} <= set(leg):
                raise ProtocolError(f"sim hand_carry: waypoint {k} must be a map with pos, quat and seconds")
            leg["pos"] = _finite_array(leg["pos"], f"sim hand_carry: waypoint {k} pos", (3,), MAX_POSITION_M)
            leg["quat"] = _finite_array(leg["quat"], f"sim hand_carry: waypoint {k} quat", (4,), 2.0)
            if abs(np.linalg.norm(leg["quat"]) - 1.0) > 1e-6:
                raise ProtocolError(f"sim hand_carry: waypoint {k} quat must be a unit quaternion (x, y, z, w)")
            _number(leg["seconds"], f"sim hand_carry: waypoint {k} seconds", 0.0, MAX_LEG_S)


def bind_host(host: str) -> str:
    """``host`` as a ZeroMQ endpoint writes it: an IPv6 address in brackets (``::1`` -> ``[::1]``)."""
    return f"[{host}]" if ":" in host and not host.startswith("[") else host


def serve_in_thread(task: str, seed: int = 0, host: str = "127.0.0.1",
                    release_after_s: float = DEFAULT_RELEASE_AFTER_S) -> tuple[str, threading.Event, threading.Thread]:
    """A server on a free port of ``host`` in a background thread (tests, benchmarks).

    Returns:
        ``(address, stop, thread)``: set ``stop`` and join ``thread`` to end it.
    """
    server = WorldServer(task, seed, release_after_s=release_after_s)
    stop, bound = threading.Event(), threading.Event()
    endpoint: list[str] = []

    def ready(address: str) -> None:
        endpoint.append(address)
        bound.set()

    thread = threading.Thread(target=server.serve, args=(f"tcp://{bind_host(host)}:*",), kwargs={"ready": ready, "stop": stop},
                              daemon=True, name=f"world-server-{task}")
    thread.start()
    if not bound.wait(30):
        stop.set()
        raise RuntimeError("the world server did not start within 30 s")
    return endpoint[0], stop, thread
