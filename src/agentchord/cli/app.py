"""The ``agentchord`` group and its small commands: ``tasks``, ``serve``, ``plan``.

The other commands are defined beside it (``episode``: ``run``, ``demo``; ``graph``; ``bench``;
``data``: ``record``) and registered here.
"""

from __future__ import annotations

import sys

import click
from rich.console import Console

from agentchord import __version__
from agentchord.cli.bench import bench_command
from agentchord.cli.data import record_command
from agentchord.cli.episode import demo, run
from agentchord.cli.graph import graph_group, import_release_command, schema_command
from agentchord.cli.support import (
    PERCEPTION_NAMES,
    REASONER_NAMES,
    BadInput,
    FiniteFloatRange,
    GuardedGroup,
    catches_sigterm,
    check_outputs,
    check_served,
    check_task_name,
    failed_calls_trace,
    load_goal_option,
)


@click.group(cls=GuardedGroup)
@click.version_option(__version__, prog_name="agentchord")
def main() -> None:
    """AgentChord: recovery-augmented task graphs for robot manipulation."""


main.add_command(schema_command)
main.add_command(graph_group)
main.add_command(import_release_command)
main.add_command(bench_command)
main.add_command(record_command)
main.add_command(run)
main.add_command(demo)


@main.command()
@click.argument("task", required=False)
@click.option("--details", "details", metavar="TASK", default=None,
              help="One task's scene: its objects (sizes, where they lie at seed 0, which arm reaches them), regions, "
                   "arms, and an example goal file to run.")
def tasks(task: str | None, details: str | None) -> None:
    """List the simulated tasks, with a one-line description each; with TASK (or --details TASK), that task's scene."""
    from agentchord.library import library_tasks
    from agentchord.sim.tasks import SIM_TASKS

    chosen = details or task
    if chosen is not None:
        check_task_name(chosen, "TASK")
        click.echo(describe_task(chosen))
        return
    graphs = set(library_tasks())
    width = max(len(name) for name in SIM_TASKS)
    for name, sim in sorted(SIM_TASKS.items()):
        if getattr(sim, "goal_defined", False):
            mark = "  (no library graph: plan it with --instruction)"
        else:
            mark = "" if name in graphs else "  (no library graph yet)"
        click.echo(f"{name:<{width}}  {sim.description}{mark}")


@main.command()
@click.option("--task", required=True, help="The simulated task served.")
@click.option("--port", type=click.IntRange(0, 65535), default=5555, show_default=True, help="TCP port (0: any free one, printed).")
@click.option("--host", default="127.0.0.1", show_default=True, help="Interface to listen on (0.0.0.0: every IPv4 one; ::1 or :: for IPv6).")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Seed of a trial a client opens without one.")
@click.option("--release-after", "release_after", type=FiniteFloatRange(0.1, 86400.0), default=300.0, show_default=True,
              help="Seconds without a request after which a client's trial may be taken over by another client.")
@catches_sigterm
def serve(task, port, host, seed, release_after) -> None:
    """Serve TASK's simulator over the world protocol (ZeroMQ) until interrupted.

    `run`/`demo --world tcp://HOST:PORT` drive it as a remote world, the way they would drive a
    real robot's driver: docs/world_protocol.md lists the messages. One client at a time: while a
    client's trial is open, another client's is refused (exit status 2, naming the holder) until the
    first closes it or sends nothing for --release-after seconds.
    """
    check_task_name(task, "--task")
    check_served(task, "the world protocol")
    import zmq

    from agentchord.sim.serve import WorldServer, bind_host

    def ready(endpoint: str) -> None:
        click.echo(f"serving {task} on {endpoint} (Ctrl-C to stop; a trial idle for {release_after:g} s is released)")
        sys.stdout.flush()

    if any(c in host for c in " /@?#*") or not host:
        raise click.BadParameter(f"{host!r} is not an interface address or name (e.g. 127.0.0.1, 0.0.0.0, ::1)",
                                 param_hint="--host")
    try:
        WorldServer(task, seed, release_after_s=release_after).serve(f"tcp://{bind_host(host)}:{port or '*'}", ready=ready)
    except zmq.ZMQError as exc:
        raise BadInput(f"cannot listen on {host}:{port}: {exc}") from exc


