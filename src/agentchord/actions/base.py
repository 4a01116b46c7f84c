"""Interruptible tick-level programs: the ``initialise / update / terminate`` lifecycle.

An atomic action is a small script written as a generator that yields once per
control tick after setting its arm's targets. The base class turns that into
py_trees' behaviour lifecycle, so the executor can interrupt any action at any
tick (a monitor fired) and the arm simply holds its last commanded pose.
"""

from __future__ import annotations

import enum
from collections.abc import Iterator
from typing import TYPE_CHECKING

from pydantic import BaseModel

if TYPE_CHECKING:
    from agentchord.actions.controller import RobotController


class Status(enum.Enum):
    """Lifecycle status of a program (py_trees' Status)."""

    INVALID = "INVALID"
    RUNNING = "RUNNING"
    SUCCESS = "SUCCESS"
    FAILURE = "FAILURE"


class ActionFailed(Exception):
    """Raised inside a script when the action cannot go on (e.g. nothing to grasp)."""


class ObjectGone(ActionFailed):
    """The object is not where the edge's earlier steps left it (not in the hand to place): the scene
    changed under the action, rather than the action being unable to do its part."""


class ArmAction:
    """One arm's atomic action.

    Subclasses set ``name`` and implement :meth:`script`.

    Args:
        arm: ``left`` or ``right``.
        args: The validated arguments (the catalogue's pydantic model).
    """

    name = "action"

    def __init__(self, arm: str, args: BaseModel) -> None:
        self.arm = arm
        self.args = args
        self.status = Status.INVALID
        self.failure_reason: str | None = None
        #: Whether it failed with :class:`ObjectGone`.
        self.object_gone = False
        self._script: Iterator[None] | None = None

    def initialise(self, robot: RobotController) -> None:
        """Start (or restart) the action from the robot's current state."""
        self.status = Status.RUNNING
        self.failure_reason = None
        self.object_gone = False
        self._script = self.script(robot)

    def update(self, robot: RobotController) -> Status:
        """Advance one control tick."""
        if self._script is None:
            raise RuntimeError(f"{self.name}: update() before initialise()")
        try:
            next(self._script)
        except StopIteration:
            self.status = Status.SUCCESS
        except ActionFailed as exc:
            self.failure_reason = str(exc)
            self.object_gone = isinstance(exc, ObjectGone)
            self.status = Status.FAILURE
        return self.status

    def terminate(self, new_status: Status) -> None:
        """Stop the script; when interrupted the arm holds its last commanded pose."""
        if self._script is not None:
            self._script.close()
            self._script = None
        if self.status == Status.RUNNING:
            self.status = new_status

    def script(self, robot: RobotController) -> Iterator[None]:
        """The action's tick-by-tick script; yields once per control tick."""
        raise NotImplementedError

    def describe(self) -> str:
        """Short text for traces and video overlays."""
        fields = ", ".join(f"{k}={v}" for k, v in self.args.model_dump().items())
        return f"{self.arm}.{self.name}({fields})"
