"""A world in another process: the client side of the world protocol (``--world tcp://host:port``).

:class:`RemoteWorld` implements :class:`~agentchord.worlds.protocol.World` (and
:class:`~agentchord.worlds.protocol.GroundTruthWorld` when the server has ground truth) over
ZeroMQ REQ/REP with the messages of ``docs/world_protocol.md``. Each ``step`` sends both arms'
commands and receives the state after the tick, so every query between two ticks (joints, tool
poses, widths, grasp signals, object poses) is answered locally; only camera frames and the
simulator's own calls (used by disturbances and success checks) are round trips of their own.
Arrays travel as raw float64 bytes: the same seed gives the same episode as the local world.

Every reply is checked before it is used: a reply that is not the protocol (a missing field, a
wrong type or shape) or a reading that is not finite (a NaN joint angle or pose) is a
:class:`RemoteWorldError` naming the field, never an internal error nor a verdict computed
from NaN.
"""

from __future__ import annotations

import ipaddress
import math
import os
import socket as sockets
from typing import Any, cast

import numpy as np
import zmq

from agentchord.robot.aloha import ARMS
from agentchord.worlds.protocol import ArmCommand, CameraFrame, ObjectInfo
from agentchord.worlds.wire import PROTOCOL_VERSION, WireError, pack, unpack

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]

#: Seconds a reply may take before the server counts as gone (a camera frame or a trial's set-up included).
DEFAULT_TIMEOUT_S = 120.0
#: Environment variable that sets it (seconds, a number within ``(0, MAX_TIMEOUT_S]``).
ENV_TIMEOUT = "AGENTCHORD_WORLD_TIMEOUT"
#: The longest reply wait accepted (a day): ZeroMQ takes the wait as a 32-bit count of milliseconds.
MAX_TIMEOUT_S = 86_400.0
#: Protocol versions this client speaks (1: without trial tokens).
PROTOCOLS = (1, PROTOCOL_VERSION)


#: Milliseconds a closing client waits for the server to take its close.
CLOSE_WAIT_MS = 1000

class RemoteWorldError(RuntimeError):
    """The remote world did not answer, refused a request, or speaks another protocol version."""


class RemoteWorldSettingError(RemoteWorldError, ValueError):
    """An address or a timeout that cannot be used, found before anything is sent."""


def check_address(address: str) -> str:
    """``address`` if it is a ZeroMQ endpoint a client can connect to (``tcp://host:port``, ``ipc://path``).

    An IPv6 address goes in brackets (``tcp://[::1]:5555``). Names are not resolved here
    (see :func:`resolve_address`).

    Raises:
        ValueError: Anything else, saying what is expected.
    """
    expected = "expected tcp://HOST:PORT (e.g. tcp://127.0.0.1:5555, tcp://[::1]:5555) or ipc://PATH"
    if address.startswith("tcp://"):
        host, sep, port = address[len("tcp://"):].rpartition(":")
        if sep and host and port.isdigit() and 0 < int(port) < 65536:
            if host.startswith("[") and host.endswith("]"):
                try:
                    ipaddress.IPv6Address(host[1:-1])
                except ValueError:
                    raise ValueError(f"bad world address {address!r}: {host} is not an IPv6 address") from None
                return address
            if ":" in host:
                raise ValueError(f"bad world address {address!r}: an IPv6 address goes in brackets, "
                                 f"tcp://[{host}]:{port}")
            if host == "*" or any(c in host for c in " /[]@?#"):
                raise ValueError(f"bad world address {address!r}: {host!r} is not a host a client can connect to; "
                                 f"{expected}")
            return address
    elif address.startswith("ipc://") and len(address) > len("ipc://"):
        return address
    raise ValueError(f"bad world address {address!r}: {expected}")


