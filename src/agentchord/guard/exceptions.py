"""Exceptions of the input guard: each names what was refused and why.

Every one is a :class:`ValueError`, so that a pydantic validator that raises it
reports it as a field error, and the command line maps the family to exit status 2.
"""

from __future__ import annotations


class InputError(ValueError):
    """Base class: an input (a number, a document, a path) was refused."""


class NonFiniteNumberError(InputError):
    """A number is NaN or infinite, or beyond the magnitude any quantity of a task can have.

    Attributes:
        where: Path of the number inside its document (``offset[1]``), empty at the top.
        value: The number.
    """

    def __init__(self, where: str, value: float, message: str) -> None:
        self.where = where
        self.value = value
        super().__init__(f"{where}: {message}" if where else message)


class DocumentError(InputError):
    """A document (a file, an LLM reply) cannot be read within the limits.

    Attributes:
        where: Path inside the document where the limit was hit, empty if none.
    """

    def __init__(self, message: str, where: str = "") -> None:
        self.where = where
        super().__init__(message)


class NotARegularFileError(DocumentError):
    """A path names a FIFO, a device or a directory: reading it could hang or never end."""


class TooLargeError(DocumentError):
    """A document is larger than the limit (bytes, or values after YAML aliases expand)."""


class TooDeepError(DocumentError):
    """A document nests mappings and lists deeper than the limit."""


class OutputPathError(InputError):
    """An output path cannot be written (missing permission, a directory, a wrong suffix).

    Attributes:
        path: The path as given.
        option: The command-line option it came from (``--json``), if known.
    """

    def __init__(self, path: str, reason: str, option: str | None = None) -> None:
        self.path = path
        self.option = option
        self.reason = reason
        by = f"{option} " if option else ""
        super().__init__(f"cannot write {by}{path}: {reason}")
