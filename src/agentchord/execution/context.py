"""What a recovery strategy may read and ask of the executor running it.

The executor hands itself to its strategy; the strategy names only this protocol, so
``strategies`` does not import ``executor`` (which imports ``strategies``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from agentchord.execution.background import ScriptedPlan, ThreadedPlan
    from agentchord.execution.edge_program import EdgeProgram
    from agentchord.execution.planning import PlanSchedule
    from agentchord.execution.trace import Trace
    from agentchord.expr import CompiledExpr
    from agentchord.features.frame import FeatureFrame
    from agentchord.graph.models import TaskGraph
    from agentchord.monitor import EdgeMonitors, RecoveryMap
    from agentchord.worlds.protocol import World


class ExecutionContext(Protocol):
    """The executor, as its recovery strategy sees it.

    Attributes:
        graph: The (filtered) augmented graph being run.
        frame: The feature frame of this tick (read-only: the executor's perception owns it).
        trace: The episode's trace.
        node: The last node reached.
        program: The edge program running now (None between edges).
        nominal_next: Nominal node -> the nominal edge out of it.
        recovery_map: (edge, failure mode) -> recovery entry edges (Eq. 13).
        monitors: Edge id -> its compiled monitors.
        visited_nominal: Nominal nodes reached so far, in order.
        keyframes: Nominal node -> per arm (joint targets, grip) when it was reached.
        compute_s: The planner's own work measured in this process so far (s).
        world: The world being run (its ``tick``).
        replans: Re-plans adopted so far.
        constraints: Node id -> its compiled sub-goal constraints.
        background: The rest of a pipelined plan being asked in the background (None: none, or it has replied).
    """

    graph: TaskGraph
    trace: Trace
    node: str
    program: EdgeProgram | None
    nominal_next: dict[str, str]
    recovery_map: RecoveryMap
    monitors: dict[str, EdgeMonitors]
    visited_nominal: list[str]
    keyframes: dict[str, dict[str, tuple[np.ndarray, float]]]
    compute_s: float
    world: World
    replans: int
    constraints: dict[str, list[CompiledExpr]]

    @property
    def frame(self) -> FeatureFrame:
        """The feature frame of this tick."""
        ...

    @property
    def background(self) -> ThreadedPlan | ScriptedPlan | None:
        """The background plan, if one is being asked (a strategy reads whether there is one)."""
        ...

    def charge(self, kind: str, agent: str, latency_s: float, measured: bool = False, compute_s: float = 0.0,
               tokens: int | None = None) -> None:
        """Charge one blocking reasoning call (the robot holds still while it answers)."""
        ...

    def follow_schedule(self, schedule: PlanSchedule) -> None:
        """Plan with a pipelined schedule: the robot moves at its first motion, the rest arrives at its ticks."""
        ...

    def follow_background(self) -> None:
        """Start on the composed graph; the rest of the plan is asked in the background."""
        ...

    def adopt(self, graph: TaskGraph) -> None:
        """Run a re-planned graph from now on (the re-planning baselines)."""
        ...

    def constraints_hold(self, node_id: str) -> bool:
        """Whether a node's sub-goal constraints hold on the current frame."""
        ...
