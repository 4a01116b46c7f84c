"""Build the MuJoCo scene: the ALOHA bimanual ViperX on a table, plus task objects.

The robot's model comes from :mod:`agentchord.robot.model` (the ALOHA files of the
installed ``gym-aloha`` package, edited: a tool-centre site, gravity compensation,
lighter joint friction, our own actuators); here come a thick collision table, a
floor, lights and cameras. Objects are added as free bodies with explicit inertia.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np

from agentchord.robot.aloha import (  # noqa: F401  (the robot's numbers, re-exported for the simulator's modules)
    ARM_JOINTS,
    ARM_PREFIX,
    FINGER_GAP_OFFSET,
    FINGER_RANGE,
    HOME_Q,
    TABLE_CENTER,
    TABLE_HALF,
    TCP_OFFSET,
)
from agentchord.robot.exceptions import RobotModelError
from agentchord.robot.model import NOSLIP_ITERATIONS, add_collision_proxies, edit_robot, robot_xml  # noqa: F401  (re-exported)
from agentchord.worlds.protocol import grip_width, half_extent_along, upright_height
from agentchord.sim.exceptions import SceneError, SceneSpecError

#: Sliding friction of the table top (MuJoCo takes the larger of two touching geoms' coefficients).
TABLE_FRICTION = 1.0


@dataclass
class ObjectSpec:
    """A rigid object of the scene.

    Attributes:
        name: Object name (also the MuJoCo body name).
        shape: ``cylinder`` (radius, half-height) or ``box`` (half-sizes).
        size: Shape parameters as MuJoCo expects them.
        mass: Mass in kg.
        pos: Initial (x, y) on the table; z is set from the size.
        yaw: Initial rotation about z (rad).
        rgba: Colour.
        friction: Sliding friction coefficient.
        parts: A compound object (a tray with a rim): box geoms, each (half-sizes,
            centre in the body frame), that together make the object; then ``shape``
            must be ``box`` and ``size`` gives the half-sizes of their overall bounding
            box, centred on the body origin (what features such as ``extent``, ``top``
            and ``bottom`` describe). The mass is spread over the parts by volume.
            Empty (the default): one geom of ``shape`` and ``size``.
    """

    name: str
    shape: str
    size: tuple[float, ...]
    mass: float
    pos: tuple[float, float]
    yaw: float = 0.0
    rgba: tuple[float, float, float, float] = (0.2, 0.5, 0.9, 1.0)
    friction: float = 1.0
    parts: tuple[tuple[tuple[float, float, float], tuple[float, float, float]], ...] = ()

    def __post_init__(self) -> None:
        # A scene written outside the package (docs/scenes.md) is input: refused here, named, not
        # deep in MuJoCo or the features.
        sizes = {"cylinder": 2, "box": 3}
        where = f"object {self.name!r}"
        if self.shape not in sizes:
            raise SceneSpecError(f"{where}: shape {self.shape!r} is not one the simulator builds (cylinder or box)")
        try:
            size = [float(v) for v in self.size]
            numbers = [float(self.mass), float(self.pos[0]), float(self.pos[1]), float(self.yaw), float(self.friction)]
        except (TypeError, ValueError, IndexError):
            raise SceneSpecError(f"{where}: size, mass, pos, yaw and friction must be numbers") from None
        if len(size) != sizes[self.shape]:
            what = "radius, half-height" if self.shape == "cylinder" else "three half-sizes"
            raise SceneSpecError(f"{where}: a {self.shape} takes {sizes[self.shape]} sizes ({what}), got {len(size)}")
        if not all(math.isfinite(v) for v in size + numbers):
            raise SceneSpecError(f"{where}: its size, mass, pos, yaw and friction must be finite")
        if not all(0.002 <= v <= 1.0 for v in size):
            raise SceneSpecError(f"{where}: each size must be from 0.002 to 1 m (half-sizes), got {tuple(size)}")
        if not 0.001 <= self.mass <= 20.0:
            raise SceneSpecError(f"{where}: mass must be from 0.001 to 20 kg, got {self.mass}")
        if self.parts and self.shape != "box":
            raise SceneSpecError(f"{where}: a compound object (parts) must have shape 'box' (its bounding box)")

    @property
    def height(self) -> float:
        """Full height of the object standing upright."""
        return upright_height(self.shape, self.size)

    @property
    def width(self) -> float:
        """Smallest horizontal width (what a gripper closes on)."""
        return grip_width(self.shape, self.size)

    def half_extent_along(self, matrix: np.ndarray, direction: np.ndarray) -> float:
        """Half the object's extent (m) along a world direction, in its pose ``matrix`` (3 x 3)."""
        return half_extent_along(self.shape, self.size, matrix, direction)


