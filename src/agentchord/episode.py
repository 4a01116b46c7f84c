"""One seeded episode, end to end: scene, world, graph, strategy, disturbance."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from agentchord.agents.exceptions import ReasonerError
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.pipeline import ReasonerRepairer, Replanner, augment_task, compose_task, make_reasoner, plan_task
from agentchord.agents.scene import Scene
from agentchord.agents.rules.goals import GoalSpec
from agentchord.execution.baselines.progress import GoalEvents
from agentchord.execution.background import FallbackPlan, ScriptedPlan, ThreadedPlan
from agentchord.execution.baselines.strategies import BaselineContext
from agentchord.execution.executor import Executor, ExecutorConfig
from agentchord.harness import UNDISTURBED, Disturbance, DisturbanceSetting, SuccessTracker
from agentchord.execution.methods import PIPELINED_METHODS, is_baseline, make_method
from agentchord.execution.reasoning import ReasoningConfig
from agentchord.execution.repair import Repairer
from agentchord.execution.result import EpisodeResult
from agentchord.graph.exceptions import GraphNotRunnableError
from agentchord.graph.grounding import require_runnable
from agentchord.graph.models import Success, TaskGraph
from agentchord.library import load_task_graph
from agentchord.worlds.protocol import World
from agentchord.worlds.remote import RemoteWorld
from agentchord.sim.disturbances import schedule
from agentchord.sim.tasks import SIM_TASKS, GoalTracker, judge_by_goal
from agentchord.sim.trial import open_world


@dataclass
class EpisodeSpec:
    """Everything that determines an episode: the same spec gives the same episode.

    Attributes:
        task: Simulated task name.
        strategy: A method of :data:`~agentchord.execution.methods.METHODS`: ``agentchord``,
            ``agentchord-bt`` or a baseline (``inner-monologue``, ``doremi``, ``rekep``, ``code-as-monitor``).
        seed: Seeds the scene (object instances, poses) and the disturbance schedule.
        graph: The graph to run; None = the task library's graph.
        config: Budgets.
        disturbances: How the episode is disturbed (random per-action draws at ``p``, or a
            protocol); the seed draws its schedule.
        perception: ``oracle`` or ``rgbd`` features.
        repairer: Online repair of unanticipated failures (None: none, unless planned).
        instruction: Plan the graph from this instruction with ``reasoner`` on the
            episode's first observation (instead of a library or given graph).
        goal: Plan from this goal spec instead of reading ``instruction``.
        reasoner: ``rules`` (offline) or ``llm``.
        repair: Online repair through the reasoner; None = on when the graph is planned.
        reasoning: The latency model and the simulated VQA (None: no reasoning charged for
            AgentChord's strategies, the defaults for the baselines).
        world: The address of a world served by another process (``tcp://host:port``, see
            ``agentchord serve``); None: the simulator in this process. Same seed, same episode.
        background: The rest of a pipelined plan, known in advance (``graph`` is then the composed
            graph the robot starts on): an LLM episode's latencies replayed offline.
        arranger_fallback: When a pipelined LLM plan's arranger or conductor fails (the endpoint down,
            every reply refused), the offline ones write the branches instead; off, the robot goes on
            with the monitors derived from the edges' constraints only (``bench``: an outage is an
            error to rerun, not a result).
    """

    task: str
    strategy: str = "agentchord"
    seed: int = 0
    graph: TaskGraph | None = None
    config: ExecutorConfig | None = None
    disturbances: DisturbanceSetting = UNDISTURBED
    perception: str = "oracle"
    disturbance: Disturbance | None = None
    repairer: Repairer | None = None
    instruction: str | None = None
    goal: GoalSpec | None = None
    reasoner: str = "rules"
    repair: bool | None = None
    reasoning: ReasoningConfig | None = None
    world: str | None = None
    background: ScriptedPlan | None = None
    arranger_fallback: bool = True

    @property
    def planned(self) -> bool:
        """Whether the graph is planned by the agents at the start of the episode."""
        return self.graph is None and (self.instruction is not None or self.goal is not None)

    def make_disturbance(self) -> Disturbance | None:
        """The seeded disturbance schedule this spec asks for."""
        return self.disturbance if self.disturbance is not None else schedule(self.disturbances, self.seed)


def run_episode(spec: EpisodeSpec, on_tick: Callable[[Executor], None] | None = None) -> EpisodeResult:
    """Run one episode, on the simulator in this process or on the world at ``spec.world``.

    Raises:
        KeyError: Unknown task.
        ValueError: Unknown strategy.
        GraphNotRunnableError: The graph fails ``graph check`` or names objects the scene lacks.
        RemoteWorldError: The remote world did not answer or refused the trial.
    """
    if spec.task not in SIM_TASKS:
        raise KeyError(f"unknown task {spec.task!r} (tasks: {', '.join(SIM_TASKS)})")
    if spec.world is None:
        return _run_in(open_world(spec.task, spec.seed), spec, on_tick)
    with RemoteWorld(spec.world, spec.task, spec.seed) as world:
        return _run_in(world, spec, on_tick)


def run_episode_on(world: World, spec: EpisodeSpec, on_tick: Callable[[Executor], None] | None = None) -> EpisodeResult:
    """Run the episode of ``spec`` on a world the caller opened (a fresh trial of its task and seed):
    a driver of your own, or a world another loop steps (:class:`agentchord.gym.AgentChordExpert`).

    Raises:
        KeyError: Unknown task.
        ValueError: Unknown strategy.
        GraphNotRunnableError: The graph fails ``graph check`` or names objects the scene lacks.
    """
    if spec.task not in SIM_TASKS:
        raise KeyError(f"unknown task {spec.task!r} (tasks: {', '.join(SIM_TASKS)})")
    return _run_in(world, spec, on_tick)


def _run_in(world: World, spec: EpisodeSpec, on_tick: Callable[[Executor], None] | None) -> EpisodeResult:
    """The episode of ``spec`` on ``world`` (a fresh trial of its task and seed)."""
    task = SIM_TASKS[spec.task]
    repairer = spec.repairer
    calls = []
    first_scene: Scene | None = None
    goal_spec: GoalSpec | None = spec.goal
    background = spec.background
    if spec.planned:
        regions = task_regions(task)
        reasoner = make_reasoner(spec.reasoner, goal=spec.goal, watch_visibility=spec.perception == "rgbd")
        first_scene = observe(world, regions, spec.perception)
        if spec.reasoner == "llm" and spec.strategy in PIPELINED_METHODS:
            # The robot starts on the composed graph; the arranger and conductor answer while it moves.
            graph = compose_task(spec.instruction or "", first_scene, reasoner, task=spec.task)
            calls = list(reasoner.calls)
            background = ThreadedPlan(_augmenting(graph, first_scene, reasoner, world, spec.task, spec.arranger_fallback))
        else:
            planned = plan_task(spec.instruction or "", first_scene, reasoner, task=spec.task)
            graph, calls = planned.graph, planned.calls
        goal_spec = goal_spec or getattr(reasoner, "last_goal", None)
        tracker = planned_goal_tracker(spec.task, goal_spec, graph, first_scene)
        if repairer is None and spec.repair is not False:
            repairer = ReasonerRepairer(reasoner, regions)
    else:
        graph = spec.graph or load_task_graph(spec.task)
        tracker = graph_goal_tracker(spec.task, graph)
        if repairer is None and spec.repair:
            repairer = ReasonerRepairer(make_reasoner("rules"), task_regions(task))
    # A graph that fails `graph check` or names objects this scene lacks is refused before the first tick.
    source = "planned graph" if spec.planned else "graph" if spec.graph is not None else f"{spec.task} library graph"
    require_runnable(graph, [*world.object_names, *world.cloth_point_names], spec.task, source)
    context = None
    if is_baseline(spec.strategy):
        context = _baseline_context(spec, task, world, graph, first_scene, goal_spec)
    strategy = make_method(spec.strategy, spec.reasoning, context, tuple(calls))
    executor = Executor(
        graph=graph,
        world=world,
        strategy=strategy,
        tracker=tracker,
        disturbance=spec.make_disturbance(),
        disturbance_setting=spec.disturbances if spec.disturbance is None else None,
        seed=spec.seed,
        config=spec.config if spec.config is not None else ExecutorConfig(pace=getattr(task, "pace", 1.0)),
        on_tick=on_tick,
        perception=spec.perception,
        repairer=repairer,
        background=background,
    )
    result = executor.run()
    # The agents' calls came before the first tick: they open the trace.
    result.trace.events[:0] = [{"tick": 0, "event": "reasoner_call", **call.to_trace_event()} for call in calls]
    return result


def _augmenting(nominal: TaskGraph, scene: Scene, reasoner, world: World, task: str, fallback: bool = True):
    """The background work of a pipelined LLM plan: arranger, filter, conductor, then the same checks a
    graph passes before it runs (a failure is the episode's to survive, not a crash).

    With ``fallback``, a plan that fails (the endpoint down, every reply refused) is written by the
    offline arranger and conductor instead, if they can (:class:`FallbackPlan`: the trace names the
    LLM's error and who wrote the branches); if they cannot either, the LLM's failure stands.
    """
    names = [*world.object_names, *world.cloth_point_names]

    def work() -> tuple[TaskGraph, list]:
        first = len(reasoner.calls)
        try:
            planned = augment_task(nominal, scene, reasoner)
            require_runnable(planned.graph, names, task, "planned graph")
        except (ReasonerError, GraphNotRunnableError) as error:
            if not fallback:
                raise
            try:
                offline = augment_task(nominal, scene, make_reasoner("rules"))
                require_runnable(offline.graph, names, task, "planned graph")
            except (ReasonerError, GraphNotRunnableError):
                raise error from None
            raise FallbackPlan(offline.graph, list(reasoner.calls[first:]), error, "rules") from error
        return planned.graph, list(reasoner.calls[first:])

    return work


def graph_goal_tracker(task_name: str, graph: TaskGraph) -> SuccessTracker:
    """The success check a graph file asks for (its ``success``): the task's own, or the graph's own goal."""
    task = SIM_TASKS[task_name]
    if graph.success.judge == "task":
        return task.success_tracker()
    goal = GoalSpec.model_validate(graph.success.goal_spec) if graph.success.goal_spec else None
    return judge_by_goal(goal, graph.node(graph.goal).constraints, getattr(task, "regions", {}))


def planned_goal_tracker(task_name: str, goal: GoalSpec | None, graph: TaskGraph, scene: Scene) -> SuccessTracker:
    """The success check of an episode planned from an instruction or a goal spec.

    A task with no fixed goal (``blocks_and_cup``) judges the goal it was planned for. A paper
    task keeps its own check (the pour event, the handover to its target region) when the
    plan's instruction is the task's own, or the planned goal has the same outcome as the
    task's own instruction read in the same scene;
    a new combination in its scene (the bottle handed over, the block set on a side of the
    table) is judged by its planned goal instead, not reported as a failure of the paper's task.
    """
    task = SIM_TASKS[task_name]
    tracker = task.success_tracker()
    constraints = graph.node(graph.goal).constraints
    regions = getattr(task, "regions", {})
    if hasattr(tracker, "expect"):
        tracker.expect(goal, constraints, regions)
        return tracker
    if goal is None or _is_own_instruction(task_name, graph.instruction) or goal.outcome() == _own_goal_outcome(task_name, scene):
        return tracker
    return judge_by_goal(goal, constraints, regions)


def planned_success(graph: TaskGraph, task: str, goal: GoalSpec | None, scene: Scene) -> TaskGraph:
    """``graph`` saying what success means for it (its ``success``), as the run of a planned graph judges it.

    The same choice as ``run --instruction`` makes (:func:`planned_goal_tracker`): the task's own
    instruction, or a goal with its outcome, keeps the task's check; any other goal (the bottle
    handed over in the pour scene, a hand-over the other way) is judged by its goal spec and the
    goal node's constraints.
    """
    own_goal = isinstance(planned_goal_tracker(task, goal, graph, scene), GoalTracker)
    spec = goal.model_dump(mode="json") if goal is not None and own_goal else None
    return graph.model_copy(update={"success": Success(judge="goal" if own_goal else "task", goal_spec=spec)})


def _is_own_instruction(task_name: str, instruction: str) -> bool:
    """Whether ``instruction`` is the task library's own for ``task_name`` (case and spacing aside)."""
    try:
        own = load_task_graph(task_name).instruction
    except KeyError:
        return False
    return " ".join(own.lower().split()) == " ".join(instruction.lower().split()) != ""


def _own_goal_outcome(task_name: str, scene: Scene) -> frozenset | None:
    """The outcome of the task library's instruction for ``task_name``, grounded in ``scene``."""
    from agentchord.agents.exceptions import ReasonerError
    from agentchord.agents.rules.instructions import ground_instruction

    try:
        return ground_instruction(load_task_graph(task_name).instruction, scene).outcome()
    except (KeyError, ReasonerError):
        return None


def _baseline_context(spec: EpisodeSpec, task, world: World, graph: TaskGraph, first: Scene | None,
                      goal: GoalSpec | None) -> BaselineContext:
    """A baseline's re-planner (the project's agents, from the current observation) and progress watcher."""
    from agentchord.agents.exceptions import ReasonerError
    from agentchord.agents.rules.instructions import ground_instruction

    regions = task_regions(task)
    if first is None:
        first = observe(world, regions, spec.perception)
    instruction = spec.instruction or graph.instruction
    if goal is None:
        try:
            goal = ground_instruction(instruction, first)
        except ReasonerError:
            goal = None
    descriptions = {o.name: o.description for o in first.objects}
    if goal is None:  # nothing the re-planner can read: the baseline cannot re-plan
        return BaselineContext(seed=spec.seed, descriptions=descriptions)
    replanner = Replanner(spec.reasoner, instruction, goal, first, regions, spec.task)
    events = GoalEvents(goal, [*world.object_names, *world.cloth_point_names])
    return BaselineContext(seed=spec.seed, replanner=replanner, events=events, descriptions=descriptions)
