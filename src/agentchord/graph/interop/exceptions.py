"""The import's error: every problem, one line each."""

from __future__ import annotations

from collections.abc import Sequence

from agentchord.graph.exceptions import GraphError


class ReleaseImportError(GraphError):
    """The release files cannot be imported.

    Attributes:
        problems: One line per problem, ``FILE: json.path: what is wrong``.
    """

    def __init__(self, problems: Sequence[str]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(self.problems))
