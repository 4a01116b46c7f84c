"""Compiled monitors: a failure mode's expression plus its persistence trigger."""

from __future__ import annotations

from dataclasses import dataclass, field

from agentchord.expr import CompiledExpr, Vocabulary, compile_expr
from agentchord.features.frame import FeatureFrame
from agentchord.graph.models import Edge, FailureMode
from agentchord.monitor.trigger import PersistenceTrigger


@dataclass
class CompiledMonitor:
    """One failure mode of one edge, ready to evaluate every tick (paper Eq. 11-12)."""

    edge_id: str
    failure: FailureMode
    expr: CompiledExpr
    trigger: PersistenceTrigger = field(init=False)

    def __post_init__(self) -> None:
        self.trigger = PersistenceTrigger(self.failure.margin, self.failure.window)


@dataclass
class Detection:
    """A failure mode that fired.

    Attributes:
        edge_id: The edge that was active.
        failure: The failure mode that fired.
        tick: Tick it fired at.
        onset_tick: First tick of the run of violations that made it fire.
        value: The monitor's value when it fired.
    """

    edge_id: str
    failure: FailureMode
    tick: int
    onset_tick: int
    value: float


class EdgeMonitors:
    """The monitors of the active edge, evaluated together every tick."""

    def __init__(self, monitors: list[CompiledMonitor]) -> None:
        self.monitors = monitors

    @classmethod
    def compile(cls, edge: Edge, vocabulary: Vocabulary) -> EdgeMonitors:
        """Compile every failure mode of an edge."""
        return cls([CompiledMonitor(edge.id, f, compile_expr(f.monitor, vocabulary)) for f in edge.failures])

    def reset(self) -> None:
        """Clear the persistence history (the edge (re)starts)."""
        for monitor in self.monitors:
            monitor.trigger.reset()

    def evaluate(self, frame: FeatureFrame) -> Detection | None:
        """Evaluate all monitors on a frame; the first that fires, if any."""
        fired = None
        for monitor in self.monitors:
            value = monitor.expr.scalar(frame)
            if monitor.trigger.update(value, frame.tick) and fired is None:
                fired = Detection(monitor.edge_id, monitor.failure, frame.tick, monitor.trigger.first_violation_tick, value)
        return fired

    def watching(self, arm: str, obj: str) -> list[CompiledMonitor]:
        """The monitors that read both ``arm`` and ``obj`` (what watches that arm's hold of it)."""
        return [m for m in self.monitors if arm in m.expr.arms and obj in m.expr.objects]

    def violated_now(self, frame: FeatureFrame, scene_only: bool = False) -> Detection | None:
        """The first monitor violated on this frame alone, persistence aside (a state to explain, not a transient).

        Args:
            frame: The frame to read.
            scene_only: Read only monitors of the objects alone, none that reads an arm (a
                closed-gripper monitor reads as violated until its edge opens the hand).
        """
        for monitor in self.monitors:
            if scene_only and monitor.expr.arms:
                continue
            value = monitor.expr.scalar(frame)
            if value > monitor.failure.margin:
                return Detection(monitor.edge_id, monitor.failure, frame.tick, frame.tick, value)
        return None
