"""The episode commands: ``agentchord run`` (one episode, its path through the graph) and
``agentchord demo`` (seeded episodes of each strategy, a table per strategy)."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from agentchord.cli.support import (
    PERCEPTION_NAMES,
    REASONER_NAMES,
    BadInput,
    FiniteFloatRange,
    check_outputs,
    disturbance_setting,
    check_graph_source,
    check_rendered,
    check_served,
    check_task_name,
    failed_calls_trace,
    load_goal_option,
    catches_sigterm,
)
from agentchord.guard.outputs import atomic_write_text, finite_json

STRATEGY_NAMES = ("agentchord", "agentchord-bt")
#: Every method `run` and `demo` accept: AgentChord, its ablation, AgentChord with the paper's sequential plan and
#: the four baselines (`bench` compares them; named here so the command line loads without the executor).
METHOD_NAMES = (*STRATEGY_NAMES, "agentchord-sequential", "inner-monologue", "doremi", "rekep", "code-as-monitor")
DISTURB_HELP = "Disturbance kinds, comma-separated: drop, pull, perturb, shift, knock."
PROTOCOL_NAMES = ("real", "stress", "custom")
PROTOCOL_HELP = ("1-2 disturbances at random moments of each trial (ignores --p): 'real' = perturb + pull (the paper's "
                 "real-world protocol, Table II), 'stress' = all five kinds; bare --protocol (= custom) uses --disturb.")


def _kinds(ctx, param, value: str) -> tuple[str, ...]:
    from agentchord.harness import parse_kinds

    try:
        return parse_kinds(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from exc


WORLD_HELP = ("Drive the world served at this address (tcp://HOST:PORT or tcp://[IPv6]:PORT, see `agentchord serve`) "
              "instead of the simulator in this process: same seed, same episode. A world that does not answer within "
              "$AGENTCHORD_WORLD_TIMEOUT seconds (default 120) ends the command with exit status 2.")


def _world_address(ctx, param, value: str | None) -> str | None:
    if value is None:
        return None
    from agentchord.worlds.remote import RemoteWorldError, resolve_address, timeout_from_env

    try:
        timeout_from_env()  # a bad $AGENTCHORD_WORLD_TIMEOUT is refused before any work, too
        return resolve_address(value)
    except RemoteWorldError as exc:
        raise click.BadParameter(str(exc)) from exc


@click.command()
@click.argument("task")
@click.option("--strategy", type=click.Choice(METHOD_NAMES), default="agentchord", show_default=True)
@click.option("--p", "p", type=FiniteFloatRange(0.0, 1.0), default=0.0, show_default=True, help="Disturbance probability per atomic action.")
@click.option("--disturb", default="drop", show_default=True, callback=_kinds, help=DISTURB_HELP)
@click.option("--protocol", type=click.Choice(PROTOCOL_NAMES), is_flag=False, flag_value="custom", default=None,
              help=PROTOCOL_HELP)
@click.option("--perception", type=click.Choice(PERCEPTION_NAMES), default="oracle", show_default=True)
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True)
@click.option("--graph", "graph_path", type=click.Path(exists=True, dir_okay=False), help="Graph file (default: the task library's).")
@click.option("--instruction", help="Plan the graph from this instruction on the episode's first observation.")
@click.option("--goal", "goal_path", type=click.Path(exists=True, dir_okay=False), help="Plan from a goal spec file (YAML/JSON) instead.")
@click.option("--reasoner", type=click.Choice(REASONER_NAMES), default="rules", show_default=True, help="Who plans: offline rules or an LLM.")
@click.option("--repair/--no-repair", default=None, help="Online repair of unanticipated failures (default: on for a planned graph).")
@click.option("--trace", "trace_path", type=click.Path(dir_okay=False), help="Write the trace as JSON lines.")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), help="Write the episode summary as JSON.")
@click.option("--video", "video_path", type=click.Path(dir_okay=False), help="Write an MP4 of the episode.")
@click.option("--camera", default="front", show_default=True, help="Scene camera for --video.")
@click.option("--world", "world", callback=_world_address, help=WORLD_HELP)
@click.option("--rerun", "rerun_path", type=click.Path(dir_okay=False), help="Write a Rerun recording (.rrd) of the episode (docs/data.md).")
@catches_sigterm
def run(task, strategy, p, disturb, protocol, perception, seed, graph_path, instruction, goal_path, reasoner, repair,
        trace_path, json_path, video_path, camera, world, rerun_path) -> None:
    """Run one episode of TASK and print its path through the graph.

    Exit status 0 when the task succeeded, 1 when it failed, 2 on bad input.
    """
    from agentchord.episode import EpisodeSpec

    check_task_name(task, "TASK")
    check_graph_source(task, "TASK", graph_path, instruction, goal_path)
    if world is not None:
        check_served(task, "--world")
    if video_path is not None or perception == "rgbd" or rerun_path is not None:
        check_rendered(task, "--video" if video_path is not None else "--rerun" if rerun_path is not None else "--perception rgbd")
    if world is not None and video_path is not None:
        raise click.UsageError("--video renders the simulator in this process: it cannot be used with --world")
    if world is not None and rerun_path is not None:
        raise click.UsageError("--rerun records the simulator in this process: it cannot be used with --world")
    check_outputs(("--trace", trace_path, ()), ("--json", json_path, ()), ("--video", video_path, (".mp4",)),
                  ("--rerun", rerun_path, (".rrd",)), inputs=(("--graph", graph_path), ("--goal", goal_path)))
    _check_camera(task, camera, video_path)
    rerun_log = open_rerun(rerun_path, task)
    graph = _load_graph_option(graph_path)
    goal = load_goal_option(goal_path)
    if graph is not None and (instruction or goal):
        raise click.UsageError("give either --graph or --instruction/--goal, not both")
    console = Console()
    recorder = {}

    def on_tick(executor) -> None:
        if rerun_log is not None:
            rerun_log(executor)
        if video_path is None:
            return
        if "video" not in recorder:
            from agentchord.sim.render import VideoRecorder

            recorder["video"] = VideoRecorder(executor.world, video_path, camera=camera)
            recorder["seen"] = 0
        video = recorder["video"]
        recorder["graph"] = executor.graph
        for event in executor.trace.events[recorder["seen"]:]:
            if event["event"] == "failure_detected":
                video.announce(f"FAILURE {event['failure']} on {event['edge']}")
            elif event["event"] == "recovery_switch":
                video.announce(f"RECOVERY -> {event['to']}")
            elif event["event"] == "failure_cleared":
                video.announce(f"CLEARED: {', '.join(event['objects'])} held again, {event['edge']} goes on")
            elif event["event"] == "subgoal_met":
                video.announce(f"MET: {event['node']} already holds, {event['edge']} skipped")
            elif event["event"] == "merged_ahead":
                video.announce(f"AHEAD: {', '.join(event['passed'])} done already, on from {event['to']}")
            elif event["event"] == "disturbance":
                video.announce(f"DISTURBANCE: {event['kind']} {event['obj']}", ticks=25)
        recorder["seen"] = len(executor.trace.events)
        program = executor.program
        caption = f"{task}  node {_node_words(executor.graph, executor.node)}  edge {program.edge_id if program else '-'} ({program.kind if program else ''})"
        video.capture(caption)

    spec = EpisodeSpec(task=task, strategy=strategy, seed=seed, graph=graph, disturbances=disturbance_setting(p, disturb, protocol),
                       perception=perception, instruction=instruction, goal=goal, reasoner=reasoner, repair=repair,
                       world=world)
    # Ctrl-C or SIGTERM (@catches_sigterm) release the renderer; _write_video leaves no temporary file.
    try:
        result = _run_or_explain(spec, on_tick, trace_path, graph_path)
        if "video" in recorder:
            end = next((step for step in reversed(result.path) if not step.startswith("e")), "")
            graph_ran = recorder.get("graph")
            where = _node_words(graph_ran, end) if graph_ran is not None else end
            outcome = "SUCCESS" if result.success else f"FAILURE: {result.reason}"
            recorder["video"].final(f"{task}  node {where}  (episode over)", outcome[:110])
        _print_episode(console, result)
        _write_outputs(console, [
            ("trace", trace_path, lambda: result.trace.write(trace_path)),
            ("summary", json_path, lambda: atomic_write_text(json_path, finite_json(result.summary(), indent=2) + "\n")),
            ("video", video_path if "video" in recorder else None, lambda: _write_video(recorder["video"], video_path)),
            ("rerun", rerun_path, lambda: rerun_log.close(result)),
        ])
    finally:
        if "video" in recorder:
            recorder["video"].close()
    sys.exit(0 if result.success else 1)


def _node_words(graph, node_id: str, width: int = 44) -> str:
    """``v3 (bottle tilted over the cup)``: a node id with the start of its meaning, for the video's caption."""
    try:
        semantic = graph.node(node_id).semantic
    except KeyError:
        return node_id
    return f"{node_id} ({_short(semantic, width)})" if semantic else node_id