@dataclass
class ClothSpec:
    """A cloth lying flat on the table: a MuJoCo flex grid (``flexcomp``, dim 2), no rigid body.

    Vertex ``k`` of the grid is ``ix * count[1] + iy`` (``iy`` runs fastest); in the cloth's own
    frame the corners are ``bl`` (x-min, y-min), ``br`` (x-max, y-min), ``tl`` (x-min, y-max) and
    ``tr`` (x-max, y-max). The world exposes them as points ``{name}_bl`` ... (see
    ``SimWorld.cloth_point``). MuJoCo 3.8 caps one flex/geom pair at 50 contacts, so the table
    supports a coarse grid only (7x7: 72 elements, most in contact); a finer cloth sags into it.

    Attributes:
        name: Flex name; its vertex bodies are ``{name}_{k}``.
        size: Full size (x, y) of the flat cloth (m).
        count: Vertices along x and y.
        mass: Total mass (kg), spread evenly over the vertices.
        pos: Centre (x, y) on the table.
        yaw: Rotation about z (rad).
        radius: Half thickness (m): the collision radius of the flex elements.
        friction: Sliding friction of every cloth contact (the cloth's contacts take priority
            over the other geom's parameters: the fingers' condim-4 contact made the solver
            return NaN on flex elements).
        rgba: Colour.
        bending: Young's modulus (Pa) of the cloth's bending stiffness (MuJoCo's ``elastic2d="bend"``,
            shell thickness = ``radius``); 0 = none (the cloth crumples like a sheet of links).
        bending_damping: Damping of the bending model (without it a stiff cloth keeps vibrating).
        self_collide: Whether the cloth collides with itself (a folded layer lies on the other one
            instead of passing through it).
    """

    name: str = "cloth"
    size: tuple[float, float] = (0.30, 0.24)
    count: tuple[int, int] = (7, 7)
    mass: float = 0.06
    pos: tuple[float, float] = (0.0, 0.55)
    yaw: float = 0.0
    radius: float = 0.004
    friction: float = 1.5
    rgba: tuple[float, float, float, float] = (0.85, 0.3, 0.3, 1.0)
    bending: float = 0.0
    bending_damping: float = 0.01
    self_collide: bool = False

    def corner_vertices(self) -> dict[str, tuple[int, int]]:
        """Corner label -> (corner vertex, its diagonal neighbour inside the cloth)."""
        nx, ny = self.count
        k = lambda ix, iy: ix * ny + iy  # noqa: E731
        return {
            "bl": (k(0, 0), k(1, 1)),
            "br": (k(nx - 1, 0), k(nx - 2, 1)),
            "tl": (k(0, ny - 1), k(1, ny - 2)),
            "tr": (k(nx - 1, ny - 1), k(nx - 2, ny - 2)),
        }


