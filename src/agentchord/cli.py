"""The ``agentchord`` command line."""

from __future__ import annotations

import click

from agentchord import __version__
from agentchord.graph.cli import graph_group, schema_command


@click.group()
@click.version_option(__version__, prog_name="agentchord")
def main() -> None:
    """AgentChord: recovery-augmented task graphs for robot manipulation."""


main.add_command(schema_command)
main.add_command(graph_group)
