"""A person's hand: takes an object out of the gripper and sets it down on the table.

The paper's real-world protocol has a person pull the object out of the gripper
during motion. A person does not throw it: they lift it out of the open fingers,
carry it and set it down somewhere on the table, upright or on its side. The hand
is physical: a wrench on the object's body (xfrc_applied), a PD law tracking a
minimum-jerk path, recomputed every physics step, with the force capped at what
a hand exerts. The object still collides with the fingers, the arm, other objects
and the table; nothing is teleported.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation, Slerp

#: PD gains of the hand on the object's position (1/s^2, 1/s) and orientation: ~4 Hz, damped.
POS_KP, POS_KD = 600.0, 50.0
ROT_KP, ROT_KD = 300.0, 35.0
#: Largest force (N) and torque (N m) the hand applies, and the largest linear (m/s^2, beyond
#: gravity) and angular (rad/s^2) accelerations it may give a light object (a fork must not fly).
MAX_FORCE = 25.0
MAX_TORQUE = 1.5
MAX_ACCEL = 30.0
MAX_ANGULAR_ACCEL = 150.0
#: Seconds of each phase: out of the fingers, carried over the spot, lowered, held still before letting go.
OUT_S, CARRY_S, LOWER_S, HOLD_S = 0.3, 0.9, 0.3, 0.3
#: Seconds to lift the object over things in the way before the carry, and to bring it down after.
RISE_S = 0.3
#: Height (m) the object's resting pose is carried above before it is lowered, and released above.
CARRY_CLEARANCE = 0.05
RELEASE_CLEARANCE = 0.001
#: Out of the fingers, a person holds the object clear of a gripper still moving faster than this
#: (m/s) before carrying it off (else the arm runs into it again), at most this long (s).
MOVING_TOOL_SPEED = 0.05
MAX_CLEAR_HOLD_S = 1.5


def min_jerk(s: float) -> float:
    """Minimum-jerk time scaling on [0, 1]."""
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


@dataclass(frozen=True)
class Waypoint:
    """A pose the hand brings the object to, ``seconds`` after the previous one."""

    pos: np.ndarray
    rotation: Rotation
    seconds: float


#: Where a gripper is now: its position and rotation matrix (world frame).
ToolPose = Callable[[], tuple[np.ndarray, np.ndarray]]


class PersonHand:
    """Carries one body along waypoints, then lets go.

    Args:
        model: The MuJoCo model.
        data: Its data (xfrc_applied is written every physics step while carrying).
        body: Id of the object's body.
        waypoints: Poses to reach in turn; the first segment starts at the object's pose now.
        tool: The pose of the gripper the object is taken out of. Given, the first segment (out of
            the fingers) moves with that gripper, and the object is held there, clear of it, while
            the gripper still moves (at most :data:`MAX_CLEAR_HOLD_S`): a person takes the object
            out of the hand wherever the arm goes meanwhile, and does not carry it back into the
            arm's way. The next segment starts where the object was held.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, body: int, waypoints: list[Waypoint],
                 tool: ToolPose | None = None) -> None:
        self.model, self.data, self.body = model, data, body
        self.mass = float(model.body_subtreemass[body])
        self.inertia = float(np.max(model.body_inertia[body]))
        start = Waypoint(data.xpos[body].copy(), Rotation.from_matrix(data.xmat[body].reshape(3, 3)), 0.0)
        self._segments = list(zip([start, *waypoints[:-1]], waypoints, strict=True))
        # One interpolator per segment, built once: the reference is read every physics step.
        self._slerps = [Slerp([0.0, 1.0], Rotation.concatenate([a.rotation, b.rotation])) for a, b in self._segments]
        self._tool = tool
        if tool is not None:
            # The first segment's ends in the gripper's frame at the grab.
            tool_pos, tool_rot = tool()
            self._out_local = [tool_rot.T @ (w.pos - tool_pos) for w in self._segments[0]]
            self._tool_pos = tool_pos
        self._held_clear = 0.0
        self._t = 0.0
        self.done = False

    def _out_ends(self, tool: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """The first segment's ends in the world, following the gripper at ``tool`` (position, rotation)."""
        tool_pos, tool_rot = tool
        return tool_pos + tool_rot @ self._out_local[0], tool_pos + tool_rot @ self._out_local[1]

    def _leave_tool(self, tool: tuple[np.ndarray, np.ndarray]) -> None:
        """Out of the fingers and clear: the rest of the path is the world's, from where the object is held."""
        out_end = self._out_ends(tool)[1]
        self._tool = None
        a, b = self._segments[0]
        self._segments[0] = (a, Waypoint(out_end, b.rotation, b.seconds))
        nxt_a, nxt_b = self._segments[1]
        self._segments[1] = (Waypoint(out_end, nxt_a.rotation, nxt_a.seconds), nxt_b)

    def _reference(self, tool: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, Rotation]:
        """The pose the object should have now; ``tool``: the gripper's pose while the object follows it."""
        t = self._t
        for k, ((a, b), slerp) in enumerate(zip(self._segments, self._slerps, strict=True)):
            if t <= b.seconds or (k == 0 and tool is not None):
                s = min_jerk(t / b.seconds)
                start, end = self._out_ends(tool) if k == 0 and tool is not None else (a.pos, b.pos)
                return start + s * (end - start), slerp([s])[0]
            t -= b.seconds
        last = self._segments[-1][1]
        return last.pos, last.rotation

    def _advance(self, dt: float, tool: tuple[np.ndarray, np.ndarray] | None) -> None:
        """Move the path's clock on; out of the fingers, wait while the gripper still moves."""
        if tool is not None:
            speed = float(np.linalg.norm(tool[0] - self._tool_pos)) / dt
            self._tool_pos = tool[0]
            out_s = self._segments[0][1].seconds
            if self._t + dt > out_s:
                if speed > MOVING_TOOL_SPEED and self._held_clear < MAX_CLEAR_HOLD_S:
                    self._t = out_s
                    self._held_clear += dt
                    return
                self._leave_tool(tool)
        self._t += dt

    @property
    def duration(self) -> float:
        """Seconds of the path from the grip to the release (not counting time held clear of a moving gripper)."""
        return sum(b.seconds for _, b in self._segments)

    def apply(self, dt: float) -> None:
        """Set the wrench for the next physics step (zero once the object is set down)."""
        wrench = self.data.xfrc_applied[self.body]
        if self._t >= self.duration:
            wrench[:] = 0.0
            self.done = True
            return
        tool = self._tool() if self._tool is not None else None  # read once per physics step
        pos_ref, rot_ref = self._reference(tool)
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, self.body, vel, 0)
        omega, lin = vel[:3], vel[3:]
        pos = self.data.xpos[self.body]
        accel = POS_KP * (pos_ref - pos) - POS_KD * lin
        force = self.mass * (accel - self.model.opt.gravity)
        rot = Rotation.from_matrix(self.data.xmat[self.body].reshape(3, 3))
        err = (rot_ref * rot.inv()).as_rotvec()
        torque = self.inertia * (ROT_KP * err - ROT_KD * omega)
        max_force = min(MAX_FORCE, self.mass * (MAX_ACCEL + 9.81))
        max_torque = min(MAX_TORQUE, self.inertia * MAX_ANGULAR_ACCEL)
        wrench[:3] = force * min(1.0, max_force / max(np.linalg.norm(force), 1e-9))
        wrench[3:] = torque * min(1.0, max_torque / max(np.linalg.norm(torque), 1e-9))
        self._advance(dt, tool)


