"""The simulated VQA model: answers from ground truth with seeded errors.

The paper's simulation gave every method ground-truth object states; a VQA query here is
answered from the constraints it asks about, evaluated on the current frame (with oracle
perception, the simulator's state), then flipped with the configured probabilities: a miss
(a failure answered "yes, it holds") or a false alarm (a success answered "no").
"""

from __future__ import annotations

import numpy as np

from agentchord.features.frame import FeatureFrame


class SimulatedVqa:
    """Yes/no answers about constraints.

    Args:
        seed: The episode's seed (the answers' errors are drawn from their own stream).
        miss: Probability of "holds" when a constraint is violated.
        false_alarm: Probability of "violated" when every constraint holds.
    """

    def __init__(self, seed: int, miss: float = 0.0, false_alarm: float = 0.0) -> None:
        self.rng = np.random.default_rng([seed, 0x76A])
        self.miss = miss
        self.false_alarm = false_alarm
        self.queries = 0
        self.errors = 0

    def holds(self, constraints: list, frame: FeatureFrame) -> bool:
        """The answer to "do these constraints all hold now?" (``constraints``: compiled expressions)."""
        truth = all(c.scalar(frame) <= 0.0 for c in constraints)
        self.queries += 1
        # One draw per query whatever the rates, so that changing a rate does not shift later answers.
        draw = float(self.rng.random())
        flip = draw < (self.false_alarm if truth else self.miss)
        self.errors += flip
        return truth != flip
