"""The `agentchord schema` and `agentchord graph ...` commands (the graph package's command line).

Exit statuses as everywhere (:mod:`agentchord.cli.support`): 0 valid / written, 2 an
unreadable or invalid file or an output that cannot be written.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from agentchord.cli.support import EXIT_BAD_INPUT, BadInput, check_outputs
from agentchord.graph.exceptions import GraphError, GraphFileError
from agentchord.graph.grounding import check_scene
from agentchord.graph.loader import JSON_SUFFIXES, YAML_SUFFIXES, dump_graph, load_graph
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import forward_filter
from agentchord.graph.render import FORMATS, STYLES, render
from agentchord.graph.validation import check_graph
from agentchord.guard.outputs import atomic_write_text

GRAPH_SUFFIXES = YAML_SUFFIXES + JSON_SUFFIXES


@click.command("schema")
@click.argument("kind", type=click.Choice(["graph", "goal"]), default="graph")
def schema_command(kind: str) -> None:
    """Print the JSON Schema of task-graph files (KIND graph) or of goal specs (KIND goal)."""
    if kind == "goal":
        from agentchord.agents.rules.goals import GoalSpec

        click.echo(json.dumps(GoalSpec.model_json_schema(), indent=2))
        return
    click.echo(json.dumps(TaskGraph.model_json_schema(), indent=2))


@click.group("graph")
def graph_group() -> None:
    """Check, render and filter task-graph files (YAML or JSON)."""


def _load_or_exit(path: Path) -> TaskGraph:
    try:
        return load_graph(path)
    except GraphFileError as error:
        raise BadInput(str(error)) from None


@graph_group.command("check")
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--task", "task", default=None, help="Also check the graph against this simulated task's scene: its objects, and each arm's reach.")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Seed of the task's scene (with --task).")
def check_command(files: tuple[Path, ...], task: str | None, seed: int) -> None:
    """Validate graph FILES: print one line per problem, exit 2 if any.

    A valid file prints ``FILE: ok (N nodes, M edges, K failure modes)``. With ``--task``,
    each graph must also name only objects of that task's scene (as ``run`` requires), and
    every nominal grasp and place must lie within the reach of its arm in the scene of
    ``--seed`` (the message names the edge, the arm, how far, and what would do instead).
    """
    names, scene = _task_scene(task, seed) if task is not None else ([], None)
    failed = False
    for path in files:
        try:
            graph = load_graph(path)  # read once: a large file costs seconds to parse
        except GraphFileError as error:
            problems = error.problems
        else:
            found = check_graph(graph) + _goal_spec_problems(graph, scene)
            if scene is not None:
                from agentchord.agents.reach_check import reach_problems

                found += check_scene(graph, names, task)
                found += reach_problems(graph, scene) if not found else []
            problems = [f"{path}: {problem}" for problem in found]
        if problems:
            failed = True
            for line in problems:
                click.echo(line)
            continue
        click.echo(
            f"{path}: ok ({_count(len(graph.nodes), 'node')}, {_count(len(graph.edges), 'edge')}, "
            f"{_count(len(graph.failures()), 'failure mode')})"
        )
    sys.exit(EXIT_BAD_INPUT if failed else 0)


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _goal_spec_problems(graph, scene) -> list:
    """What is wrong with the goal the graph is judged by (``success.goal_spec``), as ``run`` refuses it; with a
    scene, also whether it can be done there (its objects and regions, things that fit)."""
    if graph.success.goal_spec is None:
        return []
    from pydantic import ValidationError

    from agentchord.agents.rules.feasibility import spec_problems, stated_goal_problems
    from agentchord.agents.rules.goals import GoalSpec

    if scene is not None:  # an object the scene lacks is check_scene's to say
        return [p for p in stated_goal_problems(graph, scene) if "the scene has no '" not in p.message]
    try:
        GoalSpec.model_validate(graph.success.goal_spec)
    except ValidationError as error:
        return spec_problems(error)
    return []


def _task_scene(task: str, seed: int):
    """The names the feature frame of ``task``'s scene holds (objects, cloth points), and the scene the agents see."""
    from agentchord.agents.observe import observe, task_regions
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.trial import open_world

    if task not in SIM_TASKS:
        raise click.BadParameter(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})", param_hint="--task")
    world = open_world(task, seed)
    return [*world.object_names, *world.cloth_point_names], observe(world, task_regions(SIM_TASKS[task]))


@graph_group.command("render")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--output",
    "output",
    required=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help=f"Output file; its suffix picks the format ({', '.join(FORMATS)}).",
)
@click.option(
    "--style",
    type=click.Choice(STYLES),
    default="readable",
    show_default=True,
    help="readable: the nominal chain top to bottom, each recovery branch an arc named 'failure -> intent', "
    "details on hover (.svg, .html) and in tables (.html); full: every action list and monitor on the arcs.",
)
def render_command(file: Path, output: Path, style: str) -> None:
    """Draw graph FILE: nominal chain blue, recovery branches pink.

    ``.html`` writes one page: the figure, and tables of every node's constraints, every
    edge's actions and failure modes, and every recovery branch (where it leaves and merges,
    what fires it, the other arm's way).
    """
    check_outputs(("-o", output, FORMATS))
    graph = _load_or_exit(file)
    try:
        render(graph, output, style=style)
    except GraphError as error:
        raise BadInput(str(error)) from None
    click.echo(f"wrote {output}")