def resolve_address(address: str) -> str:
    """Check ``address`` and that its host name resolves, so that a name no one answers to is refused at once.

    Raises:
        RemoteWorldSettingError: A bad address or a name that does not resolve.
    """
    try:
        check_address(address)
    except ValueError as exc:
        raise RemoteWorldSettingError(str(exc)) from None
    if address.startswith("tcp://"):
        host, _, port = address[len("tcp://"):].rpartition(":")
        try:
            sockets.getaddrinfo(host.strip("[]"), int(port), type=sockets.SOCK_STREAM)
        except (OSError, UnicodeError) as exc:
            reason = getattr(exc, "strerror", None) or str(exc)
            raise RemoteWorldSettingError(f"bad world address {address!r}: cannot resolve {host!r} ({reason})") from None
    return address


def timeout_from_env(env: dict[str, str] | None = None) -> float:
    """The reply timeout: :data:`ENV_TIMEOUT` if set, else :data:`DEFAULT_TIMEOUT_S`.

    Raises:
        RemoteWorldSettingError: The variable is not a number of seconds within ``(0, MAX_TIMEOUT_S]``.
    """
    value = (os.environ if env is None else env).get(ENV_TIMEOUT)
    if value is None or not value.strip():
        return DEFAULT_TIMEOUT_S
    try:
        return check_timeout(float(value))
    except ValueError:
        raise RemoteWorldSettingError(f"{ENV_TIMEOUT}={value!r}: expected seconds, a number within "
                                      f"(0, {MAX_TIMEOUT_S:g}]") from None


def check_timeout(seconds: float) -> float:
    """``seconds`` if it is a usable reply timeout.

    Raises:
        RemoteWorldSettingError: Not finite, not positive, or beyond :data:`MAX_TIMEOUT_S`.
    """
    if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or not math.isfinite(seconds) \
            or not 0 < seconds <= MAX_TIMEOUT_S:
        raise RemoteWorldSettingError(f"the world's reply timeout must be seconds within (0, {MAX_TIMEOUT_S:g}], "
                                      f"got {seconds!r}")
    return float(seconds)


class MalformedReplyError(RemoteWorldError):
    """A reply that is not the protocol, or whose readings are not finite."""


def _client_name() -> str:
    return f"agentchord on {sockets.gethostname()} (pid {os.getpid()})"


class _Reader:
    """Reads the fields of one reply, each checked: present, of its type and shape, finite."""

    def __init__(self, address: str, what: str) -> None:
        self.address, self.what = address, what

    def fail(self, where: str, problem: str) -> MalformedReplyError:
        """The error for ``where``."""
        return MalformedReplyError(f"the world at {self.address} sent a malformed {self.what!r} reply: {where}: {problem}")

    def field(self, mapping: Any, key: str, kind: type | tuple[type, ...], where: str | None = None) -> Any:
        """``mapping[key]``, which must be a ``kind``."""
        where = where or key
        if not isinstance(mapping, dict):
            raise self.fail(where.rpartition(".")[0] or "the reply", f"expected a map, got {type(mapping).__name__}")
        if key not in mapping:
            raise self.fail(where, "missing")
        value = mapping[key]
        if not isinstance(value, kind) or (isinstance(value, bool) and bool not in (kind if isinstance(kind, tuple) else (kind,))):
            names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
            raise self.fail(where, f"expected {names}, got {type(value).__name__}")
        return value

    def array(self, mapping: Any, key: str, shape: tuple[int, ...], where: str | None = None, finite: bool = True,
              dtype: Any = None) -> np.ndarray:
        """``mapping[key]`` as an array of ``shape`` (-1: any length), finite (or at least not NaN)."""
        where = where or key
        value = self.field(mapping, key, (np.ndarray, list, tuple), where)
        try:
            if isinstance(value, np.ndarray) and value.dtype.kind in "biuf" and dtype is None:
                array = value  # as it came: the local world's dtype and bits
            else:
                array = np.asarray(value, dtype=dtype or float)
        except (TypeError, ValueError, OverflowError):
            raise self.fail(where, "expected numbers") from None
        if array.dtype.kind not in "biuf":
            raise self.fail(where, f"expected numbers, got {array.dtype}")
        if len(array.shape) != len(shape) or any(n not in (-1, m) for n, m in zip(shape, array.shape)):
            wanted = "x".join("n" if n < 0 else str(n) for n in shape) or "a scalar"
            raise self.fail(where, f"expected shape {wanted}, got {'x'.join(map(str, array.shape)) or 'a scalar'}")
        if array.dtype.kind == "f":
            bad = ~np.isfinite(array) if finite else np.isnan(array)
            if bad.any():
                raise self.fail(where, f"{'not finite' if finite else 'NaN'} ({array[bad].ravel()[0]} at index "
                                       f"{tuple(int(i) for i in np.argwhere(bad)[0])})")
        return array

    def number(self, mapping: Any, key: str, where: str | None = None, low: float = -math.inf, high: float = math.inf,
               integer: bool = False) -> float:
        """``mapping[key]``, a finite number within ``[low, high]`` (an integer where asked)."""
        where = where or key
        value = self.field(mapping, key, int if integer else (int, float), where)
        if isinstance(value, float) and not math.isfinite(value):
            raise self.fail(where, f"not finite ({value})")
        if not low <= value <= high:
            raise self.fail(where, f"{value} is out of range [{low:g}, {high:g}]")
        return value

    def __enter__(self) -> _Reader:
        return self

    def __exit__(self, kind: Any, error: Any, traceback: Any) -> None:
        # What the field checks did not foresee (a list of the wrong length, a name that is not a string)
        # is still the reply's fault, not ours.
        if error is not None and not isinstance(error, RemoteWorldError) and isinstance(
                error, (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError)):
            raise self.fail("a field", f"{type(error).__name__}: {error}") from error


