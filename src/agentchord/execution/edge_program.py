"""Edge programs: an edge's steps compiled into one interruptible program.

A step runs one atomic action per arm at once (both arms = synchronous); the
step ends when every arm's action has ended, then the next step starts.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from agentchord.actions.base import ArmAction, Status
from agentchord.actions.controller import RobotController
from agentchord.actions.library import Grasp, MoveToTarget, Place, make_action
from agentchord.actions.motion import grip, move_joints
from agentchord.graph.models import Edge

#: Called with (arm, action) whenever an atomic action starts or ends.
ActionHook = Callable[[str, ArmAction], None]


class EdgeProgram:
    """The program of one edge (nominal or recovery).

    Args:
        edge_id: Id of the edge (or a label for a synthetic program).
        target: The node reached when the program succeeds.
        steps: Per step, the arm actions to run together.
        kind: ``nominal``, ``recovery`` or ``backtrack``.
        edge: The edge it was compiled from (None for a synthetic program). Kept because an
            edge made at run time (a re-plan's arm-switch alternative) is in no graph.
    """

    def __init__(self, edge_id: str, target: str, steps: list[list[ArmAction]], kind: str, edge: Edge | None = None) -> None:
        self.edge_id = edge_id
        self.edge = edge
        self.target = target
        self.steps = steps
        self.kind = kind
        self.step_index = 0
        self.failure_reason: str | None = None
        #: The action whose failure ended the program (None while it has not failed).
        self.failed_action: ArmAction | None = None
        #: 1 for a program's first run; a recovery bound again after the scene changed under it is its 2nd.
        self.attempt = 1
        #: Whether it failed because an object was not where an earlier step left it (:class:`ObjectGone`).
        self.scene_changed = False
        self.on_action_start: ActionHook = lambda arm, action: None
        self.on_action_end: ActionHook = lambda arm, action: None

    @classmethod
    def from_edge(cls, edge: Edge) -> EdgeProgram:
        """Compile a graph edge's steps into arm actions."""
        steps = [[make_action(call.fn, arm, call.args) for arm, call in step.items() if call is not None] for step in edge.steps]
        _link_grasps_to_places(steps)
        _link_handoffs_to_later_moves(steps)
        return cls(edge.id, edge.target, steps, edge.kind, edge=edge)

    @property
    def running(self) -> list[ArmAction]:
        """The actions of the current step."""
        return self.steps[self.step_index] if self.step_index < len(self.steps) else []

    def initialise(self, robot: RobotController) -> None:
        """Start the first step from the robot's current state."""
        self.step_index = 0
        self._start_step(robot)

    def _start_step(self, robot: RobotController) -> None:
        for action in self.running:
            action.initialise(robot)
            self.on_action_start(action.arm, action)

    def update(self, robot: RobotController) -> Status:
        """Advance every running action one tick."""
        try:
            return self._update(robot)
        finally:
            robot.free_arms = frozenset()

    def _update(self, robot: RobotController) -> Status:
        while self.step_index < len(self.steps):
            statuses = []
            for action in self.running:
                if action.status == Status.RUNNING:
                    # An arm whose part of the step is done may be moved aside by the other's action.
                    robot.free_arms = frozenset(robot.targets) - {a.arm for a in self.running if a.status == Status.RUNNING}
                    status = action.update(robot)
                    if status != Status.RUNNING:
                        self.on_action_end(action.arm, action)
                statuses.append(action.status)
            if Status.FAILURE in statuses:
                failed = next(a for a in self.running if a.status == Status.FAILURE)
                self.failure_reason = f"{failed.describe()}: {failed.failure_reason}"
                self.failed_action = failed
                self.scene_changed = failed.object_gone
                self.terminate(Status.INVALID)
                return Status.FAILURE
            if Status.RUNNING in statuses:
                return Status.RUNNING
            # Every arm finished this step: start the next one within the same tick.
            self.step_index += 1
            if self.step_index < len(self.steps):
                self._start_step(robot)
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        """Interrupt: stop every running action (arms hold their commanded poses)."""
        for action in self.running:
            if action.status == Status.RUNNING:
                action.terminate(new_status)
                self.on_action_end(action.arm, action)


def _link_grasps_to_places(steps: list[list[ArmAction]]) -> None:
    """Give each grasp the later place of its object by its arm (for ``skip_if_placed``)."""
    for i, step in enumerate(steps):
        for action in step:
            if not isinstance(action, Grasp):
                continue
            later = (a for s in steps[i + 1:] for a in s
                     if isinstance(a, Place) and a.arm == action.arm and a.args.obj == action.args.obj)
            action.placed_by = next(later, None)


def _link_handoffs_to_later_moves(steps: list[list[ArmAction]]) -> None:
    """Give each hand-off place (``within_reach``) the points later steps move a tool to."""
    for i, step in enumerate(steps):
        for action in step:
            if isinstance(action, Place) and action.args.within_reach is not None:
                action.carried_to = tuple(np.asarray(a.args.pos[:2], dtype=float) for s in steps[i + 1:] for a in s
                                          if isinstance(a, MoveToTarget))


class ReturnToKeyframe(ArmAction):
    """Backtracking's motion: move an arm back to a node's recorded keyframe."""

    name = "return_to_keyframe"

    def __init__(self, arm: str, q: np.ndarray, grip_value: float) -> None:
        super().__init__(arm, args=None)  # type: ignore[arg-type]
        self.q = q
        self.grip_value = grip_value

    def script(self, robot: RobotController):
        if self.grip_value < 0.5 <= robot.targets[self.arm].grip:
            yield from grip(robot, self.arm, self.grip_value, ticks=6)
        yield from move_joints(robot, self.arm, self.q)
        robot.set_pose(self.arm, robot.ik.tcp_pose(self.arm))
        if self.grip_value >= 0.5 > robot.targets[self.arm].grip:
            yield from grip(robot, self.arm, self.grip_value)

    def describe(self) -> str:
        return f"{self.arm}.return_to_keyframe"