def set_down_path(
    pos: np.ndarray,
    rotation: Rotation,
    out_dir: np.ndarray,
    spot: np.ndarray,
    rest_height: float,
    rest_rotation: Rotation,
    out_distance: float = 0.10,
    over: float | None = None,
) -> list[Waypoint]:
    """Waypoints of a take-and-set-down: out of the fingers along ``out_dir``, over ``spot``, down.

    Args:
        pos: The object's centre now (m).
        rotation: Its orientation now (kept while it slides out of the fingers).
        out_dir: Unit direction out of the open fingers (away from the palm).
        spot: (x, y) on the table where it is set down.
        rest_height: Height (m) of the object's centre when it rests in ``rest_rotation``.
        rest_rotation: Orientation it is set down in (upright or on its side).
        out_distance: How far (m) it slides out of the fingers (a long object, taken out along
            its length, needs more than its half length).
        over: Height (m) the object's centre must keep while it crosses to the spot, where
            something stands in the way (None: nothing does). Above both ends of the carry, the
            hand lifts it first, carries it across at that height and brings it down over the spot.
    """
    out = pos + out_distance * out_dir + np.array([0.0, 0.0, 0.03])
    above = np.array([spot[0], spot[1], rest_height + CARRY_CLEARANCE])
    down = np.array([spot[0], spot[1], rest_height + RELEASE_CLEARANCE])
    carry = [Waypoint(above, rest_rotation, CARRY_S)]
    if over is not None and over > min(out[2], above[2]):
        # A person lifts a bottle over the cup rather than sweeping it through (a straight carry
        # knocked the cup over).
        lift = max(over, out[2], above[2])
        carry = [
            Waypoint(np.array([out[0], out[1], lift]), rotation, RISE_S),
            Waypoint(np.array([spot[0], spot[1], lift]), rest_rotation, CARRY_S),
            Waypoint(above, rest_rotation, RISE_S),
        ]
    return [
        Waypoint(out, rotation, OUT_S),
        *carry,
        Waypoint(down, rest_rotation, LOWER_S),
        # A person lets go once it is still: a bottle laid on its side does not roll away.
        Waypoint(down, rest_rotation, HOLD_S),
    ]
