"""The MuJoCo world: physics, 50 Hz position control, contacts, gripper faults.

Objects move only through contact: a grasp holds because finger pads squeeze
the object with friction, and a drop happens because the fingers open.
"""

from __future__ import annotations

import mujoco
import numpy as np

from agentchord.worlds.protocol import CONTROL_HZ, ArmCommand, CameraFrame  # noqa: F401  (re-exported)
from agentchord.sim.cameras import DepthCamera
from agentchord.sim.exceptions import UnknownObjectError
from agentchord.sim.hand import PersonHand, Waypoint
from agentchord.sim.scene import (
    ARM_JOINTS,
    ARM_PREFIX,
    FINGER_GAP_OFFSET,
    FINGER_RANGE,
    HOME_Q,
    NOSLIP_ITERATIONS,
    SceneSpec,
    build_model,
)

#: A finger touches a cloth point (a corner) when it touches the cloth within this distance of it (m).
CLOTH_HOLD_RADIUS = 0.04
#: ... and only with at least this gap between its finger pads (m): cloth pinched between them.
CLOTH_MIN_PINCH = 0.002


class SimWorld:
    """One trial's MuJoCo world: a :class:`~agentchord.worlds.protocol.World` with ground truth
    (:class:`~agentchord.worlds.protocol.GroundTruthWorld`), plus the simulator's own means of
    disturbing it (gripper faults, pushes, knocks, a person's hand) and contact queries.

    Physics runs at ``1 / timestep``, control at :data:`~agentchord.worlds.protocol.CONTROL_HZ`.

    Args:
        scene: The objects and their initial placement.
    """

    def __init__(self, scene: SceneSpec) -> None:
        self.scene = scene
        self.model = build_model(scene)
        self.data = mujoco.MjData(self.model)
        self.substeps = round(1.0 / (CONTROL_HZ * self.model.opt.timestep))
        self.tick = 0
        m = self.model
        self._arm_qadr = {a: np.array([m.joint(f"{p}/{j}").qposadr[0] for j in ARM_JOINTS]) for a, p in ARM_PREFIX.items()}
        self._arm_dofadr = {a: np.array([m.joint(f"{p}/{j}").dofadr[0] for j in ARM_JOINTS]) for a, p in ARM_PREFIX.items()}
        self._arm_act = {a: np.array([m.actuator(f"{a}_{j}").id for j in ARM_JOINTS]) for a in ARM_PREFIX}
        self._finger_qadr = {a: m.joint(f"{p}/left_finger").qposadr[0] for a, p in ARM_PREFIX.items()}
        self._finger_act = {a: (m.actuator(f"{a}_left_finger").id, m.actuator(f"{a}_right_finger").id) for a in ARM_PREFIX}
        self._finger_geoms = {
            a: (m.geom(f"{p}/10_left_gripper_finger").id, m.geom(f"{p}/10_right_gripper_finger").id) for a, p in ARM_PREFIX.items()
        }
        self._tcp_site = {a: m.site(f"{a}_tcp").id for a in ARM_PREFIX}
        self._object_body = {o.name: m.body(o.name).id for o in scene.objects}
        # Every geom of an object's body counts as the object (a compound tray has several).
        self._object_geoms = {
            o.name: frozenset(int(g) for g in np.nonzero(m.geom_bodyid == m.body(o.name).id)[0]) for o in scene.objects
        }
        self._object_spec = {o.name: o for o in scene.objects}
        self._fault_until: dict[str, int] = {}
        self._push_until: dict[int, int] = {}
        self._hands: list[PersonHand] = []
        self.commands: dict[str, ArmCommand] = {}
        self._contacts: set[tuple[int, int]] = set()
        # A cloth (flex): named points (its corners) -> (vertex, diagonal neighbour inside), and
        # per finger geom the positions of its contacts with the cloth at the last tick.
        self._cloth_points: dict[str, tuple[int, int]] = {}
        self._cloth_vert0 = 0
        self._finger_cloth_contacts: dict[int, np.ndarray] = {}
        if scene.cloth is not None:
            self._cloth_vert0 = int(m.flex_vertadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_FLEX, scene.cloth.name)])
            for label, (corner, inner) in scene.cloth.corner_vertices().items():
                self._cloth_points[f"{scene.cloth.name}_{label}"] = (corner, inner)
        self.reset()

    # ------------------------------------------------------------------ set-up
    def reset(self) -> None:
        """Both arms home, grippers open, objects at rest on the table."""
        mujoco.mj_resetData(self.model, self.data)
        for arm in ARM_PREFIX:
            self.data.qpos[self._arm_qadr[arm]] = HOME_Q
            self.commands[arm] = ArmCommand(q=HOME_Q.copy(), grip=0.0)
            self._set_fingers_qpos(arm, FINGER_RANGE[1])
        self._apply_commands()
        mujoco.mj_forward(self.model, self.data)
        for _ in range(25):  # let objects settle onto the table
            self.step()
        self.tick = 0

    def _set_fingers_qpos(self, arm: str, q: float) -> None:
        adr = self._finger_qadr[arm]
        self.data.qpos[adr] = q
        self.data.qpos[adr + 1] = -q

    # ----------------------------------------------------------------- control
    def command(self, arm: str, command: ArmCommand) -> None:
        """Set one arm's targets for the next ticks."""
        self.commands[arm] = command

    def inject_gripper_fault(self, arm: str, ticks: int) -> None:
        """Force ``arm``'s gripper open for ``ticks`` control ticks (the drop disturbance)."""
        self._fault_until[arm] = self.tick + ticks

    def push(self, obj: str, force: np.ndarray, ticks: int) -> None:
        """Slide an object: a force (N, world frame) applied at table height for ``ticks`` ticks.

        Applied where the object meets the table, not at its centre, so a tall cup slides
        instead of tipping over (upright or lying, whatever its orientation).
        """
        self.object_spec(obj)
        body = self._object_body[obj]
        base = np.array([0.0, 0.0, -max(float(self.data.xpos[body][2]), 0.0)])
        self.data.xfrc_applied[body, :3] = force
        self.data.xfrc_applied[body, 3:] = np.cross(base, force)
        self._push_until[body] = self.tick + ticks

    def knock(self, obj: str, direction: np.ndarray, ticks: int = 6) -> None:
        """Knock an object over: a horizontal push high on it, scaled to tip it."""
        spec = self.object_spec(obj)
        body = self._object_body[obj]
        direction = np.asarray(direction, dtype=float)
        direction = direction / max(np.linalg.norm(direction), 1e-9)
        # Tipping needs F * h > m g * (half width): push with twice that.
        force = 2.0 * spec.mass * 9.81 * (0.5 * spec.width) / max(spec.height, 1e-3) * direction
        top = np.array([0.0, 0.0, 0.5 * spec.height])
        self.data.xfrc_applied[body, :3] = force
        self.data.xfrc_applied[body, 3:] = np.cross(top, force)
        self._push_until[body] = self.tick + ticks

    def hand_carry(self, obj: str, waypoints: list[Waypoint], out_of: str | None = None) -> PersonHand:
        """A person's hand takes ``obj`` and carries it along ``waypoints``, then lets go (see ``hand``).

        ``out_of``: the arm whose gripper it is taken out of; the first waypoint moves with that gripper.
        """
        self.object_spec(obj)
        tool = None
        if out_of is not None:

            def tool() -> tuple[np.ndarray, np.ndarray]:
                return self.tcp_pose(out_of)
        hand = PersonHand(self.model, self.data, self._object_body[obj], waypoints, tool)
        self._hands.append(hand)
        return hand

    @property
    def hand_busy(self) -> bool:
        """Whether a person's hand is still carrying an object."""
        return bool(self._hands)

    def gripper_faulted(self, arm: str) -> bool:
        """Whether a gripper fault is forcing ``arm`` open now."""
        return self._fault_until.get(arm, -1) > self.tick

    def _apply_commands(self) -> None:
        ctrl = self.data.ctrl
        lo, hi = FINGER_RANGE
        for arm, cmd in self.commands.items():
            ctrl[self._arm_act[arm]] = cmd.q
            grip = 0.0 if self.gripper_faulted(arm) else cmd.grip
            q_finger = hi - grip * (hi - lo)
            left, right = self._finger_act[arm]
            ctrl[left] = q_finger
            ctrl[right] = -q_finger

    def step(self) -> None:
        """Advance one control tick (``substeps`` physics steps)."""
        self._apply_commands()
        if self.scene.noslip_while_touching_cloth:
            # The contacts of the last tick: a pinch loads the cloth on the ticks after the fingers closed on it.
            self.model.opt.noslip_iterations = NOSLIP_ITERATIONS if self._finger_cloth_contacts else 0
        for _ in range(self.substeps):
            for hand in self._hands:
                hand.apply(self.model.opt.timestep)
            mujoco.mj_step(self.model, self.data)
        self._after_step()

    def _after_step(self) -> None:
        """A tick's bookkeeping once its physics ran: hands done, pushes over, the contacts it left."""
        self._hands = [hand for hand in self._hands if not hand.done]
        self.tick += 1
        for body, until in list(self._push_until.items()):
            if self.tick >= until:
                self.data.xfrc_applied[body] = 0.0
                del self._push_until[body]
        # As Python ints in one call (a pair at a time from numpy costs more than the rest of the step's bookkeeping).
        self._contacts = {(a, b) for a, b in self.data.contact.geom[: self.data.ncon].tolist()}
        if self._cloth_points:
            self._record_cloth_contacts()

    def _record_cloth_contacts(self) -> None:
        ncon = self.data.ncon
        flex = self.data.contact.flex[:ncon]
        geoms = self.data.contact.geom[:ncon]
        pos = self.data.contact.pos[:ncon]
        with_cloth = (flex >= 0).any(axis=1)
        self._finger_cloth_contacts = {}
        for geom in (g for pair in self._finger_geoms.values() for g in pair):
            rows = with_cloth & (geoms == geom).any(axis=1)
            if rows.any():
                self._finger_cloth_contacts[geom] = pos[rows].copy()

    # ------------------------------------------------------------------ state
    @property
    def time(self) -> float:
        """Robot time since reset (s)."""
        return self.tick / CONTROL_HZ

    @property
    def object_names(self) -> list[str]:
        """Names of the scene's objects."""
        return list(self._object_body)

    def object_body_id(self, name: str) -> int:
        """The MuJoCo body id of an object (its body may be named otherwise: gym-aloha's ``box`` is our ``cube``)."""
        try:
            return self._object_body[name]
        except KeyError:
            raise UnknownObjectError(f"no object {name!r} in the scene (objects: {', '.join(self._object_body)})") from None

    def object_spec(self, name: str):
        """The object's specification (shape, size, mass)."""
        try:
            return self._object_spec[name]
        except KeyError:
            raise UnknownObjectError(f"no object {name!r} in the scene (objects: {', '.join(self._object_body)})") from None

    def object_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Position and rotation matrix of an object's body."""
        self.object_spec(name)
        body = self._object_body[name]
        return self.data.xpos[body].copy(), self.data.xmat[body].reshape(3, 3).copy()

    def object_quat(self, name: str) -> np.ndarray:
        """Orientation quaternion (w, x, y, z) of an object."""
        return self.data.xquat[self._object_body[name]].copy()

    def object_velocity(self, name: str) -> float:
        """Linear speed of an object (m/s)."""
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, self._object_body[name], vel, 0)
        return float(np.linalg.norm(vel[3:]))

    def arm_q(self, arm: str) -> np.ndarray:
        """Measured arm joint positions."""
        return self.data.qpos[self._arm_qadr[arm]].copy()

    def tcp_pose(self, arm: str) -> tuple[np.ndarray, np.ndarray]:
        """Measured tool-centre position and rotation matrix."""
        site = self._tcp_site[arm]
        return self.data.site_xpos[site].copy(), self.data.site_xmat[site].reshape(3, 3).copy()

    def gripper_width(self, arm: str) -> float:
        """Gap between the finger pads (m)."""
        q = self.data.qpos[self._finger_qadr[arm]] - self.data.qpos[self._finger_qadr[arm] + 1]
        return float(max(q - FINGER_GAP_OFFSET, 0.0))

    def in_contact(self, geom_a: int, geom_b: int) -> bool:
        """Whether two geoms touch at the last tick."""
        return (geom_a, geom_b) in self._contacts or (geom_b, geom_a) in self._contacts

    def holding(self, arm: str, obj: str) -> bool:
        """Contact-based grasp: both finger pads touch the object (a cloth point: the cloth near it)."""
        if obj in self._cloth_points:
            return self._holding_cloth_point(arm, obj)
        geoms = self._object_geoms[obj]
        left, right = self._finger_geoms[arm]
        return self._touches(left, geoms) and self._touches(right, geoms)

    def _touches(self, geom: int, geoms: frozenset[int]) -> bool:
        """Whether ``geom`` touches any of ``geoms`` at the last tick."""
        return any(self.in_contact(geom, g) for g in geoms)

    def touching(self, obj_a: str, obj_b: str) -> bool:
        """Whether two objects touch."""
        return any(self._touches(g, self._object_geoms[obj_b]) for g in self._object_geoms[obj_a])

    def on_table(self, obj: str) -> bool:
        """Whether the object rests on the table."""
        return self._touches(self.model.geom("table").id, self._object_geoms[obj])

    def arm_base(self, arm: str) -> np.ndarray:
        """Position of the arm's shoulder (its waist axis) in the world."""
        return self.data.xpos[self.model.body(f"{ARM_PREFIX[arm]}/shoulder_link").id].copy()

    # ---------------------------------------------------------------- cameras
    @property
    def camera_names(self) -> list[str]:
        """The scene's cameras."""
        return [mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(self.model.ncam)]

    def open_camera(self, name: str, width: int = 320, height: int = 240) -> DepthCamera:
        """A rendering camera of this world (close it when done): depth, geometry, object labels.

        Raises:
            KeyError: No such camera.
        """
        if name not in self.camera_names:
            raise KeyError(f"no camera {name!r} in the scene (cameras: {', '.join(self.camera_names)})")
        return DepthCamera(self.model, name, width, height, object_names=self.object_names, data=self.data)

    # ------------------------------------------------------------------ cloth
    @property
    def cloth_radius(self) -> float:
        """Half the cloth's thickness (m); 0 without a cloth."""
        return float(self.scene.cloth.radius) if self.scene.cloth is not None else 0.0

    @property
    def cloth_point_names(self) -> list[str]:
        """Named points of the scene's cloth (its corners ``{cloth}_bl`` ...); empty without a cloth."""
        return list(self._cloth_points)

    def cloth_point(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """A cloth point's position and its horizontal outward direction (from the diagonal
        neighbour inside the cloth to the corner; unit, or zero when they are above each other)."""
        try:
            corner, inner = self._cloth_points[name]
        except KeyError:
            raise UnknownObjectError(f"no cloth point {name!r} in the scene (points: {', '.join(self._cloth_points)})") from None
        verts = self.data.flexvert_xpos
        pos = verts[self._cloth_vert0 + corner].copy()
        out = pos - verts[self._cloth_vert0 + inner]
        out[2] = 0.0
        norm = float(np.linalg.norm(out))
        return pos, out / norm if norm > 1e-6 else np.zeros(3)

    def cloth_vertices(self) -> np.ndarray:
        """Positions of the cloth's vertices (n x 3)."""
        cloth = self.scene.cloth
        if cloth is None:
            return np.zeros((0, 3))
        n = cloth.count[0] * cloth.count[1]
        return self.data.flexvert_xpos[self._cloth_vert0 : self._cloth_vert0 + n].copy()

    def cloth_speed(self) -> float:
        """Largest speed of a cloth vertex (m/s); 0 without a cloth."""
        cloth = self.scene.cloth
        if cloth is None:
            return 0.0
        n = cloth.count[0] * cloth.count[1]
        bodies = self.model.flex_vertbodyid[self._cloth_vert0 : self._cloth_vert0 + n]
        dofs = self.model.body_dofadr[bodies]
        vel = np.stack([self.data.qvel[d : d + 3] for d in dofs if d >= 0]) if len(dofs) else np.zeros((1, 3))
        return float(np.linalg.norm(vel, axis=1).max())

    def touching_cloth(self, arm: str) -> bool:
        """Whether either finger pad of ``arm`` touches the cloth."""
        return any(g in self._finger_cloth_contacts for g in self._finger_geoms[arm])

    def _holding_cloth_point(self, arm: str, name: str) -> bool:
        # Cloth between the pads: fingers closed on nothing but resting on the cloth do not count.
        if not self._finger_cloth_contacts or self.gripper_width(arm) < CLOTH_MIN_PINCH:
            return False
        pos = self.data.flexvert_xpos[self._cloth_vert0 + self._cloth_points[name][0]]
        for geom in self._finger_geoms[arm]:
            contacts = self._finger_cloth_contacts.get(geom)
            if contacts is None or np.linalg.norm(contacts - pos, axis=1).min() > CLOTH_HOLD_RADIUS:
                return False
        return True