def _load_graph_option(graph_path: str | None):
    if graph_path is None:
        return None
    from agentchord.graph.exceptions import GraphFileError
    from agentchord.graph.loader import load_graph
    from agentchord.graph.validation import check_graph

    try:
        graph = load_graph(graph_path)
    except GraphFileError as exc:
        raise BadInput(str(exc)) from exc
    problems = check_graph(graph)
    if problems:
        lines = "\n".join(f"{graph_path}: {p.path}: {p.message}" for p in problems)
        raise click.UsageError(f"the graph is not valid:\n{lines}")
    if graph.success.goal_spec is not None:
        from pydantic import ValidationError

        from agentchord.agents.rules.goals import GoalSpec

        try:
            GoalSpec.model_validate(graph.success.goal_spec)
        except ValidationError as exc:
            from agentchord.agents.rules.feasibility import spec_problems

            lines = "\n".join(f"{graph_path}: {problem}" for problem in spec_problems(exc))
            raise click.UsageError(f"the graph is not valid:\n{lines}") from None
    return graph


def _run_or_explain(spec, on_tick=None, trace_path=None, graph_path=None):
    """Run an episode; a reasoner that cannot plan, or a graph that cannot run here, is bad input (exit 2)."""
    from agentchord.agents.exceptions import ReasonerError
    from agentchord.episode import run_episode
    from agentchord.graph.exceptions import GraphNotRunnableError
    from agentchord.worlds.remote import RemoteWorldError

    try:
        return run_episode(spec, on_tick=on_tick)
    except RemoteWorldError as exc:
        raise BadInput(str(exc)) from exc
    except ReasonerError as exc:
        raise BadInput(str(exc) + failed_calls_trace(exc, trace_path)) from exc
    except GraphNotRunnableError as exc:
        source = graph_path or exc.source
        raise BadInput("the graph cannot run:\n" + "\n".join(f"{source}: {line}" for line in exc.lines)) from exc


