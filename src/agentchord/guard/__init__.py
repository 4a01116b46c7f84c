"""Limits on what comes in and where results go: finite numbers, bounded documents, safe output paths.

The bottom layer of the package (it imports nothing else of AgentChord): the graph models,
goal specs, the release importer, the LLM reasoner and the command line all use it, so that
one rule says what a bad input is and one exception family reports it.
"""

from agentchord.guard.documents import MAX_DEPTH, MAX_FILE_BYTES, MAX_VALUES, check_shape, read_text
from agentchord.guard.exceptions import (
    DocumentError,
    InputError,
    NonFiniteNumberError,
    NotARegularFileError,
    OutputPathError,
    TooDeepError,
    TooLargeError,
)
from agentchord.guard.numbers import MAX_MAGNITUDE, FiniteFloat, check_finite, non_finite
from agentchord.guard.outputs import atomic_write_bytes, atomic_write_text, check_output_path, finite_json

__all__ = [
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_MAGNITUDE",
    "MAX_VALUES",
    "DocumentError",
    "FiniteFloat",
    "InputError",
    "NonFiniteNumberError",
    "NotARegularFileError",
    "OutputPathError",
    "TooDeepError",
    "TooLargeError",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_finite",
    "check_output_path",
    "check_shape",
    "finite_json",
    "non_finite",
    "read_text",
]
