"""Command-line interface of the graph package: ``agentchord schema`` and ``agentchord graph ...``."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from agentchord.graph.exceptions import GraphError, GraphFileError
from agentchord.graph.loader import dump_graph, load_graph
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import forward_filter
from agentchord.graph.render import FORMATS, render
from agentchord.graph.validation import check_file


@click.command("schema")
@click.argument("kind", type=click.Choice(["graph", "goal"]), default="graph")
def schema_command(kind: str) -> None:
    """Print the JSON Schema of task-graph files (KIND graph) or of goal specs (KIND goal)."""
    if kind == "goal":
        from agentchord.agents.rules.goals import GoalSpec  # noqa: PLC0415

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
        click.echo(str(error))
        sys.exit(1)


@graph_group.command("check")
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
def check_command(files: tuple[Path, ...]) -> None:
    """Validate graph FILES: print one line per problem, exit 1 if any.

    A valid file prints ``FILE: ok (N nodes, M edges, K failure modes)``.
    """
    failed = False
    for path in files:
        problems = check_file(path)
        if problems:
            failed = True
            for line in problems:
                click.echo(line)
            continue
        graph = load_graph(path)
        click.echo(
            f"{path}: ok ({len(graph.nodes)} nodes, {len(graph.edges)} edges, {len(graph.failures())} failure modes)"
        )
    sys.exit(1 if failed else 0)


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
def render_command(file: Path, output: Path) -> None:
    """Draw graph FILE: nominal edges blue, recovery edges pink."""
    graph = _load_or_exit(file)
    try:
        render(graph, output)
    except GraphError as error:
        raise click.ClickException(str(error)) from None
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
    graph = _load_or_exit(file)
    try:
        result = forward_filter(graph)
    except GraphError as error:
        raise click.ClickException(f"{file}: {error} (run `agentchord graph check {file}`)") from None
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
        try:
            dump_graph(result.graph, output)
        except GraphFileError as error:
            raise click.ClickException(str(error)) from None
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
    from agentchord.graph.interop import FrameMap, ReleaseImportError, import_release  # noqa: PLC0415

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
        sys.exit(2)
    if not quiet:
        for line in result.notes:
            click.echo(f"note: {line}")
    try:
        dump_graph(result.graph, output)
    except GraphFileError as error:
        raise click.ClickException(str(error)) from None
    if output.suffix.lower() in (".yaml", ".yml"):
        header = [
            f"# Imported by `agentchord import-release` from {task_graph} and {recovery_spec}",
            f"# (frame {frame}); dropped or approximated:",
            *(f"#   {line}" for line in result.notes),
        ]
        output.write_text("\n".join(header) + "\n" + output.read_text(encoding="utf-8"), encoding="utf-8")
    graph = result.graph
    _warn_sim_objects(graph)
    click.echo(
        f"wrote {output}: task {graph.task}, {len(graph.nodes)} nodes, {len(graph.edges)} edges, "
        f"{len(graph.failures())} failure modes"
    )


def _warn_sim_objects(graph: TaskGraph) -> None:
    """Say so when the graph names objects that its simulated task's scene lacks."""
    import numpy as np  # noqa: PLC0415

    from agentchord.worlds.sim.tasks import SIM_TASKS  # noqa: PLC0415

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