def _check_camera(task: str, camera: str, video_path) -> None:
    """Refuse an unknown --camera before the episode, not when its first frame is drawn."""
    if video_path is None:
        return
    from agentchord.sim.trial import open_world

    cameras = open_world(task, 0).camera_names
    if camera not in cameras:
        raise click.BadParameter(f"no camera {camera!r} in the {task} scene (cameras: {', '.join(cameras)})",
                                 param_hint="--camera")


def open_rerun(path: str | None, task: str):
    """The Rerun logger of ``run --rerun PATH`` (None without the option).

    Raises:
        BadInput: rerun-sdk is not installed.
    """
    if path is None:
        return None
    try:
        from agentchord.data.rerun_log import RerunLogger

        return RerunLogger(path, task)
    except ImportError as exc:
        raise BadInput(f"--rerun needs rerun-sdk (pip install 'agentchord[data]'): {exc}") from exc


def _write_video(video, path) -> Path:
    """Encode the video beside ``path`` and rename it over ``path``: never half an MP4.

    A symlink is written through to its target (the link kept), as every other output is; a
    device or FIFO (``/dev/null``) gets the bytes written into it.
    """
    import os
    import shutil
    import tempfile

    given = Path(path)
    special = given.exists() and not given.is_file()
    target = Path(os.path.realpath(given))
    folder = Path(tempfile.gettempdir()) if special else target.parent
    fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=".mp4", dir=folder)  # the encoder needs .mp4
    os.close(fd)
    try:
        video.path = Path(tmp)
        video.write()
        if special:
            with open(tmp, "rb") as source, open(given, "wb") as sink:
                shutil.copyfileobj(source, sink)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp's file is private; a video is not
            os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return given