@main.command()
@click.argument("instruction", required=False)
@click.option("--task", required=True, help="Simulated task whose seeded scene is the first observation.")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Seed of the scene.")
@click.option("--goal", "goal_path", type=click.Path(exists=True, dir_okay=False), help="A goal spec (YAML/JSON) instead of reading INSTRUCTION.")
@click.option("--reasoner", type=click.Choice(REASONER_NAMES), default="rules", show_default=True)
@click.option("--perception", type=click.Choice(PERCEPTION_NAMES), default="oracle", show_default=True)
@click.option("-o", "--output", type=click.Path(dir_okay=False), required=True, help="Where to write the augmented graph (.yaml/.json).")
@click.option("--render", "render_path", type=click.Path(dir_okay=False), help="Also draw it (.svg, .png, .pdf, .dot, .mmd).")
@click.option("--trace", "trace_path", type=click.Path(dir_okay=False), help="Write the agents' calls as JSON lines.")
@click.option("--explain", is_flag=True, help="Print the parse: clauses -> goal predicates -> skills -> graph (rules reasoner).")
@catches_sigterm
def plan(instruction, task, seed, goal_path, reasoner, perception, output, render_path, trace_path, explain) -> None:
    """Compose, arrange and conduct the graph for INSTRUCTION in TASK's scene; write it to --output.

    Exit status 0 when a valid graph was written, 2 when the instruction cannot be planned.
    """
    from agentchord.agents.exceptions import ReasonerError
    from agentchord.agents.observe import observe, task_regions
    from agentchord.agents.pipeline import make_reasoner, plan_task
    from agentchord.episode import planned_success
    from agentchord.execution.trace import Trace
    from agentchord.graph.loader import dump_graph
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.trial import open_world

    check_task_name(task, "--task")
    _check_plan_outputs(output, render_path, trace_path, goal_path)
    goal = load_goal_option(goal_path)
    if not instruction and goal is None:
        raise click.UsageError("give an INSTRUCTION or --goal")
    sim_task = SIM_TASKS[task]
    world = open_world(task, seed)
    scene = observe(world, task_regions(sim_task), perception)
    if explain:
        from agentchord.agents.rules.explain import explain_plan

        click.echo(explain_plan(instruction or "", scene, goal))
    try:
        agent = make_reasoner(reasoner, goal=goal, watch_visibility=perception == "rgbd")
        result = plan_task(instruction or "", scene, agent, task=task)
    except ReasonerError as exc:
        raise BadInput(str(exc) + failed_calls_trace(exc, trace_path)) from exc
    console = Console()
    graph = planned_success(result.graph, task, goal or getattr(agent, "last_goal", None), scene)
    dump_graph(graph, output)
    modes = sum(len(e.failures) for e in graph.edges)
    console.print(f"[bold]{task}[/bold] (seed {seed}): {len(result.nominal.edges)} nominal edges, {modes} failure modes, "
                  f"{len(graph.recovery_edges())} recovery edges, {len(graph.recovery_nodes())} recovery nodes")
    for removed in result.filtered.removed:
        console.print(f"  forward-moving filter removed {removed.failure} on {removed.edge}: {removed.reason}")
    timing = ", ".join(f"{agent} {1000 * s:.0f} ms" for agent, s in result.seconds.items())
    console.print(f"  {timing} ({reasoner} reasoner)")
    if graph.success.judge == "goal":
        console.print(f"  success: judged by this graph's own goal ({graph.goal}), not the {task} task's check")
    console.print(f"graph: {output}")
    if render_path:
        from agentchord.graph.render import render

        console.print(f"figure: {render(graph, render_path)}")
    if trace_path:
        trace = Trace()
        for call in result.calls:
            trace.add(0, "reasoner_call", **call.to_trace_event())
        console.print(f"trace: {trace.write(trace_path)}")


def _check_plan_outputs(output, render_path, trace_path, goal_path=None) -> None:
    from agentchord.graph.loader import JSON_SUFFIXES, YAML_SUFFIXES
    from agentchord.graph.render import FORMATS

    check_outputs(("-o", output, YAML_SUFFIXES + JSON_SUFFIXES), ("--render", render_path, FORMATS), ("--trace", trace_path, ()),
                  inputs=(("--goal", goal_path),))


