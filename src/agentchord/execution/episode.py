"""One seeded episode, end to end: scene, world, graph, strategy, disturbance."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from agentchord.execution.executor import EpisodeResult, Executor, ExecutorConfig
from agentchord.execution.strategies import make_strategy
from agentchord.graph.models import TaskGraph
from agentchord.tasks import load_task_graph
from agentchord.worlds.sim.disturbances import Disturbance, RandomDrop
from agentchord.worlds.sim.tasks import SIM_TASKS
from agentchord.worlds.sim.world import SimWorld


@dataclass
class EpisodeSpec:
    """Everything that determines an episode: the same spec gives the same episode.

    Attributes:
        task: Simulated task name.
        strategy: ``agentchord`` or ``agentchord-bt``.
        p: Drop probability per atomic action.
        seed: Seeds the scene (object instances, poses) and the disturbance schedule.
        graph: The graph to run; None = the task library's graph.
        config: Budgets.
        disturbance: A disturbance to use instead of the random drop of ``p``.
    """

    task: str
    strategy: str = "agentchord"
    p: float = 0.0
    seed: int = 0
    graph: TaskGraph | None = None
    config: ExecutorConfig | None = None
    disturbance: Disturbance | None = None


def run_episode(spec: EpisodeSpec, on_tick: Callable[[Executor], None] | None = None) -> EpisodeResult:
    """Run one episode.

    Raises:
        KeyError: Unknown task.
        ValueError: Unknown strategy or a probability outside [0, 1].
    """
    if spec.task not in SIM_TASKS:
        raise KeyError(f"unknown task {spec.task!r} (tasks: {', '.join(SIM_TASKS)})")
    task = SIM_TASKS[spec.task]
    scene = task.sample_scene(np.random.default_rng([spec.seed, 0x5CE7E]))
    world = SimWorld(scene)
    graph = spec.graph or load_task_graph(spec.task)
    executor = Executor(
        graph=graph,
        world=world,
        strategy=make_strategy(spec.strategy),
        tracker=task.success_tracker(),
        disturbance=spec.disturbance or (RandomDrop(spec.p, spec.seed) if spec.p > 0 else None),
        config=spec.config,
        on_tick=on_tick,
    )
    result = executor.run()
    result.trace.events[0].update({"seed": spec.seed, "p": spec.p})
    return result
