"""The persistence trigger of paper Eq. 12.

Mode k fires at tick t iff m_k(Phi_s) > delta_k for every s in the last tau_k
ticks: a transient violation (contact chatter, perception noise) shorter than
the window never fires.
"""

from __future__ import annotations


class PersistenceTrigger:
    """Counts consecutive violating ticks of one monitor.

    Args:
        margin: Robustness margin delta (the monitor must exceed it).
        window: Persistence window tau in ticks (>= 1).

    Raises:
        ValueError: If ``window`` is below 1.
    """

    __slots__ = ("margin", "window", "streak", "first_violation_tick")

    def __init__(self, margin: float = 0.0, window: int = 3) -> None:
        if window < 1:
            raise ValueError(f"persistence window must be >= 1 tick, got {window}")
        self.margin = margin
        self.window = window
        self.streak = 0
        #: Tick at which the current run of violations began (None when normal).
        self.first_violation_tick: int | None = None

    def update(self, value: float, tick: int = 0) -> bool:
        """Feed one tick's monitor value; True when the mode fires."""
        if value > self.margin:
            if self.streak == 0:
                self.first_violation_tick = tick
            self.streak += 1
        else:
            self.streak = 0
            self.first_violation_tick = None
        return self.streak >= self.window

    def reset(self) -> None:
        """Forget the history (a new edge starts)."""
        self.streak = 0
        self.first_violation_tick = None
