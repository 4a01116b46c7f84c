"""Seeded disturbances: the paper's random drop and its real-world disturbance kinds.

Kinds, each modelled on what a person (or a gripper fault) does to the scene; all
are physical (forces and gripper faults, never teleports). docs/disturbances.md
states the models and the landing statistics ``benchmarks/bench_disturbances.py``
measures.

- ``drop``: the held object falls from where it is held: the gripper is forced
  open for a moment.
- ``pull``: a person takes the held object out of the gripper during motion and
  sets it down on the table, upright or (a tall object) on its side, at a seeded
  spot 6-25 cm from where it was taken (a person's hand: ``hand.PersonHand``).
- ``perturb``: the object being grasped is pushed a few centimetres (2-5 cm)
  before the fingers close. Pushes are gentle (at most 3 m/s^2, and slow enough that a tall
  object slides instead of tipping).
- ``shift``: a target the action refers to (the cup the bottle approaches;
  for an action without an object, the free object nearest the tool) slides
  5-8 cm.
- ``knock``: an upright object nobody holds, taller than wide, is knocked over (a push high
  on it); a plate or a tray cannot be knocked over.

Two schedules. :class:`RandomDisturbances` draws once per atomic action
started (probability ``p``, a moment within the action, a kind): the paper's
simulated protocol, a stream that two strategies with the same seed consume
identically for their n-th action. :class:`ProtocolDisturbances` is the
paper's real-world protocol: one or two disturbances at random moments of
each trial. Scripted variants inject one chosen disturbance, for tests.
Presets (:data:`PRESETS`): ``real`` = perturb + pull (the paper's Table II),
``stress`` = every kind (its Fig. 4 style stress test).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.features.frame import FeatureFrame
from agentchord.harness import (
    KINDS,
    PROTOCOL_WINDOW,
    Disturbance,
    DisturbanceEvent,
    DisturbanceSetting,
    RunningAction,
    parse_kinds,
)
from agentchord.sim.hand import OUT_S, set_down_path
from agentchord.sim.scene import TABLE_FRICTION
from agentchord.sim.world import CONTROL_HZ, SimWorld

#: How long a gripper fault forces the fingers open (ticks at 50 Hz).
FAULT_TICKS = 12
#: ... and a pull: until the person's hand has taken the object out of the fingers (its first phase).
PULL_FAULT_TICKS = int(np.ceil(OUT_S * CONTROL_HZ)) + 3
#: How far (m) a pulled object slides out of the fingers: at least this, and its half length plus the margin.
PULL_OUT_DISTANCE = 0.10
PULL_OUT_MARGIN = 0.04
#: A person sets a pulled object down this far (m, horizontal) from where they took it ...
SET_DOWN_DISTANCE = (0.06, 0.25)
#: ... inside this part of the table (x range, y range; m): in front of the robot, off its bases ...
SET_DOWN_AREA = ((-0.32, 0.32), (0.28, 0.85))
#: ... at least this far (m, horizontal) from either arm's base, and this far clear of other objects;
#: within the robot's workspace: this far (m, horizontal) from at least one arm's shoulder (the
#: experimenter tests recovery, not reach: an object put beyond the arms is a different experiment).
SET_DOWN_BASE_CLEARANCE = 0.30
SET_DOWN_WORKSPACE = (0.36, 0.62)
SET_DOWN_OBJECT_CLEARANCE = 0.03
#: A person carries a pulled object this far (m) clear of what stands in its way, above and beside ...
CARRY_PASS_CLEARANCE = 0.02
#: ... but not over what it carries: an object over its footprint whose bottom is this far (m) above
#: its own (a capsule on a tray's 5 mm base), not one beside it on the table.
LOAD_ABOVE = 0.003
#: Share of tall objects (a bottle) a person sets down on their side rather than upright.
LYING_SHARE = 0.3
#: A perturbation pushes the object being grasped this far (m), a shift this far.
PERTURB_DISTANCE = (0.02, 0.05)
SHIFT_DISTANCE = (0.05, 0.08)
#: Largest acceleration (m/s^2, beyond sliding friction) a push gives an object.
PUSH_ACCEL = 3.0
#: Only an object at least this much taller than wide can be knocked over (not a plate, not a tray).
KNOCK_MIN_ASPECT = 1.2


def _held_by(frame: FeatureFrame, arm: str) -> list[str]:
    return sorted(obj for a, obj in frame.holding if a == arm)


#: An object slower than this (m/s) and supported by the table or another object is at rest.
RESTING_SPEED = 0.05


def _free_objects(frame: FeatureFrame, world: SimWorld) -> list[str]:
    """Objects at rest that no arm holds: what a person pushes or knocks over.

    Not one in the air (just dropped, still falling): a push at table height on it would spin it.
    """
    # Rigid bodies only: a frame may also carry feature points (a cloth's corners).
    held = {obj for _, obj in frame.holding}
    return sorted(name for name in world.object_names if name not in held and _resting(world, name))


def _resting(world: SimWorld, name: str) -> bool:
    """Whether an object is at rest on the table or on another object (not on the robot alone, not moving)."""
    supported = world.on_table(name) or any(world.touching(name, other) for other in world.object_names if other != name)
    return supported and world.object_velocity(name) < RESTING_SPEED


def _slide(world: SimWorld, obj: str, direction: np.ndarray, distance: float) -> None:
    """Push ``obj`` along ``direction`` so that it slides about ``distance`` (m) on the table, upright.

    A net acceleration a for T s beyond sliding friction, then friction stops it:
    distance = a T^2 / 2 + (a T)^2 / (2 mu g). The push is gentle, as a person's is: a is at
    most :data:`PUSH_ACCEL`, and for a tall object at most half of g * width / height (the
    inertial torque of a faster push would tip it over), and T is as long as it takes. A
    cylinder lying on its side is pushed along its axis (pushed across it, it would roll away).
    """
    spec = world.object_spec(obj)
    axis = world.object_pose(obj)[1][:, 2]
    if spec.shape == "cylinder" and abs(axis[2]) < 0.5:
        along = np.array([axis[0], axis[1], 0.0]) / max(np.linalg.norm(axis[:2]), 1e-9)
        direction = along if float(np.dot(along, direction)) >= 0.0 else -along
    mu_g = max(spec.friction, TABLE_FRICTION) * 9.81  # the contact's coefficient is the larger of the two
    accel = min(PUSH_ACCEL, 0.5 * 9.81 * spec.width / max(spec.height, 1e-3))
    seconds = np.sqrt(distance / (0.5 * accel + accel**2 / (2.0 * mu_g)))
    ticks = max(int(np.ceil(seconds * CONTROL_HZ)), 1)
    seconds = ticks / CONTROL_HZ
    # The same distance over the whole number of ticks: a^2 T^2 / (2 mu g) + a T^2 / 2 - distance = 0.
    qa, qb = seconds**2 / (2.0 * mu_g), 0.5 * seconds**2
    accel = (-qb + np.sqrt(qb * qb + 4.0 * qa * distance)) / (2.0 * qa)
    world.push(obj, spec.mass * (mu_g + accel) * direction, ticks=ticks)


def _footprint(spec) -> float:
    """Radius (m) of the circle an upright object covers on the table."""
    return float(spec.size[0]) if spec.shape == "cylinder" else float(np.hypot(spec.size[0], spec.size[1]))


def _set_down_spot(world: SimWorld, frame: FeatureFrame, obj: str, rng: np.random.Generator) -> np.ndarray:
    """A spot on the table where a person sets ``obj`` down: near where they took it, clear of things."""
    here = frame.objects[obj].pos[:2]
    spec = world.object_spec(obj)
    bases = [world.arm_base(arm)[:2] for arm in ("left", "right")]
    others = [(frame.objects[n].pos[:2], _footprint(world.object_spec(n))) for n in world.object_names if n != obj]
    radius = 0.5 * spec.height if spec.shape == "cylinder" else _footprint(spec)  # it may be set down lying
    (x_lo, x_hi), (y_lo, y_hi) = SET_DOWN_AREA
    candidate = np.clip(here, [x_lo, y_lo], [x_hi, y_hi])
    for _ in range(40):
        angle, distance = rng.uniform(0.0, 2.0 * np.pi), rng.uniform(*SET_DOWN_DISTANCE)
        candidate = here + distance * np.array([np.cos(angle), np.sin(angle)])
        if not (x_lo <= candidate[0] <= x_hi and y_lo <= candidate[1] <= y_hi):
            continue
        reach = [float(np.linalg.norm(candidate - b)) for b in bases]
        if min(reach) < SET_DOWN_BASE_CLEARANCE:
            continue
        if not any(SET_DOWN_WORKSPACE[0] <= r <= SET_DOWN_WORKSPACE[1] for r in reach):
            continue
        if all(np.linalg.norm(candidate - pos) >= radius + r + SET_DOWN_OBJECT_CLEARANCE for pos, r in others):
            return candidate
    return np.clip(candidate, [x_lo, y_lo], [x_hi, y_hi])


def _take_and_set_down(world: SimWorld, frame: FeatureFrame, obj: str, arm: str, rng: np.random.Generator,
                       spot: np.ndarray | None = None, lying: bool | None = None) -> None:
    """A person's hand takes ``obj`` out of ``arm``'s open gripper and sets it down on the table.

    ``spot`` and ``lying`` override the seeded draw (scripted disturbances).
    """
    spec = world.object_spec(obj)
    pos, matrix = world.object_pose(obj)
    tool = world.tcp_pose(arm)[1]
    approach = tool[:, 0]
    # Out of a side grasp beyond the finger tips; out of a top grasp along the gap between the pads.
    out = tool[:, 2] if abs(approach[2]) > 0.7 else approach
    out = np.array([out[0], out[1], 0.0]) / max(np.linalg.norm(out[:2]), 1e-6)
    drawn = _set_down_spot(world, frame, obj, rng)
    spot = drawn if spot is None else np.asarray(spot, dtype=float)
    yaw = Rotation.from_euler("z", rng.uniform(-np.pi, np.pi))
    tall = spec.shape == "cylinder" and spec.height > 2.0 * spec.width
    on_side = rng.random() < LYING_SHARE
    if tall and (on_side if lying is None else lying):
        rest, height = yaw * Rotation.from_euler("y", 90.0, degrees=True), 0.5 * spec.width
    else:
        rest, height = yaw, 0.5 * spec.height
    # Out of the fingers entirely: a fork taken out of a top grasp slides along its length.
    distance = max(PULL_OUT_DISTANCE, spec.half_extent_along(matrix, out) + PULL_OUT_MARGIN)
    over = _carry_height(world, frame, obj, pos[:2] + distance * out[:2], spot)
    path = set_down_path(pos, Rotation.from_matrix(matrix), out, spot, height, rest, distance, over=over)
    world.hand_carry(obj, path, out_of=arm)


def _carry_height(world: SimWorld, frame: FeatureFrame, obj: str, start: np.ndarray, spot: np.ndarray) -> float | None:
    """The height (m) ``obj``'s centre must keep to pass over what stands on the table between
    ``start`` and ``spot`` (x, y), turning as it goes; None when nothing stands in the way.

    Objects the robot holds are up in the air with it, and objects in or on ``obj`` (a capsule in
    a tray) travel with it: both are left out.
    """
    spec = world.object_spec(obj)
    # Its half diagonal (a cylinder's: radius and half height), reached whichever way it turns.
    reach = float(np.linalg.norm(spec.size[:2] if spec.shape == "cylinder" else spec.size[:3]))
    up = np.array([0.0, 0.0, 1.0])
    here, matrix = world.object_pose(obj)
    bottom = here[2] - spec.half_extent_along(matrix, up)
    held = {name for _, name in frame.holding}
    tops = []
    for name in world.object_names:
        if name == obj or name in held:
            continue
        other = world.object_spec(name)
        other_pos, other_matrix = world.object_pose(name)
        resting_on = other_pos[2] - other.half_extent_along(other_matrix, up) > bottom + LOAD_ABOVE
        if resting_on and np.linalg.norm(other_pos[:2] - here[:2]) < _footprint(spec):
            # Lifted over its own load: a tray pulled with a capsule in it would throw the capsule
            # off the table.
            continue
        if _distance_to_segment(other_pos[:2], start, spot) < _footprint(other) + reach + CARRY_PASS_CLEARANCE:
            tops.append(other_pos[2] + other.half_extent_along(other_matrix, up))
    return max(tops) + reach + CARRY_PASS_CLEARANCE if tops else None


def _distance_to_segment(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance (m) from ``point`` to the segment ``a``-``b`` (all x, y)."""
    ab = b - a
    t = float(np.clip((point - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(point - (a + t * ab)))


def _horizontal(rng: np.random.Generator) -> np.ndarray:
    angle = rng.uniform(0.0, 2.0 * np.pi)
    return np.array([np.cos(angle), np.sin(angle), 0.0])


def inject(kind: str, world: SimWorld, frame: FeatureFrame, rng: np.random.Generator,
           arm: str = "", action: RunningAction | None = None,
           direction: tuple[float, float, float] | None = None,
           spot: tuple[float, float] | None = None, lying: bool | None = None) -> DisturbanceEvent | None:
    """Apply one disturbance of ``kind`` now, if it applies to the current state.

    Args:
        kind: One of :data:`KINDS`.
        world: The world to act on.
        frame: The current features (who holds what).
        rng: Draws directions and choices (seeded by the schedule).
        arm: The arm whose action is running (drop, pull, perturb, shift).
        action: The running atomic action (its ``obj`` argument is the target).
        direction: Horizontal direction of a push or knock (None: drawn from ``rng``).
        spot: Where a pull sets the object down (None: drawn from ``rng``).
        lying: Whether a pull sets a tall object down on its side (None: drawn).

    Returns:
        The event, or None when the kind does not apply now (nothing held to
        drop, no grasp in progress to perturb, ...).

    Raises:
        ValueError: Unknown kind.
    """
    name = action.name if action is not None else ""
    target = getattr(getattr(action, "args", None), "obj", None)
    if direction is not None:
        push_dir = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    else:
        push_dir = _horizontal(rng)
    if kind in ("drop", "pull"):
        held = _held_by(frame, arm) if arm else []
        # Only a closed grip can lose its object: an opening gripper is releasing anyway.
        if not held or world.commands[arm].grip < 0.5:
            return None
        obj = held[0]
        rigid = obj in world.object_names
        two_handed = any(a != arm for a, o in frame.holding if o == obj)
        if kind == "pull" and rigid and (world.hand_busy or two_handed):
            return None  # a person takes a rigid object out of one hand (not a tray held in two)
        # A person pulling holds the fingers open until the object is out of them.
        world.inject_gripper_fault(arm, PULL_FAULT_TICKS if kind == "pull" and rigid else FAULT_TICKS)
        if kind == "pull" and rigid:
            _take_and_set_down(world, frame, obj, arm, rng, spot, lying)
        # A cloth's corner pulled out of the fingers just falls back onto the table.
        return DisturbanceEvent(world.tick, kind, obj, arm, name)
    if kind == "perturb":
        if name != "grasp" or target not in world.object_names or frame.is_holding(arm, target):
            return None
        if not _resting(world, target) and not any(obj == target for _, obj in frame.holding):
            # Not one lying on nothing but the robot's fingers (a pull set it down there) or falling
            # off them: pushed so, no table friction holds it and it goes off the table (a bottle
            # did, in a single-arm pour). One the other hand holds (a hand-over) is pushed in that hand.
            return None
        _slide(world, target, push_dir, float(rng.uniform(*PERTURB_DISTANCE)))
        return DisturbanceEvent(world.tick, kind, target, arm, name)
    if kind == "shift":
        free = _free_objects(frame, world)
        if target is None and arm and free:
            # An action without an object (a pour): move what the tool works over.
            tool = frame.arms[arm].ee
            target = min(free, key=lambda n: float(np.linalg.norm(frame.objects[n].pos[:2] - tool[:2])))
        if target is None or name == "grasp" or target not in free:
            return None
        _slide(world, target, push_dir, float(rng.uniform(*SHIFT_DISTANCE)))
        return DisturbanceEvent(world.tick, kind, target, arm, name)
    if kind == "knock":
        upright = [n for n in _free_objects(frame, world) if frame.objects[n].axis[2] > 0.9
                   and world.object_spec(n).height >= KNOCK_MIN_ASPECT * world.object_spec(n).width]
        if not upright:
            return None
        victim = target if target in upright else upright[int(rng.integers(len(upright)))]
        world.knock(victim, push_dir)
        return DisturbanceEvent(world.tick, kind, victim, "", name)
    raise ValueError(f"unknown disturbance kind {kind!r} (kinds: {', '.join(KINDS)})")


@dataclass
class RandomDisturbances:
    """With probability ``p`` per atomic action, one disturbance at a random moment within it.

    With ``kinds=("drop",)`` this is the paper's simulated disturbance. If the
    drawn kind does not apply at the drawn moment (nothing held to drop),
    nothing happens.

    Args:
        p: Probability per atomic action.
        seed: Seed of the schedule.
        kinds: Kinds to draw from.
    """

    p: float
    seed: int
    kinds: tuple[str, ...] = ("drop",)
    events: list[DisturbanceEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not 0.0 <= self.p <= 1.0:
            raise ValueError(f"disturbance probability must be in [0, 1], got {self.p}")
        parse_kinds(",".join(self.kinds))
        self._rng = np.random.default_rng([self.seed, 0xD209])
        self._pending: dict[str, tuple[int, str, RunningAction]] = {}

    def action_started(self, arm: str, action: RunningAction, expected_ticks: int, tick: int) -> None:
        """Draw whether, when and what disturbs this action."""
        # Always draw all three so the stream stays aligned across strategies.
        hit, moment, pick = self._rng.random() < self.p, self._rng.random(), self._rng.random()
        if hit:
            kind = self.kinds[int(pick * len(self.kinds))]
            self._pending[arm] = (tick + 1 + int(moment * expected_ticks), kind, action)
        else:
            self._pending.pop(arm, None)

    def action_ended(self, arm: str) -> None:
        """The action ended before its drawn moment: nothing happens."""
        self._pending.pop(arm, None)

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject a disturbance that is due now."""
        for arm, (due, kind, action) in list(self._pending.items()):
            if world.tick < due:
                continue
            del self._pending[arm]
            event = inject(kind, world, frame, self._rng, arm, action)
            if event is not None:
                self.events.append(event)
                return event
        return None


@dataclass
class ProtocolDisturbances:
    """The paper's real-world protocol: one or two disturbances at random moments of each trial.

    Moments are drawn in ticks within ``window``; at its moment a disturbance
    of a drawn kind is injected as soon as it applies (retrying for up to
    ``patience`` ticks, then trying the other kinds in order).

    Args:
        seed: Seed of the schedule.
        kinds: Kinds to draw from.
        window: Range of ticks the moments are drawn from.
        patience: Ticks a due disturbance waits for a state it applies to.
    """

    seed: int
    kinds: tuple[str, ...] = KINDS
    window: tuple[int, int] = PROTOCOL_WINDOW
    patience: int = 100
    events: list[DisturbanceEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        parse_kinds(",".join(self.kinds))
        self._rng = np.random.default_rng([self.seed, 0x9A07])
        count = int(self._rng.integers(1, 3))
        moments = sorted(int(t) for t in self._rng.integers(*self.window, size=count))
        self._due = [(t, self.kinds[int(self._rng.integers(len(self.kinds)))]) for t in moments]
        self._running: dict[str, RunningAction] = {}

    def action_started(self, arm: str, action: RunningAction, expected_ticks: int, tick: int) -> None:
        """Remember what each arm is doing (the target of perturb and shift)."""
        self._running[arm] = action

    def action_ended(self, arm: str) -> None:
        """The arm is idle."""
        self._running.pop(arm, None)

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject the next due disturbance once it applies."""
        if not self._due or world.tick < self._due[0][0]:
            return None
        due, kind = self._due[0]
        late = world.tick - due > self.patience
        order = [k for k in self.kinds if k != kind] if late else [kind]
        for candidate in order:
            for arm in sorted(self._running) or [""]:
                event = inject(candidate, world, frame, self._rng, arm, self._running.get(arm))
                if event is not None:
                    self._due.pop(0)
                    self.events.append(event)
                    return event
        if late:
            self._due.pop(0)  # nothing applies at all: skip this one
        return None


@dataclass
class ScriptedDisturbance:
    """One chosen disturbance during the ``nth`` run of ``action`` (0-based), ``after`` ticks in.

    For tests and demonstrations of one specific failure.
    """

    action: str
    kind: str = "drop"
    nth: int = 0
    after: int = 20
    seed: int = 0
    direction: tuple[float, float, float] | None = None
    spot: tuple[float, float] | None = None
    lying: bool | None = None
    events: list[DisturbanceEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        parse_kinds(self.kind)
        self._rng = np.random.default_rng([self.seed, 0x5C41])
        self._seen = 0
        self._due: tuple[str, int, RunningAction] | None = None

    def action_started(self, arm: str, action: RunningAction, expected_ticks: int, tick: int) -> None:
        """Arm the disturbance when the chosen run of the chosen action starts."""
        if action.name != self.action:
            return
        if self._seen == self.nth:
            self._due = (arm, tick + self.after, action)
        self._seen += 1

    def action_ended(self, arm: str) -> None:
        """Disarm an arm-bound disturbance whose action ended before the moment."""
        if self._due is not None and self._due[0] == arm and self.kind in ("drop", "pull", "perturb"):
            self._due = None

    def apply(self, world: SimWorld, frame: FeatureFrame) -> DisturbanceEvent | None:
        """Inject when due."""
        if self._due is None or world.tick < self._due[1]:
            return None
        arm, _, action = self._due
        self._due = None
        event = inject(self.kind, world, frame, self._rng, arm, action, self.direction, self.spot, self.lying)
        if event is not None:
            self.events.append(event)
        return event


def ScriptedDrop(action: str, nth: int = 0, after: int = 20) -> ScriptedDisturbance:  # reads as a type
    """A drop during the ``nth`` run of ``action``, ``after`` ticks in."""
    return ScriptedDisturbance(action, "drop", nth, after)


def schedule(setting: DisturbanceSetting, seed: int) -> Disturbance | None:
    """The seeded schedule of ``setting`` for the episode of ``seed`` (None: undisturbed)."""
    if setting.protocol is not None:
        return ProtocolDisturbances(seed, setting.kinds, setting.window)
    return RandomDisturbances(setting.p, seed, setting.kinds) if setting.p > 0 else None
