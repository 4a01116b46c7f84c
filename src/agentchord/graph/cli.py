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
def schema_command() -> None:
    """Print the JSON Schema of task-graph files."""
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