class RemoteCamera:
    """A camera of a remote world: one ``camera`` request per frame."""

    def __init__(self, world: RemoteWorld, name: str, width: int, height: int) -> None:
        self.world, self.name, self.width, self.height = world, name, width, height

    def capture(self) -> CameraFrame:
        """A frame of the remote world as it is now."""
        reply = self.world.request("camera", name=self.name, width=self.width, height=self.height)
        with self.world.reading("camera") as read:
            frame = read.field(reply, "frame", dict)
            shape = (self.height, self.width)
            labels, rgb = frame.get("labels"), frame.get("rgb")
            return CameraFrame(
                camera=read.field(frame, "camera", str, "frame.camera"),
                depth=read.array(frame, "depth", shape, "frame.depth", finite=False),
                fovy=read.number(frame, "fovy", "frame.fovy", low=0.0, high=180.0),
                pos=read.array(frame, "pos", (3,), "frame.pos"), rot=read.array(frame, "rot", (3, 3), "frame.rot"),
                far=read.number(frame, "far", "frame.far", low=0.0),
                labels=None if labels is None else read.array(frame, "labels", shape, "frame.labels", dtype=np.int64),
                rgb=None if rgb is None else read.array(frame, "rgb", (*shape, 3), "frame.rgb", dtype=np.uint8),
            )

    def close(self) -> None:
        """Nothing to release on this side."""


