"""Every method of the comparison by name: AgentChord, its ablation and the four baselines."""

from __future__ import annotations

from agentchord.execution.baselines import BASELINES
from agentchord.execution.baselines.strategies import BaselineContext
from agentchord.execution.reasoning import ReasoningConfig
from agentchord.execution.strategies import STRATEGIES, RecoveryStrategy

#: The methods in the paper's column order (Table I): the baselines, then the ablation, then AgentChord
#: with the paper's sequential plan, then AgentChord (its plan pipelined: the robot moves while the agents think).
METHODS: tuple[str, ...] = ("inner-monologue", "doremi", "rekep", "code-as-monitor", "agentchord-bt",
                            "agentchord-sequential", "agentchord")
#: Short column names, as the paper's tables write them.
SHORT = {"inner-monologue": "IM", "doremi": "DRM", "rekep": "ReKep", "code-as-monitor": "CaM", "agentchord-bt": "AC-BT",
         "agentchord-sequential": "AC-seq", "agentchord": "AgentChord"}


#: The methods whose plan is pipelined: the robot moves before the arranger and conductor have answered.
PIPELINED_METHODS = frozenset({"agentchord"})


def is_baseline(name: str) -> bool:
    """Whether ``name`` is one of the four re-planning or backtracking baselines."""
    return name in BASELINES


def make_method(name: str, reasoning: ReasoningConfig | None = None, context: BaselineContext | None = None,
                planned_calls: tuple = ()) -> RecoveryStrategy:
    """A method's strategy, ready for one episode.

    Args:
        name: One of :data:`METHODS`.
        reasoning: The latency model (None: no reasoning charged, robot time only; the
            baselines always charge, with the defaults when None).
        context: A baseline's re-planner, progress and seed.
        planned_calls: The calls that planned the episode's graph (charged instead of modelled).

    Raises:
        ValueError: Unknown name.
    """
    if name in BASELINES:
        strategy: RecoveryStrategy = BASELINES[name](reasoning, context)
    elif name in STRATEGIES:
        strategy = STRATEGIES[name]()
        strategy.reasoning = reasoning
    else:
        raise ValueError(f"unknown method {name!r} (choose from: {', '.join(METHODS)})")
    strategy.planned_calls = tuple(planned_calls)
    return strategy
