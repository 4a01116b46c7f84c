"""Which objects still move: the goal is judged on a scene that has come to rest."""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable

import numpy as np

from agentchord.features.frame import FeatureFrame
from agentchord.worlds.protocol import CONTROL_HZ

#: Speed (m/s) under which an object counts as at rest (the grasp's own wait for rest uses the same).
REST_SPEED = 0.02


class MotionWatch:
    """Object speeds over the last few ticks, from the feature frames.

    Speeds are taken over ``span`` ticks, not one: RGB-D frames refresh at 10 Hz (every 5 ticks),
    and a one-tick difference between two refreshes would read as rest.

    Args:
        objects: The objects watched (those the graph names; absent from a frame, skipped).
        span: Ticks the speed is measured over.
    """

    def __init__(self, objects: Iterable[str], span: int = 5) -> None:
        self.objects = tuple(objects)
        self._positions: deque[dict[str, np.ndarray]] = deque(maxlen=span + 1)

    def observe(self, frame: FeatureFrame) -> None:
        """Record one tick's object positions."""
        self._positions.append({n: frame.objects[n].pos.copy() for n in self.objects if n in frame.objects})

    def moving(self, speed: float = REST_SPEED) -> list[str]:
        """The watched objects faster than ``speed`` (m/s) over the recorded ticks, in graph order."""
        if len(self._positions) < 2:
            return []
        first, last = self._positions[0], self._positions[-1]
        seconds = (len(self._positions) - 1) / CONTROL_HZ
        return [n for n in self.objects if n in first and n in last
                and float(np.linalg.norm(last[n] - first[n])) / seconds > speed]