def describe_task(name: str) -> str:
    """A task's scene as text for ``tasks --details``: what a newcomer needs to write a goal or an instruction."""
    from agentchord.agents.observe import observe, task_regions
    from agentchord.agents.rules.goals import GoalSpec
    from agentchord.library import library_tasks
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.trial import open_world

    task = SIM_TASKS[name]
    scene = observe(open_world(name, 0), task_regions(task))
    lines = [f"{name}: {task.description}", "",
             "objects (at seed 0; x + is the robot's right, y + away from it; sizes are full extents):"]
    for o in scene.objects:
        size = " x ".join(f"{100 * v:.1f}" for v in o.extent)
        reach = ", ".join(o.reachable_by) if o.reachable_by else "no arm"
        words = o.description.split()
        description = " ".join(w for k, w in enumerate(words) if k == 0 or w != words[k - 1])  # "red red block"
        lines.append(f"  {o.name:<12} {description:<22} size {size} cm at ({o.pos[0]:+.2f}, {o.pos[1]:+.2f}) m, reached by: {reach}")
    lines.append("regions:" if scene.regions else "regions: none")
    for r in scene.regions:
        lines.append(f"  {r.name:<12} {r.description} (centre ({r.center[0]:+.2f}, {r.center[1]:+.2f}) m, radius {100 * r.radius:.0f} cm)")
    lines.append("arms:")
    for a in scene.arms:
        base = f"base ({a.base[0]:+.2f}, {a.base[1]:+.2f}) m, " if a.base is not None else ""
        lines.append(f"  {a.name:<6} {base}reaches {a.reach_top:.2f} m from above, {a.reach_side:.2f} m from the side")
    lines.append(f"library graph: {'yes' if name in library_tasks() else 'no (plan one: run --instruction or --goal)'}")
    example = _example_goal(scene)
    GoalSpec.model_validate(example)  # the example is a goal spec this scene takes
    lines += ["", f"an example goal file (save it as goal.yaml, then: agentchord run {name} --goal goal.yaml;",
              "every kind: agentchord schema goal):", "goals:"]
    lines += [f"  - {{{', '.join(f'{k}: {v}' for k, v in goal.items())}}}" for goal in example["goals"]]
    return "\n".join(lines)


def _example_goal(scene) -> dict:
    """A goal this scene can be given, the first of a few kinds the offline planner finds feasible here:
    a fold, a pour, something into a container, into a region, beside another object, or put back."""
    from agentchord.agents.rules import knowledge as kb
    from agentchord.agents.rules.feasibility import goal_problems
    from agentchord.agents.rules.goals import GoalSpec

    corners = [o for o in scene.objects if kb.is_cloth_corner(o.name)]
    movable = [o for o in scene.objects if not kb.is_cloth_corner(o.name)]
    small = sorted(movable, key=lambda o: o.extent[0] * o.extent[1])
    candidates: list[list[dict]] = []
    if corners:
        candidates.append([{"kind": "folded", "cloth": corners[0].name.rsplit("_", 1)[0]}])
    for source in (o for o in movable if kb.is_pourable(o)):
        candidates += [[{"kind": "poured", "source": source.name, "target": t.name}, {"kind": "placed", "obj": source.name}]
                       for t in movable if t is not source and kb.is_container(t)]
    candidates += [[{"kind": "inside", "obj": o.name, "container": c.name}] for o in small for c in movable
                   if c is not o and kb.is_container(c)]
    candidates += [[{"kind": "placed", "obj": o.name, "region": r.name}] for o in small for r in scene.regions]
    candidates += [[{"kind": "placed", "obj": o.name, "relative_to": a.name, "offset": [0.17 if o.pos[0] > a.pos[0] else -0.17, 0.0]}]
                   for o in small for a in reversed(small) if a is not o]
    candidates += [[{"kind": "placed", "obj": o.name}] for o in small]
    for goals in candidates:
        spec = GoalSpec.model_validate({"goals": goals})
        if not goal_problems(spec, scene):
            return {"goals": goals}
    return {"goals": candidates[-1] if candidates else []}