def _cloth_xml(cloth: ClothSpec) -> str:
    """The ``flexcomp`` element of a cloth (MjSpec has no flexcomp builder: it goes in the XML).

    A ``direct`` flexcomp on the grid, not ``type="grid"``: the grid splits every quad along the same
    diagonal, so two opposite corners belong to a single triangle that a pinch squeezes out of the
    fingers. Here each quadrant's quads are split along the diagonal through its own cloth corner:
    every corner vertex has two triangles, the same for all four (a symmetric "diamond" mesh).
    """
    (nx, ny), (sx, sy) = cloth.count, cloth.size
    points = [(sx * (ix / (nx - 1) - 0.5), sy * (iy / (ny - 1) - 0.5)) for ix in range(nx) for iy in range(ny)]
    k = lambda ix, iy: ix * ny + iy  # noqa: E731
    elements = []
    for ix in range(nx - 1):
        for iy in range(ny - 1):
            a, b, c, d = k(ix, iy), k(ix + 1, iy), k(ix + 1, iy + 1), k(ix, iy + 1)
            if (2 * ix + 1 < nx - 1) == (2 * iy + 1 < ny - 1):
                elements += [(a, b, c), (a, c, d)]
            else:
                elements += [(a, b, d), (b, c, d)]
    point = " ".join(f"{x:.6f} {y:.6f} 0" for x, y in points)
    element = " ".join(f"{a} {b} {c}" for a, b, c in elements)
    bending = (
        f'<elasticity young="{cloth.bending}" poisson="0.3" thickness="{cloth.radius}" elastic2d="bend" damping="{cloth.bending_damping}"/>'
        if cloth.bending > 0 else ""
    )
    self_collide = 'selfcollide="auto" internal="false"' if cloth.self_collide else 'selfcollide="none"'
    return f"""<flexcomp name="{cloth.name}" type="direct" dim="2" point="{point}" element="{element}"
      pos="{cloth.pos[0]} {cloth.pos[1]} {cloth.radius + 0.001}" euler="0 0 {cloth.yaw}" radius="{cloth.radius}"
      mass="{cloth.mass}" rgba="{' '.join(map(str, cloth.rgba))}">
      <contact condim="3" priority="1" friction="{cloth.friction} 0.005 0.0001" solref="0.01 1"
        solimp="0.95 0.99 0.0001" {self_collide}/>
      <edge equality="true" damping="0.01"/>
      {bending}
    </flexcomp>"""


@dataclass
class SceneSpec:
    """Everything needed to build one trial's scene, and how its physics is solved.

    Attributes:
        objects: The rigid objects and their initial placement.
        timestep: Physics step (s); a control tick at 50 Hz is ``0.02 / timestep`` steps.
        cloth: An optional flex cloth (None = none).
        solver: MuJoCo's constraint solver: ``newton`` (a few exact iterations, each a sparse
            factorisation) or ``cg`` (conjugate gradient: many cheap iterations; on a cloth's ~450
            constraint rows a step costs about a third of Newton's).
        noslip_while_touching_cloth: Run the noslip pass only on the ticks after a finger touched the
            cloth (the pass holds a pinch; a cloth nobody holds, lying or folded, does not need it).
    """

    objects: list[ObjectSpec] = field(default_factory=list)
    timestep: float = 0.002
    cloth: ClothSpec | None = None
    solver: Literal["newton", "cg"] = "newton"
    noslip_while_touching_cloth: bool = False


def _add_environment(spec: mujoco.MjSpec) -> None:
    world = spec.worldbody
    world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[2, 2, 0.1], pos=[0, 0.6, -0.75], rgba=[0.35, 0.35, 0.38, 1])
    table = world.add_body(name="table", pos=[TABLE_CENTER[0], TABLE_CENTER[1], -TABLE_HALF[2]])
    # A thick box, not the thin mesh: objects resting on a mesh skin were launched.
    table.add_geom(name="table", type=mujoco.mjtGeom.mjGEOM_BOX, size=list(TABLE_HALF), rgba=[0.55, 0.45, 0.35, 1], friction=[TABLE_FRICTION, 0.005, 0.0001])
    for xyz, direction in (((-1, -1, 1.5), (1, 1, -1.5)), ((1, -1, 1.5), (-1, 1, -1.5))):
        world.add_light(pos=list(xyz), dir=list(direction), type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL, diffuse=[0.45, 0.45, 0.45], castshadow=0)
    target = mujoco.mjtCamLight.mjCAMLIGHT_TARGETBODY
    world.add_camera(name="front", pos=[0.0, -0.25, 0.75], mode=target, targetbody="table", fovy=55)
    world.add_camera(name="top", pos=[0.0, 0.6, 1.35], xyaxes=[1, 0, 0, 0, 1, 0])
    world.add_camera(name="side", pos=[1.0, 0.1, 0.6], mode=target, targetbody="table", fovy=55)
    spec.visual.quality.offsamples = 0
    spec.visual.quality.shadowsize = 0
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]


