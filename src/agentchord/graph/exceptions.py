"""Exceptions of the task-graph package."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


class GraphError(Exception):
    """Base class for task-graph errors."""

    def __reduce__(self) -> tuple[object, ...]:
        # Subclasses take other arguments than the message: rebuild from the state, so
        # that an error raised in a bench worker process reaches the parent intact.
        return (_rebuild, (type(self), self.args, self.__dict__))


def _rebuild(cls: type[GraphError], args: tuple, state: dict) -> GraphError:
    error = cls.__new__(cls)
    Exception.__init__(error, *args)
    error.__dict__.update(state)
    return error


class GraphFileError(GraphError):
    """A graph file could not be read, parsed or validated.

    Attributes:
        path: The offending file.
        problems: One line per problem, each ``FILE: where: what is wrong``.
    """

    def __init__(self, path: str | Path, problems: Sequence[str]) -> None:
        self.path = Path(path)
        self.problems = [f"{path}: {problem}" for problem in problems]
        super().__init__("\n".join(self.problems))


class GraphNotRunnableError(GraphError):
    """A graph about to run fails ``graph check`` or names objects its scene lacks.

    Attributes:
        source: Where the graph came from (a file, ``planned``, a task's library graph).
        lines: One line per problem, ``where: what is wrong``.
        problems: One line per problem, each ``SOURCE: where: what is wrong``.
    """

    def __init__(self, source: str, problems: Sequence[str]) -> None:
        self.source = source
        self.lines = list(problems)
        self.problems = [f"{source}: {problem}" for problem in problems]
        super().__init__("the graph cannot run:\n" + "\n".join(self.problems))


class UnknownNodeError(GraphError, KeyError):
    """A node id that the graph does not define."""

    def __init__(self, node_id: str, known: Sequence[str]) -> None:
        self.node_id = node_id
        super().__init__(f"unknown node {node_id!r}; the graph has {', '.join(known) or 'no nodes'}")

    def __str__(self) -> str:  # KeyError would repr() the message
        return str(self.args[0])


class UnknownEdgeError(GraphError, KeyError):
    """An edge id that the graph does not define."""

    def __init__(self, edge_id: str, known: Sequence[str]) -> None:
        self.edge_id = edge_id
        super().__init__(f"unknown edge {edge_id!r}; the graph has {', '.join(known) or 'no edges'}")

    def __str__(self) -> str:
        return str(self.args[0])


class UnknownActionError(GraphError):
    """An edge step calls an action that the catalogue does not define."""

    def __init__(self, edge_id: str, fn: str) -> None:
        self.edge_id = edge_id
        self.fn = fn
        super().__init__(f"edge {edge_id!r} calls unknown action {fn!r}: its expected cost is unknown")


class NoPathError(GraphError):
    """No path joins two nodes over the edges considered."""


class RenderError(GraphError):
    """A graph could not be rendered (unknown format, Graphviz missing or failing)."""