class RemoteWorld:
    """A world served by another process (``agentchord serve``, or a robot's driver).

    Args:
        address: The server's endpoint, ``tcp://host:port``.
        task: The task of the trial to open.
        seed: The trial's seed.
        timeout_s: Seconds a reply may take.

    Raises:
        RemoteWorldError: No server answered, or it refused the trial.
    """

    def __init__(self, address: str, task: str, seed: int, timeout_s: float | None = None) -> None:
        self.address = resolve_address(address)
        self.timeout_s = timeout_from_env() if timeout_s is None else check_timeout(timeout_s)
        self.timeout_ms = int(self.timeout_s * 1000)
        self._context: zmq.Context[zmq.Socket] = zmq.Context.instance()
        self._socket: zmq.Socket | None = None
        #: The open trial's token (protocol 2): every request of the trial carries it.
        self.trial: str | None = None
        #: Requests answered so far (hello and open included).
        self.requests = 0
        self._connect()
        try:
            self._open(task, seed)
        except BaseException:
            self.close()
            raise

    def _open(self, task: str, seed: int) -> None:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
            raise RemoteWorldSettingError(f"seed {seed!r} cannot be sent to a remote world: the world protocol "
                                          "carries seeds from 0 to 2^63 - 1")
        hello = self.request("hello")
        if hello.get("protocol") not in PROTOCOLS:
            raise RemoteWorldError(f"{self.address} speaks world protocol {hello.get('protocol')!r}, "
                                   f"this client {' or '.join(map(str, PROTOCOLS))}")
        opened = self.request("open", task=task, seed=seed, client=_client_name())
        with self.reading("open") as read:
            trial = opened.get("trial")
            if hello["protocol"] >= 2 and not isinstance(trial, str):
                raise read.fail("trial", "missing (protocol 2 hands out a trial token)")
            self.trial = trial
            info = read.field(opened, "world", dict)
            self.task = read.field(opened, "task", str)
            self.seed = read.number(opened, "seed", integer=True, low=0)
            self.control_hz = int(read.number(info, "control_hz", "world.control_hz", integer=True, low=1, high=10_000))
            self._objects = {}
            for k, o in enumerate(read.field(info, "objects", list, "world.objects")):
                at = f"world.objects[{k}]"
                name = read.field(o, "name", str, f"{at}.name")
                self._objects[name] = ObjectInfo(
                    name=name, shape=read.field(o, "shape", str, f"{at}.shape"),
                    size=tuple(float(x) for x in read.array(o, "size", (-1,), f"{at}.size")),
                    # The casts give the tuples the lengths the protocol sends (rgba's is checked, parts' and pos' are not).
                    rgba=cast(Vec4, tuple(float(x) for x in read.array(o, "rgba", (4,), f"{at}.rgba"))),
                    mass=float(read.number(o, "mass", f"{at}.mass", low=0.0)),
                    friction=float(read.number(o, "friction", f"{at}.friction", low=0.0)),
                    parts=tuple((cast(Vec3, tuple(float(x) for x in h)), cast(Vec3, tuple(float(x) for x in c)))
                                for h, c in read.field(o, "parts", list, f"{at}.parts")),
                    pos=cast(Vec2, tuple(float(x) for x in read.array(o, "pos", (-1,), f"{at}.pos"))),
                    yaw=float(read.number(o, "yaw", f"{at}.yaw")),
                )
            self._object_index = {name: k for k, name in enumerate(self._objects)}
            self._cloth_points = [str(p) for p in read.field(info, "cloth_points", list, "world.cloth_points")]
            self._cloth_index = {name: k for k, name in enumerate(self._cloth_points)}
            self._cloth_radius = float(read.number(info, "cloth_radius", "world.cloth_radius", low=0.0))
            self._cameras = [str(c) for c in read.field(info, "cameras", list, "world.cameras")]
            bases = read.field(info, "arm_base", dict, "world.arm_base")
            self._arm_base = {arm: read.array(bases, arm, (3,), f"world.arm_base.{arm}") for arm in ARMS}
            self.has_ground_truth = bool(info.get("ground_truth", False))
            commands = read.field(info, "commands", dict, "world.commands")
            self.commands: dict[str, ArmCommand] = {}
            for arm in ARMS:
                command = read.field(commands, arm, dict, f"world.commands.{arm}")
                self.commands[arm] = ArmCommand(q=read.array(command, "q", (6,), f"world.commands.{arm}.q"),
                                                grip=float(read.number(command, "grip", f"world.commands.{arm}.grip")))
        self._state: dict[str, Any] = {}
        self._holding: frozenset[tuple[str, str]] = frozenset()
        self.tick = 0
        self._adopt(opened.get("state"), "open")

    def reading(self, what: str) -> _Reader:
        """The checker of a reply to ``what``, as a context: anything amiss is a :class:`MalformedReplyError`."""
        return _Reader(self.address, what)

    # ------------------------------------------------------------------ transport
    def _connect(self) -> None:
        socket = self._context.socket(zmq.REQ)
        socket.setsockopt(zmq.LINGER, 0)
        socket.setsockopt(zmq.RCVTIMEO, self.timeout_ms)
        socket.setsockopt(zmq.SNDTIMEO, self.timeout_ms)
        socket.setsockopt(zmq.IPV6, 1)  # a name or tcp://[::1]:port may be IPv6; IPv4 still works
        try:
            socket.connect(self.address)
        except zmq.ZMQError as exc:
            socket.close(0)
            raise RemoteWorldSettingError(f"cannot connect to the world at {self.address}: {exc}") from None
        self._socket = socket

    def request(self, op: str, **fields: Any) -> dict[str, Any]:
        """Send one request, return the reply.

        Raises:
            RemoteWorldError: No reply in time (the connection is then closed), a reply that is not
                the protocol, or an error reply.
        """
        if self._socket is None:
            raise RemoteWorldError(f"the connection to {self.address} is closed")
        if self.trial is not None and op not in ("hello", "open"):
            fields["trial"] = self.trial
        try:
            message = pack({"op": op, **fields})
        except (TypeError, ValueError, OverflowError) as exc:  # nothing was sent: the socket stays usable
            raise RemoteWorldError(f"cannot send {op!r} to the world at {self.address}: {exc}") from None
        try:
            self._socket.send(message)
            reply = unpack(self._socket.recv())
        except zmq.Again:
            self.close()
            raise RemoteWorldError(
                f"no reply from the world at {self.address} within {self.timeout_s:g} s "
                f"(is `agentchord serve` running there? {ENV_TIMEOUT} sets the wait)"
            ) from None
        except WireError as exc:
            self.close()
            raise MalformedReplyError(f"the world at {self.address} does not speak the world protocol: "
                                      f"its reply to {op!r} is {exc}") from None
        self.requests += 1
        ok = reply.get("ok")
        if ok is not True:
            if ok is False:
                raise RemoteWorldError(f"the world at {self.address} refused {op!r}: {reply.get('type')}: {reply.get('error')}")
            raise MalformedReplyError(f"the world at {self.address} sent a malformed {op!r} reply: ok: "
                                      f"{'missing' if 'ok' not in reply else f'expected true or false, got {ok!r:.40}'}")
        return reply

    def close(self) -> None:
        """Close the trial (when the server still answers, within a second) and the connection.

        The close goes on a connection of its own: the request socket may still be waiting for a
        reply (a client interrupted by Ctrl-C or SIGTERM in the middle of a step), and a REQ socket
        in that state cannot send, which left the trial open and every other client refused until
        the server released it.
        """
        if self._socket is None:
            return
        socket, self._socket = self._socket, None
        socket.close(0)
        trial, self.trial = self.trial, None
        if trial is None:  # a refused open has no trial to close (and must not close another's)
            return
        closer = self._context.socket(zmq.REQ)
        try:
            closer.setsockopt(zmq.LINGER, 0)
            closer.setsockopt(zmq.SNDTIMEO, CLOSE_WAIT_MS)
            closer.setsockopt(zmq.IPV6, 1)
            closer.connect(self.address)
            closer.send(pack({"op": "close", "trial": trial}))
            if closer.poll(CLOSE_WAIT_MS):
                closer.recv()
        except zmq.ZMQError:
            pass  # the server is gone: it released the trial with itself
        finally:
            closer.close(0)

    def __enter__(self) -> RemoteWorld:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _adopt(self, state: Any, op: str = "step") -> None:
        n, m = len(self._objects), len(self._cloth_points)
        names = {*self._objects, *self._cloth_points}
        with self.reading(op) as read:
            if not isinstance(state, dict):
                raise read.fail("state", "missing" if state is None else f"expected a map, got {type(state).__name__}")
            checked: dict[str, Any] = {
                "tick": read.number(state, "tick", "state.tick", integer=True, low=0),
                "arm_q": read.array(state, "arm_q", (2, 6), "state.arm_q"),
                "tcp_pos": read.array(state, "tcp_pos", (2, 3), "state.tcp_pos"),
                "tcp_rot": read.array(state, "tcp_rot", (2, 3, 3), "state.tcp_rot"),
                "width": read.array(state, "width", (2,), "state.width"),
                "hand_busy": read.field(state, "hand_busy", bool, "state.hand_busy"),
            }
            holding = read.field(state, "holding", list, "state.holding")
            for pair in holding:
                if not (isinstance(pair, (list, tuple)) and len(pair) == 2 and pair[0] in ARMS and pair[1] in names):
                    raise read.fail("state.holding", f"expected [arm, object] pairs of this scene, got {pair!r:.80}")
            if self.has_ground_truth:
                for key, shape in (("obj_pos", (n, 3)), ("obj_rot", (n, 3, 3)), ("obj_quat", (n, 4)),
                                   ("cloth_pos", (m, 3)), ("cloth_out", (m, 3))):
                    checked[key] = read.array(state, key, shape, f"state.{key}")
        self._state = {**state, **checked}
        self.tick = int(checked["tick"])
        self._holding = frozenset((arm, name) for arm, name in holding)

    # ------------------------------------------------------------------ World
    @property
    def time(self) -> float:
        """Robot time since the trial opened (s)."""
        return self.tick / self.control_hz

    @property
    def object_names(self) -> list[str]:
        """Names of the scene's rigid objects."""
        return list(self._objects)

    @property
    def cloth_point_names(self) -> list[str]:
        """Named points of the cloth (its corners); empty without one."""
        return list(self._cloth_points)

    @property
    def camera_names(self) -> list[str]:
        """The server's cameras."""
        return list(self._cameras)

    def object_spec(self, name: str) -> ObjectInfo:
        """What the task knows of an object."""
        try:
            return self._objects[name]
        except KeyError:
            raise KeyError(f"no object {name!r} in the scene (objects: {', '.join(self._objects)})") from None

    def command(self, arm: str, command: ArmCommand) -> None:
        """Set one arm's targets; sent with the next :meth:`step`."""
        self.commands[arm] = command

    def step(self) -> None:
        """One control tick on the server; the reply is the state after it."""
        commands = {arm: {"q": np.asarray(c.q, dtype=float), "grip": float(c.grip)} for arm, c in self.commands.items()}
        self._adopt(self.request("step", commands=commands)["state"])

    def arm_q(self, arm: str) -> np.ndarray:
        """Measured arm joint positions."""
        return self._state["arm_q"][ARMS.index(arm)].copy()

    def tcp_pose(self, arm: str) -> tuple[np.ndarray, np.ndarray]:
        """Measured tool-centre position and rotation matrix."""
        k = ARMS.index(arm)
        return self._state["tcp_pos"][k].copy(), self._state["tcp_rot"][k].copy()

    def gripper_width(self, arm: str) -> float:
        """Gap between the finger pads (m)."""
        return float(self._state["width"][ARMS.index(arm)])

    def holding(self, arm: str, obj: str) -> bool:
        """The server's grasp signal at the last tick."""
        return (arm, obj) in self._holding

    def arm_base(self, arm: str) -> np.ndarray:
        """Position of the arm's shoulder in the world."""
        return self._arm_base[arm].copy()

    def open_camera(self, name: str, width: int = 320, height: int = 240) -> RemoteCamera:
        """A camera of the remote world.

        Raises:
            KeyError: No such camera.
        """
        if name not in self._cameras:
            raise KeyError(f"no camera {name!r} in the scene (cameras: {', '.join(self._cameras)})")
        return RemoteCamera(self, name, width, height)

    # ------------------------------------------------------------------ GroundTruthWorld
    def object_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Position and rotation matrix of an object at the last tick."""
        k = self._object_index[self.object_spec(name).name]
        return self._state["obj_pos"][k].copy(), self._state["obj_rot"][k].copy()

    def object_quat(self, name: str) -> np.ndarray:
        """Orientation quaternion (w, x, y, z) of an object at the last tick."""
        return self._state["obj_quat"][self._object_index[name]].copy()

    def cloth_point(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """A cloth point's position and horizontal outward direction at the last tick."""
        try:
            k = self._cloth_index[name]
        except KeyError:
            raise KeyError(f"no cloth point {name!r} in the scene (points: {', '.join(self._cloth_points)})") from None
        return self._state["cloth_pos"][k].copy(), self._state["cloth_out"][k].copy()

    @property
    def cloth_radius(self) -> float:
        """Half the cloth's thickness (m); 0 without a cloth."""
        return self._cloth_radius

    # ------------------------------------------------------------------ the simulator's own means
    # Disturbances and success checks (the simulator's side) reach the server's simulator here.
    def _sim(self, method: str, *args: Any) -> Any:
        reply = self.request("sim", method=method, args=list(args))
        if "state" in reply:
            self._adopt(reply["state"], f"sim {method}")
        return reply.get("result")

    def _sim_number(self, method: str, *args: Any) -> float:
        result = self._sim(method, *args)
        with self.reading(f"sim {method}") as read:
            return float(read.number({"result": result}, "result", low=0.0))

    def _sim_flag(self, method: str, *args: Any) -> bool:
        result = self._sim(method, *args)
        with self.reading(f"sim {method}") as read:
            return read.field({"result": result}, "result", bool)

    @property
    def hand_busy(self) -> bool:
        """Whether a person's hand is still carrying an object (at the last tick)."""
        return bool(self._state["hand_busy"])

    def object_velocity(self, name: str) -> float:
        """Linear speed of an object (m/s)."""
        return self._sim_number("object_velocity", name)

    def on_table(self, obj: str) -> bool:
        """Whether the object rests on the table."""
        return self._sim_flag("on_table", obj)

    def touching(self, obj_a: str, obj_b: str) -> bool:
        """Whether two objects touch."""
        return self._sim_flag("touching", obj_a, obj_b)

    def touching_cloth(self, arm: str) -> bool:
        """Whether either finger pad of ``arm`` touches the cloth."""
        return self._sim_flag("touching_cloth", arm)

    def cloth_speed(self) -> float:
        """Largest speed of a cloth vertex (m/s)."""
        return self._sim_number("cloth_speed")

    def cloth_vertices(self) -> np.ndarray:
        """Positions of the cloth's vertices (n x 3)."""
        result = self._sim("cloth_vertices")
        with self.reading("sim cloth_vertices") as read:
            return np.asarray(read.array({"result": result}, "result", (-1, 3)), dtype=float)

    def gripper_faulted(self, arm: str) -> bool:
        """Whether a gripper fault is forcing ``arm`` open now."""
        return self._sim_flag("gripper_faulted", arm)

    def inject_gripper_fault(self, arm: str, ticks: int) -> None:
        """Force ``arm``'s gripper open for ``ticks`` ticks (the drop disturbance)."""
        self._sim("inject_gripper_fault", arm, int(ticks))

    def push(self, obj: str, force: np.ndarray, ticks: int) -> None:
        """Slide an object with a force (N) for ``ticks`` ticks."""
        self._sim("push", obj, np.asarray(force, dtype=float), int(ticks))

    def knock(self, obj: str, direction: np.ndarray, ticks: int = 6) -> None:
        """Knock an object over."""
        self._sim("knock", obj, np.asarray(direction, dtype=float), int(ticks))

    def hand_carry(self, obj: str, waypoints: list, out_of: str | None = None) -> None:
        """A person's hand carries ``obj`` along ``waypoints`` (each ``pos``, ``rotation``, ``seconds``),
        the first one moving with ``out_of``'s gripper."""
        wire = [{"pos": np.asarray(w.pos, dtype=float), "quat": w.rotation.as_quat(), "seconds": float(w.seconds)}
                for w in waypoints]
        self._sim("hand_carry", obj, wire, out_of)
