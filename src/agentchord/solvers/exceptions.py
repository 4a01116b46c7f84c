"""Exceptions of the constrained solvers (sub-goal and receding-horizon path).

Each failure has its own class; every one is a :class:`SolverError`. A solver that
ran but could not meet its hard constraints attaches what it found, so a caller can
still inspect (or knowingly use) the best compromise.
"""

from __future__ import annotations

from typing import Any


class SolverError(Exception):
    """Base class of the solvers' errors."""


class SolverProblemError(SolverError, ValueError):
    """A problem description is malformed (unknown arm, empty bounds, wrong shapes)."""


class InfeasibleSubgoalError(SolverError):
    """The sub-goal solver found no point meeting every hard constraint (raised on request only).

    Attributes:
        solution: The best compromise found (a :class:`~agentchord.solvers.subgoal_problem.SubgoalSolution`);
            ``solution.violations`` says which constraints fail.
    """

    # The solvers import this module, never the reverse: the attached results are typed ``Any``.
    def __init__(self, message: str, solution: Any) -> None:
        self.solution = solution
        super().__init__(message)

    def __reduce__(self) -> tuple[Any, ...]:
        # The bench runner ships errors between processes: keep the attached result.
        return (type(self), (str(self), self.solution))


class PathNotReachedError(SolverError):
    """``plan_path`` ran out of solves before the tool reached the goal (raised on request only).

    Attributes:
        path: What was executed before giving up (a :class:`~agentchord.solvers.path.ExecutedPath`).
    """

    def __init__(self, message: str, path: Any) -> None:
        self.path = path
        super().__init__(message)

    def __reduce__(self) -> tuple[Any, ...]:
        # The bench runner ships errors between processes: keep the attached result.
        return (type(self), (str(self), self.path))


class NoHandoffSpotError(SolverError):
    """No spot on the table is reachable by both arms and clear of the other objects.

    Attributes:
        obj: The object to set down.
        placer: The arm that would set it down.
        taker: The arm that would take it.
    """

    def __init__(self, obj: str, placer: str, taker: str) -> None:
        self.obj, self.placer, self.taker = obj, placer, taker
        super().__init__(f"no free spot on the table where the {placer} arm can set {obj} down for the {taker} arm")

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.obj, self.placer, self.taker))
