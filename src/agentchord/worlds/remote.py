"""A world in another process: the client side of the world protocol (``--world tcp://host:port``).

:class:`RemoteWorld` implements :class:`~agentchord.worlds.protocol.World` (and
:class:`~agentchord.worlds.protocol.GroundTruthWorld` when the server has ground truth) over
ZeroMQ REQ/REP with the messages of ``docs/world_protocol.md``. Each ``step`` sends both arms'
commands and receives the state after the tick, so every query between two ticks (joints, tool
poses, widths, grasp signals, object poses) is answered locally; only camera frames and the
simulator's own calls (used by disturbances and success checks) are round trips of their own.
Arrays travel as raw float64 bytes: the same seed gives the same episode as the local world.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import zmq

from agentchord.robot.aloha import ARMS
from agentchord.worlds.protocol import ArmCommand, CameraFrame, ObjectInfo
from agentchord.worlds.wire import PROTOCOL_VERSION, pack, unpack

#: Seconds a reply may take before the server counts as gone (a camera frame or a trial's set-up included).
DEFAULT_TIMEOUT_S = 120.0


class RemoteWorldError(RuntimeError):
    """The remote world did not answer, refused a request, or speaks another protocol version."""


def check_address(address: str) -> str:
    """``address`` if it is a ZeroMQ endpoint a client can connect to (``tcp://host:port``, ``ipc://path``).

    Raises:
        ValueError: Anything else, saying what is expected.
    """
    if address.startswith("tcp://"):
        host, sep, port = address[len("tcp://"):].rpartition(":")
        if sep and host and port.isdigit() and 0 < int(port) < 65536:
            return address
    elif address.startswith("ipc://") and len(address) > len("ipc://"):
        return address
    raise ValueError(f"bad world address {address!r}: expected tcp://HOST:PORT (e.g. tcp://127.0.0.1:5555) or ipc://PATH")


class RemoteCamera:
    """A camera of a remote world: one ``camera`` request per frame."""

    def __init__(self, world: RemoteWorld, name: str, width: int, height: int) -> None:
        self.world, self.name, self.width, self.height = world, name, width, height

    def capture(self) -> CameraFrame:
        """A frame of the remote world as it is now."""
        frame = self.world.request("camera", name=self.name, width=self.width, height=self.height)["frame"]
        return CameraFrame(camera=frame["camera"], depth=frame["depth"], fovy=float(frame["fovy"]), pos=frame["pos"],
                           rot=frame["rot"], far=float(frame["far"]), labels=frame.get("labels"), rgb=frame.get("rgb"))

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

    def __init__(self, address: str, task: str, seed: int, timeout_s: float = DEFAULT_TIMEOUT_S) -> None:
        self.address = check_address(address)
        self.timeout_ms = int(timeout_s * 1000)
        self._context = zmq.Context.instance()
        self._socket: zmq.Socket | None = None
        #: Requests answered so far (hello and open included).
        self.requests = 0
        self._connect()
        hello = self.request("hello")
        if hello.get("protocol") != PROTOCOL_VERSION:
            self.close()
            raise RemoteWorldError(f"{address} speaks world protocol {hello.get('protocol')!r}, this client {PROTOCOL_VERSION}")
        opened = self.request("open", task=task, seed=seed)
        info = opened["world"]
        self.task, self.seed = opened["task"], opened["seed"]
        self.control_hz = int(info["control_hz"])
        self._objects = {
            o["name"]: ObjectInfo(
                name=o["name"], shape=o["shape"], size=tuple(float(x) for x in o["size"]),
                rgba=tuple(float(x) for x in o["rgba"]), mass=float(o["mass"]), friction=float(o["friction"]),
                parts=tuple((tuple(float(x) for x in h), tuple(float(x) for x in c)) for h, c in o["parts"]),
                pos=tuple(float(x) for x in o["pos"]), yaw=float(o["yaw"]),
            )
            for o in info["objects"]
        }
        self._object_index = {name: k for k, name in enumerate(self._objects)}
        self._cloth_points = list(info["cloth_points"])
        self._cloth_index = {name: k for k, name in enumerate(self._cloth_points)}
        self._cloth_radius = float(info["cloth_radius"])
        self._cameras = list(info["cameras"])
        self._arm_base = {arm: np.asarray(pos, dtype=float) for arm, pos in info["arm_base"].items()}
        self.has_ground_truth = bool(info.get("ground_truth", False))
        self.commands: dict[str, ArmCommand] = {
            arm: ArmCommand(q=np.asarray(c["q"], dtype=float), grip=float(c["grip"])) for arm, c in info["commands"].items()
        }
        self._state: dict[str, Any] = {}
        self._holding: frozenset[tuple[str, str]] = frozenset()
        self.tick = 0
        self._adopt(opened["state"])

    # ------------------------------------------------------------------ transport
    def _connect(self) -> None:
        socket = self._context.socket(zmq.REQ)
        socket.setsockopt(zmq.LINGER, 0)
        socket.setsockopt(zmq.RCVTIMEO, self.timeout_ms)
        socket.setsockopt(zmq.SNDTIMEO, self.timeout_ms)
        socket.connect(self.address)
        self._socket = socket

    def request(self, op: str, **fields: Any) -> dict[str, Any]:
        """Send one request, return the reply.

        Raises:
            RemoteWorldError: No reply in time (the connection is then closed), or an error reply.
        """
        if self._socket is None:
            raise RemoteWorldError(f"the connection to {self.address} is closed")
        try:
            self._socket.send(pack({"op": op, **fields}))
            reply = unpack(self._socket.recv())
        except zmq.Again:
            self.close()
            raise RemoteWorldError(
                f"no reply from the world at {self.address} within {self.timeout_ms / 1000:g} s "
                "(is `agentchord serve` running there?)"
            ) from None
        self.requests += 1
        if not reply.get("ok"):
            raise RemoteWorldError(f"the world at {self.address} refused {op!r}: {reply.get('type')}: {reply.get('error')}")
        return reply

    def close(self) -> None:
        """Close the trial (when the server still answers) and the connection."""
        if self._socket is None:
            return
        socket, self._socket = self._socket, None
        try:
            socket.send(pack({"op": "close"}), zmq.NOBLOCK)
            if socket.poll(1000):
                socket.recv()
        except zmq.ZMQError:
            pass
        socket.close(0)

    def __enter__(self) -> RemoteWorld:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _adopt(self, state: dict[str, Any]) -> None:
        self._state = state
        self.tick = int(state["tick"])
        self._holding = frozenset((arm, name) for arm, name in state["holding"])

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
            self._adopt(reply["state"])
        return reply.get("result")

    @property
    def hand_busy(self) -> bool:
        """Whether a person's hand is still carrying an object (at the last tick)."""
        return bool(self._state["hand_busy"])

    def object_velocity(self, name: str) -> float:
        """Linear speed of an object (m/s)."""
        return float(self._sim("object_velocity", name))

    def on_table(self, obj: str) -> bool:
        """Whether the object rests on the table."""
        return bool(self._sim("on_table", obj))

    def touching(self, obj_a: str, obj_b: str) -> bool:
        """Whether two objects touch."""
        return bool(self._sim("touching", obj_a, obj_b))

    def touching_cloth(self, arm: str) -> bool:
        """Whether either finger pad of ``arm`` touches the cloth."""
        return bool(self._sim("touching_cloth", arm))

    def cloth_speed(self) -> float:
        """Largest speed of a cloth vertex (m/s)."""
        return float(self._sim("cloth_speed"))

    def cloth_vertices(self) -> np.ndarray:
        """Positions of the cloth's vertices (n x 3)."""
        return np.asarray(self._sim("cloth_vertices"), dtype=float)

    def gripper_faulted(self, arm: str) -> bool:
        """Whether a gripper fault is forcing ``arm`` open now."""
        return bool(self._sim("gripper_faulted", arm))

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
