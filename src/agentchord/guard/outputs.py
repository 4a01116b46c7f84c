"""Output paths checked before any work starts, and results written atomically.

An episode, a demo of a hundred trials or an LLM plan must not be lost because its
output path turns out, at the end, to be unwritable: every output is checked first
(its folder is created as ``demo --json`` always did). Results are written to a
temporary file beside the destination and renamed over it, so that a reader never
sees half a file and a failed write leaves the previous file in place.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from agentchord.guard.exceptions import OutputPathError


#: The longest file or folder name (bytes) of common file systems (ext4, XFS, APFS, NTFS).
NAME_MAX = 255
#: Bytes an atomic write adds to a file's name for its temporary file.
TEMP_SUFFIX_BYTES = 24


def _check_names(given: str, option: str | None, file: bool) -> None:
    """An empty path, or a file or folder name longer than a file system allows, is refused before any work."""
    if not given.strip():
        raise OutputPathError(given, f"an empty path; give a {'file' if file else 'folder'} name", option)
    path = Path(given)
    for part in path.parts:
        size = len(part.encode("utf-8", "surrogateescape"))
        # NAME_MAX on every common file system; an atomic write adds a temporary suffix to a file's own name.
        last = file and part == path.name
        if size > NAME_MAX - (TEMP_SUFFIX_BYTES if last else 0):
            raise OutputPathError(given, f"the name {part[:40]!r}... is {size} bytes long, more than a file system allows "
                                         f"({NAME_MAX} bytes{', less room for a temporary suffix' if last else ''})", option)


def check_output_folder(path: str | Path, option: str | None = None) -> Path:
    """An output folder's path, checked as :func:`check_output_path` checks a file's names (not yet created).

    Raises:
        OutputPathError: An empty path, or a name longer than a file system allows.
    """
    _check_names(str(path), option, file=False)
    return Path(path)


def check_output_path(path: str | Path, suffixes: Iterable[str] = (), option: str | None = None) -> Path:
    """Make sure ``path`` can be written: its folder exists (created if missing) and accepts a new file.

    Nothing is left behind: the probe file is removed, and an existing file is untouched.

    Args:
        path: The output file.
        suffixes: Accepted suffixes (lower case, with the dot); empty accepts any.
        option: The command-line option, for the message.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        OutputPathError: Wrong suffix, a directory, an existing file not writable, or a folder
            that cannot be created or written.
    """
    given = str(path)
    path = Path(path)
    suffixes = tuple(suffixes)
    _check_names(given, option, file=True)
    if suffixes and path.suffix.lower() not in suffixes:
        raise OutputPathError(given, f"unsupported file type {path.suffix or '(none)'!r}; use {', '.join(suffixes)}", option)
    if path.is_dir():
        raise OutputPathError(given, "it is a directory; give a file name", option)
    if path.exists() and not os.access(path, os.W_OK):
        raise OutputPathError(given, "the file exists and is not writable", option)
    if path.exists() and not path.is_file():
        return path  # a device or FIFO (/dev/null, /dev/stdout): written in place, nothing to probe
    folder = Path(os.path.realpath(path)).parent  # a symlink's target is what gets written
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputPathError(given, f"cannot create its folder {str(folder)!r}: {_reason(error)}", option) from None
    try:  # os.access is not enough (read-only mounts, ACLs): write a probe
        fd, probe = tempfile.mkstemp(prefix=".agentchord-probe-", dir=folder)
    except OSError as error:
        # /proc says "No such file or directory", a read-only mount "Read-only file system".
        raise OutputPathError(given, f"no file can be created in its folder {str(folder)!r} ({_reason(error)})", option) from None
    os.close(fd)
    os.unlink(probe)
    return path


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file renamed over it.

    Raises:
        OutputPathError: The folder cannot be written or the disk is full.
    """
    given = Path(path)
    if given.exists() and not given.is_file():
        # /dev/null, /dev/stdout, a FIFO: renaming over them would replace the device itself.
        try:
            with open(given, "wb") as stream:
                stream.write(data)
        except OSError as error:
            raise OutputPathError(str(given), _reason(error)) from None
        return given
    path = Path(os.path.realpath(given))  # through a symlink to its target, the link kept
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as error:
        raise OutputPathError(str(given), _reason(error)) from None
    try:
        with os.fdopen(fd, "wb") as stream:
            stream.write(data)
        if path.exists():  # keep the mode of the file it replaces
            with contextlib.suppress(OSError):
                os.chmod(tmp, path.stat().st_mode & 0o7777)
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except OSError as error:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise OutputPathError(str(given), _reason(error)) from None
    return given


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def _reason(error: OSError) -> str:
    return error.strerror or str(error)


def finite_json(payload: Any, **options: Any) -> str:
    """``payload`` as strict JSON: a NaN or infinity (an undefined mean, say) is written as ``null``.

    ``json.dumps`` would write ``NaN``, which no JSON reader accepts.
    """
    return json.dumps(_finite(payload), allow_nan=False, **options)


def _finite(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value