def _add_object(spec: mujoco.MjSpec, obj: ObjectSpec) -> None:
    # Spawn 1 mm above the table: exact contact with the table launched cylinders.
    z = 0.5 * obj.height + 0.001
    quat = [np.cos(obj.yaw / 2), 0.0, 0.0, np.sin(obj.yaw / 2)]
    body = spec.worldbody.add_body(name=obj.name, pos=[obj.pos[0], obj.pos[1], z], quat=quat)
    body.add_freejoint(name=f"{obj.name}_free")
    geom_type = mujoco.mjtGeom.mjGEOM_CYLINDER if obj.shape == "cylinder" else mujoco.mjtGeom.mjGEOM_BOX
    contact = dict(
        rgba=list(obj.rgba),
        # Rolling friction (condim 6): a fallen bottle comes to rest instead of rolling away.
        friction=[obj.friction, 0.005, 0.003],
        condim=6,
        solimp=[0.95, 0.99, 0.001, 0.5, 2.0],
        solref=[0.01, 1.0],
        # Group-0 geoms get no mass from inertiagrouprange="4 5": inertia is explicit.
        mass=0.0,
    )
    if obj.parts:
        if obj.shape != "box":
            raise SceneError(f"{obj.name}: a compound object (parts) needs shape 'box' (its bounding box)")
        # The first part carries the object's name (the lookup name); every part counts as the object.
        for k, (half, centre) in enumerate(obj.parts):
            body.add_geom(name=obj.name if k == 0 else f"{obj.name}/{k}", type=mujoco.mjtGeom.mjGEOM_BOX,
                          size=list(half), pos=list(centre), **contact)
        com, inertia, iquat = _compound_inertia(obj.mass, obj.parts)
        body.mass = obj.mass
        body.ipos = list(com)
        body.iquat = list(iquat)
        body.inertia = list(inertia)
        body.explicitinertial = True
        return
    body.add_geom(name=obj.name, type=geom_type, size=list(obj.size) + [0.0] * (3 - len(obj.size)), **contact)
    if obj.shape == "cylinder":
        r, h = obj.size[0], obj.size[1]
        inertia = [obj.mass * (3 * r * r + 4 * h * h) / 12] * 2 + [0.5 * obj.mass * r * r]
    else:
        a, b, c = (2 * s for s in obj.size)
        inertia = [obj.mass * (b * b + c * c) / 12, obj.mass * (a * a + c * c) / 12, obj.mass * (a * a + b * b) / 12]
    body.mass = obj.mass
    body.ipos = [0.0, 0.0, 0.0]
    body.iquat = [1.0, 0.0, 0.0, 0.0]
    body.inertia = inertia
    body.explicitinertial = True


def _compound_inertia(mass: float, parts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre of mass, principal inertia and its frame (quat w, x, y, z) of boxes sharing ``mass`` by volume."""
    halves = np.array([p[0] for p in parts], dtype=float)
    centres = np.array([p[1] for p in parts], dtype=float)
    volumes = np.prod(2.0 * halves, axis=1)
    masses = mass * volumes / volumes.sum()
    com = masses @ centres / mass
    tensor = np.zeros((3, 3))
    for m, half, centre in zip(masses, halves, centres):
        a, b, c = 2.0 * half
        tensor += np.diag([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])
        d = centre - com
        tensor += m * (np.dot(d, d) * np.eye(3) - np.outer(d, d))  # parallel axis
    principal, axes = np.linalg.eigh(tensor)
    if np.linalg.det(axes) < 0:
        axes[:, 0] = -axes[:, 0]
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, axes.reshape(-1))
    return com, principal, quat


def build_model(scene: SceneSpec, collision_proxies: bool = False) -> mujoco.MjModel:
    """Compile the robot, the table and the scene's objects into one model.

    Raises:
        SceneError: If the ALOHA assets are missing or the model does not compile.
    """
    try:
        cloth = _cloth_xml(scene.cloth) if scene.cloth is not None else ""
        spec = mujoco.MjSpec.from_string(robot_xml(scene.timestep, cloth))
        edit_robot(spec)
        if collision_proxies:
            add_collision_proxies(spec)
        _add_environment(spec)
        for obj in scene.objects:
            _add_object(spec, obj)
        if scene.solver == "cg":
            spec.option.solver = mujoco.mjtSolver.mjSOL_CG
        return spec.compile()
    except (ValueError, RobotModelError) as exc:
        raise SceneError(f"the scene does not compile: {exc}") from exc
