"""One seeded episode, end to end: scene, world, graph, strategy, disturbance."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from agentchord.execution.executor import EpisodeResult, Executor, ExecutorConfig
from agentchord.execution.strategies import make_strategy
from agentchord.graph.models import TaskGraph
from agentchord.tasks import load_task_graph
from agentchord.worlds.sim.disturbances import Disturbance, ProtocolDisturbances, RandomDisturbances
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
        disturb: Disturbance kinds drawn (``drop`` is the paper's simulated one).
        protocol: The paper's real-world protocol: one or two disturbances of the
            ``disturb`` kinds at random moments, whatever ``p``.
        disturbance: A disturbance schedule to use instead (tests, scripted demos).
        perception: ``oracle`` or ``rgbd`` features.
    """

    task: str
    strategy: str = "agentchord"
    p: float = 0.0
    seed: int = 0
    graph: TaskGraph | None = None
    config: ExecutorConfig | None = None
    disturb: tuple[str, ...] = ("drop",)
    protocol: bool = False
    perception: str = "oracle"
    disturbance: Disturbance | None = None

    def make_disturbance(self) -> Disturbance | None:
        """The seeded disturbance schedule this spec asks for."""
        if self.disturbance is not None:
            return self.disturbance
        if self.protocol:
            return ProtocolDisturbances(self.seed, self.disturb)
        return RandomDisturbances(self.p, self.seed, self.disturb) if self.p > 0 else None


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
        disturbance=spec.make_disturbance(),
        config=spec.config,
        on_tick=on_tick,
        perception=spec.perception,
    )
    result = executor.run()
    result.trace.events[0].update({"seed": spec.seed, "p": spec.p})
    return result
