"""Renderers closed before the process exits: one exit hook for every open MuJoCo renderer owner."""

from __future__ import annotations

import atexit
import weakref
from typing import Protocol


class Closable(Protocol):
    """Anything holding a renderer that ``close`` frees."""

    def close(self) -> None: ...


_OPEN: weakref.WeakSet = weakref.WeakSet()
_HOOKED = False


def _close_open() -> None:
    # Renderers still open at exit would be freed by their finalisers after EGL shut down.
    for owner in list(_OPEN):
        owner.close()


def close_at_exit(owner: Closable) -> None:
    """Close ``owner`` at exit if it is still open then (call once its renderer exists)."""
    global _HOOKED
    if not _HOOKED:
        # Registered after the renderer created its GL context (so after the EGL module set up
        # its own exit handler): exit handlers run last-in first-out, so this one runs first.
        atexit.register(_close_open)
        _HOOKED = True
    _OPEN.add(owner)


def closed(owner: Closable) -> None:
    """``owner`` closed its renderer itself: nothing to do at exit."""
    _OPEN.discard(owner)
