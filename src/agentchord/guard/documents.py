"""Bounded documents: regular files of bounded size, parsed values of bounded depth and count.

A FIFO given as a graph file blocks ``open`` until a writer comes; ``/dev/zero`` never
ends; a 50-level nested list makes a recursive parser or validator overflow the stack;
a few lines of YAML aliases expand into billions of values. Each is refused here with
a message that names the limit, before a parser or a model sees it.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Any

from agentchord.guard.exceptions import NotARegularFileError, TooDeepError, TooLargeError

#: Largest file read as a graph, goal spec or release file (a 10,000-node graph is ~3.5 MB).
MAX_FILE_BYTES = 64 * 2**20
#: Deepest nesting of mappings and lists in a document (a graph needs 7).
MAX_DEPTH = 32
#: Most values (scalars, mappings, lists) in a document, counting every YAML alias expansion.
MAX_VALUES = 5_000_000


def read_text(path: str | Path, max_bytes: int | None = None) -> str:
    """The UTF-8 text of a regular file of at most ``max_bytes`` bytes (default :data:`MAX_FILE_BYTES`).

    Raises:
        NotARegularFileError: The path is a directory, FIFO, socket or device.
        TooLargeError: The file is larger than ``max_bytes``.
        OSError: It cannot be read (missing, no permission).
        UnicodeDecodeError: It is not UTF-8.
    """
    path = Path(path)
    max_bytes = MAX_FILE_BYTES if max_bytes is None else max_bytes
    info = path.stat()  # before open(): opening a FIFO would block
    if not stat.S_ISREG(info.st_mode):
        kind = "a directory" if stat.S_ISDIR(info.st_mode) else "not a regular file (a FIFO, socket or device)"
        raise NotARegularFileError(f"{kind}: give a file")
    if info.st_size > max_bytes:
        raise TooLargeError(f"the file is {info.st_size:,} bytes; the limit is {max_bytes:,} bytes")
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)  # a FIFO swapped in after stat() must not block
    with os.fdopen(os.open(path, flags), "rb") as stream:
        data = stream.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise TooLargeError(f"the file is larger than the limit of {max_bytes:,} bytes")
    return data.decode("utf-8")


def check_shape(data: Any, max_depth: int | None = None, max_values: int | None = None) -> None:
    """Refuse a parsed document nested deeper than ``max_depth`` or holding more than ``max_values`` values.

    Walks iteratively, one level of nesting at a time (a deep document must not overflow
    this check either; a 10,000-node graph takes a few hundredths of a second), counting
    shared values (YAML aliases) once per reference, as a validator would see them.

    Raises:
        TooDeepError: The first value past the depth limit, with its path.
        TooLargeError: More than ``max_values`` values.
    """
    max_depth = MAX_DEPTH if max_depth is None else max_depth
    max_values = MAX_VALUES if max_values is None else max_values
    level: list[Any] = [data]
    seen = 0
    depth = 0
    while level:
        seen += len(level)
        inner: list[Any] = []
        for item in level:
            kind = type(item)
            if kind is dict or (kind is not list and kind is not tuple and isinstance(item, dict)):
                inner += item.values()
            elif kind is list or kind is tuple or isinstance(item, (list, tuple)):
                inner += item
            else:
                continue
            if depth >= max_depth:
                raise TooDeepError(f"nested more than {max_depth} levels deep", where=_deep_path(data, max_depth))
            if seen + len(inner) > max_values:  # also bounds the memory of the next level
                break
        if seen + len(inner) > max_values:
            raise TooLargeError(
                f"the document holds more than {max_values:,} values (YAML aliases expanding?); "
                "write it out without anchors or make it smaller"
            )
        level = inner
        depth += 1


def _deep_path(data: Any, max_depth: int) -> str:
    # The path of the first list or mapping (depth first) nested ``max_depth`` levels deep; run
    # only once one is known to exist, through at most the values already counted.
    stack: list[tuple[Any, int, Any]] = [(data, 0, None)]
    while stack:
        item, depth, link = stack.pop()
        if isinstance(item, (dict, list, tuple)):
            if depth >= max_depth:
                return _path(link)
            pairs = item.items() if isinstance(item, dict) else enumerate(item)
            stack += [(v, depth + 1, (link, k, not isinstance(item, dict))) for k, v in pairs]
    return ""


def _path(link: Any) -> str:
    # Paths are built only when a limit is hit.
    parts = []
    while link is not None:
        link, key, index = link
        parts.append(f"[{key}]" if index else f".{key}")
    return "".join(reversed(parts)).lstrip(".")
