"""The episode trace: every event of an episode, written as JSON lines.

A trace is the ground truth of what happened: the path through the graph,
each disturbance, each detection and recovery switch. Metrics are computed
from it, and the same seed must give the same trace.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from agentchord.guard.outputs import atomic_write_text, finite_json


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return [round(float(v), 5) for v in value]
    if isinstance(value, (np.floating, float)):
        return round(float(value), 5)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


@dataclass
class Trace:
    """Ordered list of events ``{"tick": int, "event": str, ...}``."""

    events: list[dict[str, Any]] = field(default_factory=list)

    def add(self, tick: int, event: str, **data: Any) -> dict[str, Any]:
        """Record one event."""
        record = {"tick": tick, "event": event, **_plain(data)}
        self.events.append(record)
        return record

    def of(self, event: str) -> list[dict[str, Any]]:
        """All events of one type."""
        return [e for e in self.events if e["event"] == event]

    def write(self, path: str | Path) -> Path:
        """Write as JSON lines, atomically (a failed write leaves no half trace).

        Raises:
            OutputPathError: The file cannot be written.
        """
        text = "".join(finite_json(record, sort_keys=True) + "\n" for record in self.events)
        return atomic_write_text(path, text)

    @staticmethod
    def read(path: str | Path) -> Trace:
        """Read a trace written by :meth:`write`."""
        with Path(path).open() as stream:
            return Trace([json.loads(line) for line in stream if line.strip()])
