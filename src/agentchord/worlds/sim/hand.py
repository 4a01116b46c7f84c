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
#: Height (m) the object's resting pose is carried above before it is lowered, and released above.
CARRY_CLEARANCE = 0.05
RELEASE_CLEARANCE = 0.001


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


class PersonHand:
    """Carries one body along waypoints, then lets go.

    Args:
        model: The MuJoCo model.
        data: Its data (xfrc_applied is written every physics step while carrying).
        body: Id of the object's body.
        waypoints: Poses to reach in turn; the first segment starts at the object's pose now.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, body: int, waypoints: list[Waypoint]) -> None:
        self.model, self.data, self.body = model, data, body
        self.mass = float(model.body_subtreemass[body])
        self.inertia = float(np.max(model.body_inertia[body]))
        start = Waypoint(data.xpos[body].copy(), Rotation.from_matrix(data.xmat[body].reshape(3, 3)), 0.0)
        self._segments = list(zip([start, *waypoints[:-1]], waypoints, strict=True))
        # One interpolator per segment, built once: the reference is read every physics step.
        self._slerps = [Slerp([0.0, 1.0], Rotation.concatenate([a.rotation, b.rotation])) for a, b in self._segments]
        self._t = 0.0
        self.done = False

    def _reference(self) -> tuple[np.ndarray, Rotation]:
        t = self._t
        for (a, b), slerp in zip(self._segments, self._slerps, strict=True):
            if t <= b.seconds:
                s = min_jerk(t / b.seconds)
                return a.pos + s * (b.pos - a.pos), slerp([s])[0]
            t -= b.seconds
        last = self._segments[-1][1]
        return last.pos, last.rotation

    @property
    def duration(self) -> float:
        """Seconds from the grip to the release."""
        return sum(b.seconds for _, b in self._segments)

    def apply(self, dt: float) -> None:
        """Set the wrench for the next physics step (zero once the object is set down)."""
        wrench = self.data.xfrc_applied[self.body]
        if self._t >= self.duration:
            wrench[:] = 0.0
            self.done = True
            return
        pos_ref, rot_ref = self._reference()
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
        self._t += dt


def set_down_path(
    pos: np.ndarray,
    rotation: Rotation,
    out_dir: np.ndarray,
    spot: np.ndarray,
    rest_height: float,
    rest_rotation: Rotation,
    out_distance: float = 0.10,
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
    """
    out = pos + out_distance * out_dir + np.array([0.0, 0.0, 0.03])
    above = np.array([spot[0], spot[1], rest_height + CARRY_CLEARANCE])
    down = np.array([spot[0], spot[1], rest_height + RELEASE_CLEARANCE])
    return [
        Waypoint(out, rotation, OUT_S),
        Waypoint(above, rest_rotation, CARRY_S),
        Waypoint(down, rest_rotation, LOWER_S),
        # A person lets go once it is still: a bottle laid on its side does not roll away.
        Waypoint(down, rest_rotation, HOLD_S),
    ]
