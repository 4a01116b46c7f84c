"""User constraints of the solvers, and task-graph expressions turned into them.

A solver sees a constraint as a callable ``f(positions) -> float`` over candidate
tool-centre positions (one per arm), violated when ``> 0``: the same sign
convention as the expression language (paper Eq. 3). Node and edge constraints of
a task graph are expression strings over a feature frame; :func:`expression_costs`
compiles them once and evaluates them on a private copy of the frame in which the
arms, and whatever they hold (rigidly), sit at the candidate positions.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from agentchord.expr import Vocabulary, compile_expr
from agentchord.features.frame import FeatureFrame
from agentchord.solvers.exceptions import SolverProblemError

#: A constraint over candidate tool positions: ``{arm: (3,) position} -> value``, > 0 = violated.
PositionCost = Callable[[Mapping[str, np.ndarray]], float]


@dataclass(frozen=True)
class UserCost:
    """One user constraint of a solver problem.

    Attributes:
        fn: The constraint, ``> 0`` when violated.
        weight: Scale of its penalty ``weight * max(f, 0)^2``.
        name: Label in the solution's per-term report.
        hard: A constraint the solution must meet (an inequality of the local solver);
            otherwise only a penalty (a preference).
    """

    fn: PositionCost
    weight: float = 1.0
    name: str = ""
    hard: bool = True

    def __post_init__(self) -> None:
        if not callable(self.fn):
            raise SolverProblemError(f"UserCost {self.name!r}: fn must be callable, got {type(self.fn).__name__}")
        if not self.weight >= 0.0:
            raise SolverProblemError(f"UserCost {self.name!r}: weight must be >= 0, got {self.weight}")


class HypotheticalFrame:
    """A private copy of a feature frame whose tools can be moved to candidate positions.

    Objects an arm holds move rigidly with its tool (translation only: candidates
    are positions). Every ``place`` starts from the original frame, so the copy never
    drifts.

    Args:
        frame: The frame to copy (left untouched).
        attached: Arm -> objects that move with its tool (default: ``frame.holding``).
    """

    def __init__(self, frame: FeatureFrame, attached: Mapping[str, Iterable[str]] | None = None) -> None:
        self.frame = copy.deepcopy(frame)
        if attached is None:
            attached = {}
            for arm, obj in frame.holding:
                attached.setdefault(arm, []).append(obj)
        self.attached = {arm: tuple(objs) for arm, objs in attached.items()}
        for arm, objs in self.attached.items():
            if arm not in frame.arms:
                raise SolverProblemError(f"the frame has no arm {arm!r} (arms: {', '.join(sorted(frame.arms))})")
            for obj in objs:
                if obj not in frame.objects:
                    raise SolverProblemError(f"{arm} holds {obj!r}, which the frame does not have")
        self._ee = {arm: feats.ee.copy() for arm, feats in frame.arms.items()}
        # The fields a translation moves, per held object: (features, {field: original value}).
        self._moving = {
            arm: [
                (self.frame.objects[obj], {f: getattr(frame.objects[obj], f).copy() for f in ("pos", "top", "bottom")})
                for obj in objs
            ]
            for arm, objs in self.attached.items()
        }
        self._placed: dict[str, np.ndarray] = {}

    def place(self, positions: Mapping[str, np.ndarray]) -> FeatureFrame:
        """Put the named arms' tools at ``positions``; returns the (shared, mutated) frame copy."""
        for arm, position in positions.items():
            last = self._placed.get(arm)
            if last is not None and np.array_equal(last, position):
                continue  # several constraints read the same candidate: move once
            position = np.asarray(position, dtype=float)
            self.frame.arms[arm].ee = position.copy()
            delta = position - self._ee[arm]
            for feats, original in self._moving.get(arm, ()):
                for name, value in original.items():
                    setattr(feats, name, value + delta)
            self._placed[arm] = position.copy()
        return self.frame


def expression_costs(
    sources: Iterable[str],
    frame: FeatureFrame,
    vocabulary: Vocabulary | None = None,
    *,
    attached: Mapping[str, Iterable[str]] | None = None,
    weight: float = 1.0,
    hard: bool = True,
) -> list[UserCost]:
    """Turn constraint expressions into solver constraints over candidate tool positions.

    Example:
        ``expression_costs(["dist(right.ee, cup.top + [0, -0.09, 0.08]) - 0.01"], frame)``
        gives one constraint that holds when the right tool is within 1 cm of that point.

    Args:
        sources: Expression strings (node sub-goal or edge path constraints).
        frame: The current feature frame (what the solver plans against).
        vocabulary: Names the expressions may use (default: the frame's).
        attached: Arm -> objects that move with its tool (default: what the frame says it holds).
        weight: Penalty weight of each constraint.
        hard: Whether each is a hard constraint (see :class:`UserCost`).

    Raises:
        ExprError: An expression does not compile (its message names the part at fault).
        SolverProblemError: ``attached`` names an arm or object the frame lacks.
    """
    vocabulary = vocabulary or Vocabulary.from_frame(frame)
    compiled = [compile_expr(source, vocabulary) for source in sources]
    hypothetical = HypotheticalFrame(frame, attached)
    costs = []
    for expr in compiled:
        def fn(positions: Mapping[str, np.ndarray], _expr=expr) -> float:
            return _expr.scalar(hypothetical.place(positions))

        costs.append(UserCost(fn, weight=weight, name=expr.source, hard=hard))
    return costs