def _write_outputs(console: Console, outputs) -> None:
    """Write each output (label, path, writer); one that fails does not stop the others. Exit 2 if any failed."""
    failed = []
    for label, path, write in outputs:
        if not path:
            continue
        try:
            console.print(f"{label}: {write()}")
        except Exception as exc:  # whatever the writer raised, the other outputs still get written
            failed.append(f"cannot write {label} {path}: {exc}")
    if failed:
        raise BadInput("\n".join(failed))


def plain(value):
    """A name or text from a graph file or a model, as it is: Rich markup escaped, control characters shown
    as escapes (an id ``[link=file:///etc/passwd]e1`` or a failure named with an ANSI sequence prints as written)."""
    if isinstance(value, str):
        shown = "".join(ch if ch.isprintable() or ch == " " else ch.encode("unicode_escape").decode("ascii") for ch in value)
        return escape(shown)
    if isinstance(value, (list, tuple)):
        return [plain(item) for item in value]
    return value


def _short(text: str, limit: int = 70) -> str:
    """A node's semantic on one line, cut to ``limit`` characters."""
    line = " ".join(str(text).split()).rstrip(".")
    return line if len(line) <= limit else line[: limit - 3] + "..."


def _print_episode(console: Console, result) -> None:
    for raw in result.trace.events:
        event = {key: plain(value) for key, value in raw.items()}
        kind = event["event"]
        tick = f"[dim]{event['tick']:5d}[/dim]"
        if kind == "edge_start":
            colour = "blue" if event["kind"] == "nominal" else "magenta"
            console.print(f"{tick}  [{colour}]{event['edge']}[/{colour}] -> {event['target']}  ({event['kind']})")
        elif kind == "node_reached":
            mark = "ok" if event["constraints_hold"] else f"constraints violated: {event.get('violated')}"
            meaning = f" ({_short(event['semantic'])})" if event.get("semantic") else ""
            console.print(f"{tick}  node [bold]{event['node']}[/bold]{meaning}  {mark}")
        elif kind == "disturbance":
            by = f" from the {event['arm']} gripper" if event["kind"] in ("drop", "pull") else ""
            during = f" during {event['action']}" if event["action"] else ""
            console.print(f"{tick}  [yellow]disturbance[/yellow]: {event['kind']} {event['obj']}{by}{during}")
        elif kind == "failure_detected":
            console.print(f"{tick}  [red]failure detected[/red]: {event['failure']} on {event['edge']} (violated since tick {event['onset_tick']})")
        elif kind == "recovery_switch":
            others = f" (or {', '.join(event['alternatives'])})" if event.get("alternatives") else ""
            console.print(f"{tick}  [magenta]recovery switch[/magenta] -> {event['to']}{others} ({event['latency_ticks']} ticks after onset)")
        elif kind == "recovery_bound":
            refused = "".join(f"; not {r['edge']}: {r['reason']}" for r in event["refused"])
            console.print(f"{tick}  [magenta]recovery bound[/magenta] to {event['edge']} ({'+'.join(event['arms'])} arm, "
                          f"waited {event['waited_ticks']} ticks for it to come to rest{refused})")
        elif kind == "failure_cleared":
            console.print(f"{tick}  [green]failure cleared[/green]: {event['failure']} on {event['edge']}: "
                          f"{', '.join(event['objects'])} held again as before, after {event['waited_ticks']} ticks; the edge goes on")
        elif kind == "subgoal_met":
            console.print(f"{tick}  [green]sub-goal met[/green]: {event['node']} already holds once at rest "
                          f"(after {event['waited_ticks']} ticks): {event['edge']} skipped")
        elif kind == "goal_settling":
            console.print(f"{tick}  [yellow]goal reached, judged once at rest[/yellow]: {event['reason']}")
        elif kind == "violation_at_goal":
            console.print(f"{tick}  [red]goal not met[/red] ({event['reason']}), watched for by {event['edge']}: "
                          f"{event['failure']}")
        elif kind == "merged_ahead":
            console.print(f"{tick}  [green]merged ahead[/green]: at {event['node']}, {', '.join(event['passed'])} reached before "
                          f"the failure and {event['to']} holds: {', '.join(event['skipped'])} skipped")
        elif kind == "recovery_failed":
            console.print(f"{tick}  [red]recovery failed[/red]: {event['edge']}: {event['reason']}; trying the next candidate")
        elif kind == "unrecoverable":
            console.print(f"{tick}  [red]unrecoverable[/red]: {event['obj']}: {event['reason']}")
        elif kind == "repair":
            outcome = (f"added {event['failure']}, recovering by {event['recovery']}" if event["accepted"]
                       else f"no branch added: {event.get('reason')}")
            console.print(f"{tick}  [cyan]online repair[/cyan] after {event['edge']}: {event['observation']} -> {outcome}")
        elif kind == "reasoner_call":
            status = "ok" if event["ok"] else f"failed: {event['error']}"
            console.print(f"{tick}  {event['agent']} ({event['reasoner']}): {status}, {1000 * event['latency_s']:.0f} ms")
        elif kind == "branch_removed":
            console.print(f"{tick}  forward-moving filter removed {event['failure']} on {event['edge']}: {event['reason']}")
        elif kind == "plan_arrived" and event.get("written_by"):
            console.print(f"{tick}  [yellow]the LLM's plan failed[/yellow] ({plain(str(event['llm_error'])[:200])}): "
                          f"the {event['written_by']} arranger and conductor wrote the recovery branches instead")
        elif kind == "plan_failed":
            console.print(f"{tick}  [red]the LLM's plan failed[/red] ({plain(str(event['reason'])[:200])}): each edge keeps "
                          "the monitors derived from its constraints; a failure that needs a branch ends the episode")
    verdict = "[green]SUCCESS[/green]" if result.success else "[red]FAILURE[/red]"
    console.print(f"{verdict}: {plain(result.reason)}")
    console.print(f"steps {result.steps}  robot time {result.time_s:.2f} s  wall {result.wall_s:.2f} s  "
                  f"failures detected {result.failures_detected}  recoveries {result.recoveries}")
    if result.reasoning_calls:
        calls = ", ".join(f"{n} {kind}" for kind, n in result.reasoning_calls.items())
        console.print(f"execution time {result.exec_time_s:.2f} s = robot {result.time_s:.2f} + compute {result.compute_s:.2f} "
                      f"+ reasoning {result.reasoning_s:.2f} s (modelled; calls: {calls}; re-plans {result.replans})")
    console.print("path: " + " -> ".join(plain(list(result.path))))


