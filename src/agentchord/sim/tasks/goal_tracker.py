"""Judge an episode by the goal it was planned for, for tasks with no fixed success check.

The judge reads the world (not the planner's constraints): an object is *inside* a
container when it rests, released, within the container's footprint and below its rim;
*on* a support when its bottom rests on the support's top within its footprint; *placed*
when it rests released at the stated place (a named region, a table point, or beside an
anchor where the anchor is at the end) with the stated yaw. Two predicates are events during
the episode, watched frame by frame: *poured* (the source, held, tilted to pour with its
mouth over the target, as the pouring tasks judge it) and *handed over* (both arms held the
object, then the receiver alone, off the table). A predicate it cannot judge physically
(folded) falls back to the planned graph's goal-node constraints.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.harness import Verdict
from agentchord.sim.tasks.base import pouring, resting_on_table
from agentchord.sim.tasks.rearrange_table import yaw_error_deg
from agentchord.sim.world import SimWorld

#: Largest speed (m/s) of an object at rest.
REST_SPEED = 0.02
#: How a predicate that fails only because its object still moves ends its reason.
STILL_MOVING = "is still moving"
#: How far (m) a placed object's centre may lie from a stated table point (the handover
#: task's target region has the same radius).
POINT_TOLERANCE = 0.04
#: How far (m) from its place beside an anchor (the rearrange task's tolerance).
BESIDE_TOLERANCE = 0.03
#: How far (deg) a placed object's long axis may be from a stated yaw (as rearrange table).
YAW_TOLERANCE_DEG = 20.0


@dataclass
class GoalTracker:
    """Success = the goal predicates hold at the end.

    Attributes:
        goal: The goal spec (:class:`~agentchord.agents.rules.goals.GoalSpec`), if known.
        constraints: The planned graph's goal-node constraints (the fallback).
        regions: Named regions (name -> (centre, radius)) for placed-in-region goals.
    """

    goal: object | None = None
    constraints: list[str] = field(default_factory=list)
    regions: dict = field(default_factory=dict)
    #: Events seen so far: ("poured", source, target) and ("handed_over", obj) when they happened,
    #: ("both_held", obj) once both arms held it.
    events: set = field(default_factory=set)

    def expect(self, goal: object | None, constraints: list[str], regions: dict | None = None) -> None:
        """Tell the tracker what the episode was planned to achieve."""
        self.goal, self.constraints, self.regions = goal, list(constraints), dict(regions or {})

    def observe(self, frame: FeatureFrame) -> None:
        """Watch one tick for the goal's events: a pour, a handover."""
        for goal in getattr(self.goal, "goals", []):
            kind = getattr(goal, "kind", "")
            if kind == "poured" and ("poured", goal.source, goal.target) not in self.events:
                held = any(name == goal.source and (goal.arm is None or arm == goal.arm) for arm, name in frame.holding)
                if held and pouring(frame.objects[goal.source], frame.objects[goal.target]):
                    self.events.add(("poured", goal.source, goal.target))
            elif kind == "handed_over" and ("handed_over", goal.obj) not in self.events:
                giver, receiver = frame.is_holding(goal.giver, goal.obj), frame.is_holding(goal.receiver, goal.obj)
                if giver and receiver:
                    self.events.add(("both_held", goal.obj))
                elif receiver and ("both_held", goal.obj) in self.events and frame.objects[goal.obj].bottom[2] > 0.02:
                    self.events.add(("handed_over", goal.obj))

    def verdict(self, frame: FeatureFrame, world: SimWorld) -> Verdict:
        """Judge every goal predicate on the end state."""
        if self.goal is None and not self.constraints:
            return Verdict(False, "no goal was given to judge this task by (plan it from an instruction or a goal spec)")
        failures: list[str] = []
        judged_all = self.goal is not None
        for goal in getattr(self.goal, "goals", []):
            reason = self._judge(goal, frame, world)
            if reason is None:
                judged_all = False
            elif reason:
                failures.append(reason)
        if not judged_all and self.constraints:
            failures += self._constraints(frame)
        if failures:
            # Only motion wrong: the executor judges again once things are at rest.
            settling = all(f.endswith(STILL_MOVING) for f in failures)
            return Verdict(False, "; ".join(failures), settling=settling)
        return Verdict(True, "every goal predicate holds at the end")

    def _judge(self, goal, frame: FeatureFrame, world: SimWorld) -> str | None:
        """'' when the predicate holds, a reason when not, None when it cannot be judged here."""
        kind = getattr(goal, "kind", "")
        if kind == "poured":
            seen = ("poured", goal.source, goal.target) in self.events
            return "" if seen else f"the {goal.source} never reached a pouring orientation above the {goal.target}"
        if kind == "handed_over":
            if ("handed_over", goal.obj) in self.events:
                return ""
            return f"the {goal.obj} was never handed over from the {goal.giver} arm to the {goal.receiver} arm"
        if kind not in ("inside", "on_top_of", "placed"):
            return None
        obj = frame.objects[goal.obj]
        held = any(name == goal.obj for _, name in frame.holding)
        if held:
            return f"the {goal.obj} is still held"
        if world.object_velocity(goal.obj) > REST_SPEED:
            return f"the {goal.obj} {STILL_MOVING}"
        if kind in ("inside", "on_top_of"):
            host_name = goal.container if kind == "inside" else goal.support
            host = frame.objects[host_name]
            offset = float(np.linalg.norm(obj.pos[:2] - host.pos[:2]))
            reach = 0.5 * float(min(host.extent[0], host.extent[1]))
            if offset > reach:
                return f"the {goal.obj} is {100 * offset:.1f} cm from the {host_name}'s centre (more than its half-width {100 * reach:.1f} cm)"
            if kind == "inside" and obj.bottom[2] > host.top[2]:
                return f"the {goal.obj} is not inside the {host_name} (its bottom is above the rim)"
            if kind == "on_top_of" and abs(float(obj.bottom[2] - host.top[2])) > 0.015:
                return f"the {goal.obj} does not rest on the {host_name} (gap {100 * float(obj.bottom[2] - host.top[2]):.1f} cm)"
            return ""
        if goal.region and goal.region in self.regions:
            centre, radius = self.regions[goal.region][:2]
            error = float(np.linalg.norm(obj.pos[:2] - np.asarray(centre)))
            if error > radius:
                return f"the {goal.obj} is {100 * error:.1f} cm from the {goal.region} region (radius {100 * radius:.0f} cm)"
        elif goal.at is not None:
            error = float(np.linalg.norm(obj.pos[:2] - np.asarray(goal.at)))
            if error > POINT_TOLERANCE:
                return (f"the {goal.obj} is {100 * error:.1f} cm from its place ({goal.at[0]:.2f}, {goal.at[1]:.2f}) "
                        f"(tolerance {100 * POINT_TOLERANCE:.0f} cm)")
        elif goal.relative_to is not None:
            place = frame.objects[goal.relative_to].pos[:2] + np.asarray(goal.offset)
            error = float(np.linalg.norm(obj.pos[:2] - place))
            if error > BESIDE_TOLERANCE:
                return (f"the {goal.obj} is {100 * error:.1f} cm from its place beside the {goal.relative_to} "
                        f"(tolerance {100 * BESIDE_TOLERANCE:.0f} cm)")
        if goal.yaw is not None:
            yaw_error = yaw_error_deg(obj.quat, goal.yaw)
            if yaw_error > YAW_TOLERANCE_DEG:
                return f"the {goal.obj} is {yaw_error:.0f} deg off its stated yaw {goal.yaw:.0f} deg"
        if not resting_on_table(world, goal.obj, frame):
            return f"the {goal.obj} is not resting on the table"
        return ""

    def _constraints(self, frame: FeatureFrame) -> list[str]:
        from agentchord.expr import Vocabulary, compile_expr

        vocabulary = Vocabulary(frozenset(frame.objects))
        failed = []
        for source in self.constraints:
            value = compile_expr(source, vocabulary)(frame)
            if not value <= 0.0:
                failed.append(f"{source} = {value:.3g} (should be <= 0)")
        return failed
