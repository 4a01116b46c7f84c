"""One writer per output folder: a POSIX record lock that says who holds it.

``bench`` and ``record`` each write many files into one ``--out`` folder over minutes and resume
from what is there: two processes on one folder would interleave (a dataset pairing episodes with
other episodes' videos). The second is refused at once, naming the holder.
"""

from __future__ import annotations

import datetime
import fcntl
import os
from pathlib import Path

from agentchord.guard.exceptions import OutputPathError


class FolderBusyError(OutputPathError):
    """Another process holds the folder's lock."""


def lock_folder(folder: str | Path, name: str, what: str) -> int:
    """Lock ``folder`` for this process (the folder is created if missing).

    Args:
        folder: The output folder.
        name: The lock file's name inside it (e.g. ``.sweep.lock``).
        what: What holds it, for the message (``sweep``, ``recording``).

    Returns:
        The lock's file descriptor: close it to release (the process ending releases it too).
        ``lockf``, not ``flock``: a forked worker does not inherit it.

    Raises:
        FolderBusyError: Another process holds it.
        OutputPathError: The folder or its lock file cannot be made.
    """
    folder = Path(folder)
    path = folder / name
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as error:
        raise OutputPathError(str(path), f"cannot open the {what}'s lock ({error.strerror})") from None
    try:
        fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        holder = os.read(fd, 200).decode("utf-8", "replace").strip() or "another process"
        os.close(fd)
        raise FolderBusyError(str(folder), f"another {what} is running on this directory ({holder}); "
                              "wait for it to end, or use another --out") from None
    os.ftruncate(fd, 0)
    stamp = datetime.datetime.now().isoformat(timespec="seconds")
    os.write(fd, f"pid {os.getpid()}, started {stamp}\n".encode())
    return fd
