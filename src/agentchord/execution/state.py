"""The executor's episode state, as its parts declare it for the type checker.

:class:`~agentchord.execution.executor.Executor` is built from two mixins,
:class:`~agentchord.execution.arrivals.PlanArrivals` and
:class:`~agentchord.execution.switching.RecoverySwitching`, that read and set the executor's state
and call each other's methods (and the executor's). :class:`ExecutorState`, the base of both,
declares that state once, with its types, and the methods one part calls on another; the
executor's ``__init__`` sets the attributes and the executor or a mixin defines the methods.

At run time the class adds nothing: the attributes are annotations only and the method stubs are
seen by the type checker alone (``TYPE_CHECKING``), so what a name resolves to is as without it.
Declared here, an executor's mixin is also what a recovery strategy takes
(:class:`~agentchord.execution.context.ExecutionContext`): each mixin hands ``self`` to the strategy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from collections.abc import Callable

    import numpy as np

    from agentchord.execution.background import Arrival, ScriptedPlan, ThreadedPlan
    from agentchord.execution.binding import Binding, HoldMemory
    from agentchord.execution.edge_program import EdgeProgram
    from agentchord.execution.feasibility import FeasibilityChecker
    from agentchord.execution.ledger import DisturbanceLedger
    from agentchord.execution.planning import PlanSchedule
    from agentchord.execution.repair import Repairer
    from agentchord.execution.shortcuts import Shortcuts
    from agentchord.execution.strategies import RecoveryStrategy
    from agentchord.execution.trace import Trace
    from agentchord.expr import CompiledExpr
    from agentchord.features.frame import FeatureFrame
    from agentchord.graph.models import TaskGraph
    from agentchord.monitor import Detection, EdgeMonitors, RecoveryMap
    from agentchord.worlds.protocol import World


class RecoveryBudgets(Protocol):
    """What the mixins read of the executor's :class:`~agentchord.execution.executor.ExecutorConfig`
    (not imported here: ``executor`` imports the mixins, which import this module)."""

    failure_budget: int
    max_repairs: int
    bind_wait_ticks: int
    bind_rigid_wait_ticks: int


class ExecutorState:
    """The executor's state and cross-part methods, declared for its mixins (see the module docstring)."""

    # --- the episode
    world: World
    graph: TaskGraph
    config: RecoveryBudgets
    strategy: RecoveryStrategy
    trace: Trace
    feasibility: FeasibilityChecker
    shortcuts: Shortcuts
    holds: HoldMemory
    disturbances: DisturbanceLedger
    repairer: Repairer | None
    # --- what the graph compiles to (``_compile``)
    monitors: dict[str, EdgeMonitors]
    _derived: dict[str, EdgeMonitors]
    constraints: dict[str, list[CompiledExpr]]
    recovery_map: RecoveryMap
    nominal_next: dict[str, str]
    # --- where the run is
    node: str
    visited_nominal: list[str]
    keyframes: dict[str, dict[str, tuple[np.ndarray, float]]]
    program: EdgeProgram | None
    armed: EdgeMonitors | None
    # --- failures and their recoveries (``switching``)
    binding: Binding | None
    recovering_from: str | None
    fire_counts: dict[tuple[str, str], int]
    _fallbacks: list[EdgeProgram]
    _repair_attempts: set[tuple[str, str]]
    _skipped: tuple[str, str] | None
    # --- reasoning charged
    reasoning_s: float
    reasoning_calls: dict[str, int]
    compute_s: float
    replans: int
    # --- a pipelined plan's arrivals (``arrivals``; its waits are declared there, with their type)
    schedule: PlanSchedule | None
    early_failures: list[dict[str, Any]]
    plan_wait_ticks: int
    _early_armed: str | None
    _rearm_tick: int
    still_since: int | None  # set while a recovery that waited for its branch begins
    background: ThreadedPlan | ScriptedPlan | None
    plan_error: str | None
    _incoming: tuple[int, Arrival] | None

    if TYPE_CHECKING:
        # Defined by the executor or by one of the mixins; declared here for the others.
        @property
        def frame(self) -> FeatureFrame: ...

        # executor
        def _compile(self, graph: TaskGraph) -> None: ...
        def adopt(self, graph: TaskGraph) -> None: ...
        def charge(self, kind: str, agent: str, latency_s: float, measured: bool = False, compute_s: float = 0.0,
                   tokens: int | None = None) -> None: ...
        def constraints_hold(self, node_id: str) -> bool: ...
        def describe_violation(self, node_id: str) -> str: ...
        def _step(self) -> None: ...
        def _where(self) -> str: ...
        def _node_holds(self, node_id: str) -> bool: ...
        def _arrive(self, node_id: str) -> tuple[bool, str] | None: ...
        def _start(self, program: EdgeProgram) -> None: ...
        def _arm_monitors(self, program: EdgeProgram) -> None: ...

        # switching
        def _on_failure(self, detection: Detection) -> tuple[bool, str] | None: ...
        def _on_program_failed(self) -> tuple[bool, str] | None: ...

        # arrivals
        def follow_schedule(self, schedule: PlanSchedule) -> None: ...
        def follow_background(self) -> None: ...
        def modes_unknown(self, edge_id: str) -> bool: ...
        def as_arranged(self, detection: Detection) -> Detection: ...
        def _early_failure(self, detection: Detection, suspended: EdgeProgram | None = None, since: int | None = None,
                           resume: Callable[[], tuple[bool, str] | None] | None = None) -> bool: ...
        def _early_program_failure(self) -> bool: ...
        def _wait_for_grounding(self, program: EdgeProgram) -> bool: ...
        def _unrecovered(self, detection: Detection) -> tuple[bool, str]: ...
