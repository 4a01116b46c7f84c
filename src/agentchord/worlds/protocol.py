"""The World protocol: what the executor, the actions, the feature extractors and the solvers
may ask of a robot and its scene.

A world is stepped at its control rate with one :class:`ArmCommand` per arm, and reports the
robot's own signals (joint positions, tool poses, gripper widths, grasp signals), the reach
of each arm (its base) and camera frames with their intrinsics and extrinsics. Only some
worlds also know the true state of the objects (a simulator does, a real robot does not):
they implement :class:`GroundTruthWorld` too, and a feature extractor that needs it says so
(:func:`require_ground_truth`).

Implementations: :class:`agentchord.sim.world.SimWorld` (MuJoCo, in process) and
:class:`agentchord.worlds.remote.RemoteWorld` (any world served over the message protocol of
``docs/world_protocol.md``, e.g. ``agentchord serve``). Disturbances, success checks and the
scene's ground truth stay on the simulator's side: nothing here names them.

Conventions: positions in metres in the world frame (z up, the table top at z = 0), rotation
matrices with the frame's axes as columns, quaternions (w, x, y, z); arms ``left`` and ``right``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

#: Control rate of the robot (Hz): one :meth:`World.step` per tick.
CONTROL_HZ = 50


@dataclass
class ArmCommand:
    """What one arm is told to do for one control tick.

    Attributes:
        q: Joint position targets of the 6 arm joints (rad).
        grip: Gripper target in [0, 1]: 0 fully open, 1 closed.
    """

    q: np.ndarray
    grip: float


class ObjectModel(Protocol):
    """What the task knows of an object before seeing it: its category's shape and nominal size.

    Attributes:
        name: The object's name (as the graph names it).
        shape: ``cylinder`` (size: radius, half-height) or ``box`` (size: half-sizes).
        size: The shape's parameters (m).
        rgba: Its colour (how the agents describe it).
    """

    name: str
    shape: str
    size: tuple[float, ...]
    rgba: tuple[float, float, float, float]

    @property
    def height(self) -> float:
        """Full height (m) standing upright."""
        ...

    @property
    def width(self) -> float:
        """Full width (m) across its footprint."""
        ...


@dataclass(frozen=True)
class ObjectInfo:
    """An :class:`ObjectModel` as plain data (what a remote world or a robot's driver reports).

    Attributes:
        name: The object's name.
        shape: ``cylinder`` or ``box``.
        size: The shape's parameters (m).
        rgba: Its colour.
        mass: Its mass (kg), where known.
        friction: Its sliding friction coefficient, where known.
        parts: A compound object's boxes, each (half-sizes, centre in its frame); empty: one shape.
        pos: Its initial (x, y) on the table, where known.
        yaw: Its initial rotation about z (rad).
    """

    name: str
    shape: str
    size: tuple[float, ...]
    rgba: tuple[float, float, float, float] = (0.5, 0.5, 0.5, 1.0)
    mass: float = 0.0
    friction: float = 1.0
    parts: tuple[tuple[tuple[float, float, float], tuple[float, float, float]], ...] = ()
    pos: tuple[float, float] = (0.0, 0.0)
    yaw: float = 0.0

    @property
    def height(self) -> float:
        """Full height (m) standing upright."""
        return upright_height(self.shape, self.size)

    @property
    def width(self) -> float:
        """Smallest horizontal width (m): what a gripper closes on."""
        return grip_width(self.shape, self.size)

    def half_extent_along(self, matrix: np.ndarray, direction: np.ndarray) -> float:
        """Half the object's extent (m) along a world direction, in its pose ``matrix`` (3 x 3)."""
        return half_extent_along(self.shape, self.size, matrix, direction)


def half_extent_along(shape: str, size: tuple[float, ...], matrix: np.ndarray, direction: np.ndarray) -> float:
    """Half the extent (m) along a world direction of a ``cylinder`` (radius, half-height) or ``box`` (half-sizes)
    in its pose ``matrix`` (3 x 3): what a disturbance pulling or loading it reads, for a local or a remote world."""
    local = np.abs(matrix.T @ direction)
    if shape == "cylinder":
        radius, half_height = size[0], size[1]
        return float(local[2] * half_height + np.sqrt(max(1.0 - local[2] ** 2, 0.0)) * radius)
    return float(local @ np.asarray(size[:3], dtype=float))


def gripper_opening(grip: float) -> float:
    """A World command's ``grip`` (0 open .. 1 closed, what the arm is told to close) as the opening the
    Gymnasium environments and the LeRobot datasets use (0 closed .. 1 open, ALOHA's and LeRobot's
    convention). The one place the two conventions meet; :func:`gripper_grip` is its inverse."""
    return 1.0 - float(grip)


def gripper_grip(opening: float) -> float:
    """An opening (0 closed .. 1 open, Gymnasium and LeRobot) as a World command's ``grip`` (0 open .. 1
    closed), clipped to [0, 1]; the inverse of :func:`gripper_opening`."""
    return min(1.0, max(0.0, 1.0 - float(opening)))


def upright_height(shape: str, size: tuple[float, ...]) -> float:
    """Full height (m) of a ``cylinder`` (radius, half-height) or ``box`` (half-sizes) standing upright."""
    return 2.0 * (size[1] if shape == "cylinder" else size[2])


def grip_width(shape: str, size: tuple[float, ...]) -> float:
    """Smallest horizontal width (m) of a shape standing upright: what a gripper closes on."""
    return 2.0 * size[0] if shape == "cylinder" else 2.0 * min(size[0], size[1])


@dataclass
class CameraFrame:
    """One depth image of a camera, with its intrinsics and extrinsics.

    Attributes:
        camera: The camera's name.
        depth: (H, W) distance along the camera's viewing axis (m), row 0 at the top.
        fovy: Vertical field of view (deg); pixels are square, the principal point is the centre.
        pos: The camera's position in the world (m).
        rot: (3, 3) the camera's axes as columns: it looks along its -z, y up, x right.
        far: Depth (m) at or beyond which a pixel saw nothing.
        labels: (H, W) the world's own instance segmentation, where it has one (a simulator
            does): index into :attr:`World.object_names`, -1 for anything else. None: none
            (a real camera: masks come from a segmenter).
        rgb: (H, W, 3) colour image, when the camera gives one.
    """

    camera: str
    depth: np.ndarray
    fovy: float
    pos: np.ndarray
    rot: np.ndarray
    far: float = np.inf
    labels: np.ndarray | None = None
    rgb: np.ndarray | None = None

    @property
    def intrinsics(self) -> np.ndarray:
        """The pinhole matrix K (3 x 3, pixels), the principal point at the image centre."""
        height, width = self.depth.shape
        f = 0.5 * height / np.tan(0.5 * np.radians(self.fovy))
        return np.array([[f, 0.0, 0.5 * width], [0.0, f, 0.5 * height], [0.0, 0.0, 1.0]])

    @property
    def extrinsics(self) -> np.ndarray:
        """The camera-to-world transform (4 x 4) in the camera convention above."""
        out = np.eye(4)
        out[:3, :3] = self.rot
        out[:3, 3] = self.pos
        return out


class Camera(Protocol):
    """An open camera of a world: one frame per :meth:`capture`, :meth:`close` when done."""

    name: str

    def capture(self) -> CameraFrame:
        """A frame of the world as it is now."""
        ...

    def close(self) -> None:
        """Release what the camera holds (a renderer, a connection)."""
        ...


@runtime_checkable
class World(Protocol):
    """A robot and its scene, stepped at :data:`CONTROL_HZ`.

    Attributes:
        tick: Control ticks since the episode started.
        commands: The last command of each arm (what the gripper was told to do).
    """

    tick: int
    commands: dict[str, ArmCommand]

    @property
    def time(self) -> float:
        """Robot time since the episode started (s)."""
        ...

    @property
    def object_names(self) -> list[str]:
        """Names of the scene's rigid objects."""
        ...

    @property
    def cloth_point_names(self) -> list[str]:
        """Named points of a cloth (its corners), graspable like objects; empty without one."""
        ...

    @property
    def camera_names(self) -> list[str]:
        """Cameras :meth:`open_camera` can open."""
        ...

    def object_spec(self, name: str) -> ObjectModel:
        """What the task knows of an object: shape, nominal size, colour.

        Raises:
            KeyError: No such object.
        """
        ...

    # ------------------------------------------------------------------ control
    def command(self, arm: str, command: ArmCommand) -> None:
        """Set one arm's targets for the next ticks."""
        ...

    def step(self) -> None:
        """Advance one control tick with the current commands."""
        ...

    # --------------------------------------------------------- the robot's signals
    def arm_q(self, arm: str) -> np.ndarray:
        """Measured arm joint positions (rad)."""
        ...

    def tcp_pose(self, arm: str) -> tuple[np.ndarray, np.ndarray]:
        """Measured tool-centre position and rotation matrix."""
        ...

    def gripper_width(self, arm: str) -> float:
        """Gap between the finger pads (m)."""
        ...

    def holding(self, arm: str, obj: str) -> bool:
        """The grasp signal: whether ``arm`` holds ``obj`` (a simulator: both finger pads touch it;
        a real robot: its driver's estimate from the gripper's width, effort and the object's
        proximity)."""
        ...

    def arm_base(self, arm: str) -> np.ndarray:
        """Position of the arm's shoulder (its waist axis) in the world: where its reach is measured from."""
        ...

    # ------------------------------------------------------------------ cameras
    def open_camera(self, name: str, width: int = 320, height: int = 240) -> Camera:
        """Open a camera for frames of ``width`` x ``height`` pixels.

        Raises:
            KeyError: No such camera.
        """
        ...


@runtime_checkable
class GroundTruthWorld(World, Protocol):
    """A world that knows the true state of its objects (a simulator): what oracle features read."""

    def object_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Position and rotation matrix of an object."""
        ...

    def object_quat(self, name: str) -> np.ndarray:
        """Orientation quaternion (w, x, y, z) of an object."""
        ...

    def cloth_point(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """A cloth point's position and its horizontal outward direction (unit, or zero)."""
        ...

    @property
    def cloth_radius(self) -> float:
        """Half the cloth's thickness (m); 0 without a cloth."""
        ...


class GroundTruthUnavailableError(TypeError):
    """A feature extractor that reads the objects' true state was given a world without it."""


def require_ground_truth(world: World, who: str) -> GroundTruthWorld:
    """``world`` as a :class:`GroundTruthWorld`, for an extractor that needs the true object state.

    Raises:
        GroundTruthUnavailableError: The world has no ground truth (a real robot, a remote
            world served without it), naming what it lacks and what to use instead.
    """
    if isinstance(world, GroundTruthWorld) and getattr(world, "has_ground_truth", True):
        return world
    missing = [m for m in ("object_pose", "object_quat", "cloth_point", "cloth_radius") if not hasattr(world, m)]
    what = f" (it lacks {', '.join(missing)})" if missing else ""
    raise GroundTruthUnavailableError(
        f"{who} reads the objects' true state, which {type(world).__name__} does not provide{what}: "
        "use a perception that reads cameras (--perception rgbd) on this world"
    )
