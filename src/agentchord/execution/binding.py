"""Binding a recovery to the scene: wait for what fell to come to rest, or for the hold to come back.

A recovery that begins with a grasp cannot start while its object is still falling or sliding:
the arms hold still until every object it takes is at rest on the table, then the first candidate
whose grasps are feasible starts (the executor's ``_bind``).

A hold lost for a moment can also come back by itself: a gripper that opened for a fraction of a
second and closed again on an object that rested on a finger (a bottle tilted in a pour) holds it
again. The monitor fired rightly (the grasp signal was gone for its whole persistence window), but
a regrasp would throw away a grasp that holds. So while the recovery waits, the interrupted edge
is kept suspended, not ended; when every lost object is back in the hand that held it, sitting
where it sat (:data:`RECATCH_OFFSET`, :data:`RECATCH_TILT_DEG` in the hand's frame) for the failure
mode's own persistence window (the debounce that made it fire, Eq. 12, makes it clear), the failure
has cleared and the edge resumes where it stopped. An
object caught lower or askew (a bottle that slid 5 cm down the fingers) is not resumed: its
recovery runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from agentchord.execution.edge_program import EdgeProgram
from agentchord.features.frame import FeatureFrame
from agentchord.solvers.poses import quat_to_rotation

#: Object speed (m/s) under which it counts as at rest, and for how many ticks in a row.
REST_SPEED = 0.03
REST_TICKS = 10
#: Height (m) under which an object's lower axis end must be to count as resting on the table.
RESTING_HEIGHT = 0.05
#: A hold that came back counts as the same hold when the object's centre is within this (m) ...
RECATCH_OFFSET = 0.03
#: ... and its principal axis within this (deg) of where they were in the hand's frame (the bound of
#: the arranger's slipped-grasp monitors, ``tipped(obj, 20)``: a hold the carrying edges accept) ...
RECATCH_TILT_DEG = 20.0
#: A hold last seen more than this many ticks before a failure was not lost by it.
RECENT_HOLD_TICKS = 30


@dataclass(frozen=True)
class Hold:
    """Where an object sat in a hand.

    Attributes:
        arm: The arm holding it.
        obj: The object.
        offset: Object centre in the tool frame (m).
        axis: Object principal axis in the tool frame (unit).
        tick: Tick it was seen.
    """

    arm: str
    obj: str
    offset: np.ndarray
    axis: np.ndarray
    tick: int

    @classmethod
    def seen(cls, frame: FeatureFrame, arm: str, obj: str) -> Hold:
        """The hold of ``obj`` by ``arm`` in ``frame`` (whether or not the fingers grip it now)."""
        arm_feats, obj_feats = frame.arms[arm], frame.objects[obj]
        return cls.of(arm, obj, arm_feats.ee, arm_feats.ee_quat, obj_feats.pos, obj_feats.axis, frame.tick)

    @classmethod
    def of(cls, arm: str, obj: str, ee: np.ndarray, ee_quat: np.ndarray, pos: np.ndarray, axis: np.ndarray,
           tick: int) -> Hold:
        """The hold of an object at ``pos`` along ``axis`` by a tool at ``ee`` turned by ``ee_quat`` (w, x, y, z)."""
        to_tool = quat_to_rotation(ee_quat).as_matrix().T
        return cls(arm, obj, to_tool @ (pos - ee), to_tool @ axis, tick)

    def same_as(self, other: Hold) -> bool:
        """Whether ``other`` puts the object where this hold had it (see the module docstring)."""
        cos = float(np.clip(np.dot(self.axis, other.axis), -1.0, 1.0))
        return (float(np.linalg.norm(self.offset - other.offset)) <= RECATCH_OFFSET
                and float(np.degrees(np.arccos(cos))) <= RECATCH_TILT_DEG)


@dataclass
class HoldMemory:
    """The last sighting of every (arm, object) pair in a grasp, refreshed every tick.

    Only the poses are kept each tick (on the executor's tick loop); the hold in the tool frame is
    worked out when a failure asks for it.

    Attributes:
        last: Per (arm, object), the tick, tool position and quaternion, object centre and axis at
            the last tick the arm held the object.
    """

    last: dict[tuple[str, str], tuple] = field(default_factory=dict)

    def observe(self, frame: FeatureFrame) -> None:
        """Record the holds of this tick's frame (rigid objects only)."""
        for arm, obj in frame.holding:
            feats = frame.objects.get(obj)
            if feats is not None and not feats.is_point:
                tool = frame.arms[arm]
                self.last[(arm, obj)] = (frame.tick, tool.ee.copy(), tool.ee_quat.copy(), feats.pos.copy(), feats.axis.copy())

    def lost(self, frame: FeatureFrame, arms: set[str], objects: list[str]) -> list[Hold] | None:
        """The recent holds of ``objects`` by ``arms`` that no arm holds now.

        None unless every one of ``objects`` was held a moment ago by one of ``arms`` and is in
        no hand now: only then can the failure clear by the hold coming back.
        """
        holds = []
        for obj in objects:
            if any(o == obj for _, o in frame.holding):
                return None
            recent = [Hold.of(arm, o, ee, quat, pos, axis, tick) for (arm, o), (tick, ee, quat, pos, axis) in self.last.items()
                      if o == obj and arm in arms and frame.tick - tick <= RECENT_HOLD_TICKS]
            if not recent:
                return None
            holds.extend(recent)
        return holds


@dataclass
class Binding:
    """A recovery waiting to bind its arm: the candidates (entry edge, then its alternatives).

    Attributes:
        candidates: Programs to try in order.
        objects: What their first grasps take: bound once these are at rest.
        since: Tick the recovery began.
        previous: Object positions at the last tick (for their speed).
        still: Ticks in a row every object has been at rest.
        suspended: The interrupted edge, kept to resume if the lost holds come back (else None).
        lost: The holds whose return clears the failure.
        failure: The failure mode that fired (for the trace).
        window: Ticks in a row the lost holds must be back to clear it (the mode's persistence window).
        recovering_from: The executor's recovery context before this failure (restored on resume).
        recaught: Ticks in a row every lost hold has been back.
    """

    candidates: list[EdgeProgram]
    objects: list[str]
    since: int
    previous: dict[str, np.ndarray] = field(default_factory=dict)
    still: int = 0
    suspended: EdgeProgram | None = None
    lost: list[Hold] = field(default_factory=list)
    failure: str = ""
    window: int = 3
    recovering_from: str | None = None
    recaught: int = 0

    def at_rest(self, frame: FeatureFrame, control_hz: float) -> bool:
        """Count this tick toward rest; whether every object has been at rest long enough."""
        speeds = [np.linalg.norm(frame.objects[o].pos - self.previous[o]) * control_hz
                  for o in self.objects if o in self.previous]
        self.previous = {o: frame.objects[o].pos.copy() for o in self.objects}
        # At rest on the table: still, and low (a hand pausing mid-air is not a resting place).
        still = len(speeds) == len(self.objects) and max(speeds) < REST_SPEED and not self.aloft(frame)
        self.still = self.still + 1 if still else 0
        return self.still >= REST_TICKS

    def aloft(self, frame: FeatureFrame) -> bool:
        """Whether some object's lower end is above the table (in a person's hand, on another object,
        a cloth's corner hanging from a hand that holds another)."""
        return any(min(frame.objects[o].bottom[2], frame.objects[o].top[2]) >= RESTING_HEIGHT for o in self.objects)

    def rigid(self, frame: FeatureFrame) -> bool:
        """Whether some object is a rigid body, not a cloth's corner (a point feature)."""
        return any(not frame.objects[o].is_point for o in self.objects)

    def holds_back(self, frame: FeatureFrame) -> bool:
        """Count this tick toward a cleared failure; whether every lost hold has been back long enough."""
        if self.suspended is None:
            return False
        back = all(frame.is_holding(h.arm, h.obj) and h.same_as(Hold.seen(frame, h.arm, h.obj)) for h in self.lost)
        self.recaught = self.recaught + 1 if back else 0
        return self.recaught >= self.window