@graph_group.command("filter")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--output",
    "output",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write the filtered graph here (.yaml/.yml/.json).",
)
def filter_command(file: Path, output: Path | None) -> None:
    """Apply the forward-moving filter (Eq. 8) to FILE: say which recovery branches it removes and why."""
    check_outputs(("-o", output, GRAPH_SUFFIXES), inputs=(("FILE", file),))
    graph = _load_or_exit(file)
    try:
        result = forward_filter(graph)
    except GraphError as error:
        raise BadInput(f"{file}: {error} (run `agentchord graph check {file}`)") from None
    for branch in result.removed:
        click.echo(
            f"{file}: remove {branch.failure} on {branch.edge} -> {branch.recovery_edge} "
            f"(r = {branch.recovery_node}, v_i = {branch.context}): {branch.reason}"
        )
    if result.removed_edges or result.removed_nodes:
        click.echo(
            f"{file}: unreachable after removal: edges {', '.join(result.removed_edges) or '-'}; "
            f"nodes {', '.join(result.removed_nodes) or '-'}"
        )
    if not result.removed:
        click.echo(f"{file}: nothing to remove ({len(result.kept)} recovery branches, all forward-moving)")
    if output is not None:
        dump_graph(result.graph, output)
        click.echo(f"wrote {output}")


@click.command("import-release")
@click.argument("task_graph", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("recovery_spec", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--output",
    "output",
    required=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write the augmented graph here (.yaml/.yml/.json).",
)
@click.option("--task", "task", default=None, help="Our task name (default: the sim task matching the release's).")
@click.option(
    "--objects",
    default=None,
    help="The graph's objects, comma-separated; NAME or RELEASE_NAME=NAME to rename (default: the release's names).",
)
@click.option(
    "--frame",
    default="aloha",
    show_default=True,
    help="Release frame -> ours: aloha ((x, y, z) -> (-y, x, z)), identity, or yaw=DEG,dx=M,dy=M,dz=M.",
)
@click.option("--quiet", is_flag=True, help="Do not list what was dropped or approximated.")
def import_release_command(
    task_graph: Path, recovery_spec: Path, output: Path, task: str | None, objects: str | None, frame: str, quiet: bool
) -> None:
    """Import the AgentChord reference release's TASK_GRAPH.json and RECOVERY_SPEC.json as one augmented graph.

    Every drop or approximation is listed as ``note: FILE: json.path: what``; anything that
    cannot be mapped is an error naming the file, the JSON path and the problem (exit 2).
    The mapping is documented in ``agentchord.graph.interop``.
    """
    from agentchord.graph.interop import FrameMap, ReleaseImportError, import_release

    check_outputs(("-o", output, GRAPH_SUFFIXES), inputs=(("TASK_GRAPH", task_graph), ("RECOVERY_SPEC", recovery_spec)))
    try:
        frame_map = FrameMap.parse(frame)
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="--frame") from None
    names = None if objects is None else [o.strip() for o in objects.split(",") if o.strip()]
    try:
        result = import_release(task_graph, recovery_spec, task=task, objects=names, frame=frame_map)
    except ReleaseImportError as error:
        for line in error.problems:
            click.echo(line, err=True)
        sys.exit(EXIT_BAD_INPUT)
    if not quiet:
        for line in result.notes:
            click.echo(f"note: {line}")
    dump_graph(result.graph, output)
    if output.suffix.lower() in YAML_SUFFIXES:
        header = [
            f"# Imported by `agentchord import-release` from {task_graph} and {recovery_spec}",
            f"# (frame {frame}); dropped or approximated:",
            *(f"#   {line}" for line in result.notes),
        ]
        atomic_write_text(output, "\n".join(header) + "\n" + output.read_text(encoding="utf-8"))
    graph = result.graph
    _warn_sim_objects(graph)
    click.echo(
        f"wrote {output}: task {graph.task}, {len(graph.nodes)} nodes, {len(graph.edges)} edges, "
        f"{len(graph.failures())} failure modes"
    )


def _warn_sim_objects(graph: TaskGraph) -> None:
    """Say so when the graph names objects that its simulated task's scene lacks."""
    import numpy as np

    from agentchord.sim.tasks import SIM_TASKS

    task = SIM_TASKS.get(graph.task)
    if task is None:
        click.echo(f"note: no simulated task {graph.task!r}: the graph can be checked, not run")
        return
    scene = {obj.name for obj in task.sample_scene(np.random.default_rng(0)).objects}
    missing = [obj for obj in graph.objects if obj not in scene]
    if missing:
        click.echo(
            f"warning: the {graph.task} scene has no {', '.join(missing)} (it has {', '.join(sorted(scene))}): "
            "rename with --objects RELEASE_NAME=NAME"
        )