@click.command()
@click.option("--task", default="single_arm_pour_water", show_default=True)
@click.option("--trials", type=click.IntRange(1, 10000), default=20, show_default=True)
@click.option("--seed", "first_seed", type=click.IntRange(0, 2**31), default=0, show_default=True,
              help="Seeds run from here: --seed N --trials T runs seeds N .. N+T-1.")
@click.option("--p", "p", type=FiniteFloatRange(0.0, 1.0), default=0.1, show_default=True)
@click.option("--disturb", default="drop", show_default=True, callback=_kinds, help=DISTURB_HELP)
@click.option("--protocol", type=click.Choice(PROTOCOL_NAMES), is_flag=False, flag_value="custom", default=None,
              help=PROTOCOL_HELP)
@click.option("--perception", type=click.Choice(PERCEPTION_NAMES), default="oracle", show_default=True)
@click.option("--strategies", default=",".join(STRATEGY_NAMES), show_default=True, help="Comma-separated strategies to compare.")
@click.option("--workers", type=click.IntRange(1, 64), default=None, help="Worker processes (default: one per core).")
@click.option("--planned", is_flag=True, help="Plan each episode's graph with --reasoner from the task's instruction instead of the library graph.")
@click.option("--instruction", help="Plan each episode's graph from this instruction (implies --planned).")
@click.option("--reasoner", type=click.Choice(REASONER_NAMES), default="rules", show_default=True)
@click.option("--json", "json_path", type=click.Path(dir_okay=False), help="Write the aggregates (and each episode's summary) as JSON.")
@click.option("--world", "world", callback=_world_address, help=WORLD_HELP + " Episodes then run one at a time.")
@catches_sigterm
def demo(task, trials, first_seed, p, disturb, protocol, perception, strategies, workers, planned, instruction, reasoner, json_path,
         world) -> None:
    """Seeded episodes of each strategy under random drops, then a table per strategy."""
    from agentchord.bench.report import aggregate, paired_steps, print_tables
    from agentchord.bench.runner import run_many
    from agentchord.episode import EpisodeSpec
    from agentchord.worlds.remote import RemoteWorldError

    names = [s.strip() for s in strategies.split(",") if s.strip()]
    unknown = [s for s in names if s not in METHOD_NAMES]
    if unknown or not names:
        raise click.BadParameter(f"unknown strategy {unknown} (choose from {', '.join(METHOD_NAMES)})", param_hint="--strategies")
    check_task_name(task, "--task")
    check_graph_source(task, "--task", instruction)
    if world is not None:
        check_served(task, "--world")
    if perception == "rgbd":
        check_rendered(task, "--perception rgbd")
    if world is not None and workers not in (None, 1):
        raise click.BadParameter("one remote world runs one episode at a time: use --workers 1 with --world", param_hint="--workers")
    check_outputs(("--json", json_path, ()))
    console = Console()
    setting = disturbance_setting(p, disturb, protocol)
    schedule = f"1-2 disturbances per trial ({protocol} protocol)" if protocol else f"probability p = {p} per atomic action"
    console.print(f"[bold]{task}[/bold]: {trials} seeded episodes per strategy; disturbances {', '.join(setting.kinds)}, "
                  f"{schedule}; perception {perception}")
    if planned and instruction is None:
        from agentchord.library import load_task_graph

        instruction = load_task_graph(task).instruction
    if instruction:
        console.print(f"graphs planned per episode by the {reasoner} reasoner from: {instruction!r}")
    if world is not None:
        console.print(f"world: {world} (one episode at a time)")
    specs = [EpisodeSpec(task=task, strategy=name, seed=seed, disturbances=setting,
                         perception=perception, instruction=instruction, reasoner=reasoner, world=world)
             for name in names for seed in range(first_seed, first_seed + trials)]
    summaries: dict[str, list[dict]] = {name: [] for name in names}
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(), console=console) as bar:
        job = bar.add_task("episodes", total=len(specs))
        try:
            for spec, summary in run_many(specs, workers=1 if world is not None else workers):
                summaries[spec.strategy].append(summary)
                bar.advance(job)
        except RemoteWorldError as exc:
            raise BadInput(str(exc)) from exc
    for runs in summaries.values():
        runs.sort(key=lambda s: s["seed"])
    results = {name: aggregate(summaries[name]) for name in names}
    paired = paired_steps(summaries)
    print_tables(results, console, paired)
    if json_path:
        payload = {"task": task, "p": None if protocol else p, "trials": trials, "first_seed": first_seed, "disturb": list(setting.kinds), "protocol": protocol,
                   "perception": perception, "instruction": instruction, "reasoner": reasoner if instruction else None,
                   "strategies": results, "paired_steps": paired,
                   "world": world, "runs": summaries}
        atomic_write_text(json_path, finite_json(payload, indent=2) + "\n")
        console.print(f"aggregates: {json_path}")
