"""MuJoCo renderers: opened safely beside torch, and closed before the process exits.

Every renderer of the package is opened by :func:`open_renderer` and registered with
:func:`close_at_exit` by its owner.
"""

from __future__ import annotations

import atexit
import importlib.util
import weakref
from typing import Protocol

import mujoco


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


_TRITON_LOADED = False


def _load_triton_first() -> None:
    # Headless EGL on a CPU is Mesa's llvmpipe, which loads its own LLVM. Triton (imported by
    # torch when a policy trains) bundles another; loaded after Mesa's, it segfaults the process.
    # Loaded before, both work. So a process that renders and then trains (record a dataset with
    # images, then learn from it) loads Triton first, when it is installed (about 0.2 s, once).
    global _TRITON_LOADED
    if not _TRITON_LOADED:
        _TRITON_LOADED = True
        if importlib.util.find_spec("triton") is not None:
            import triton  # noqa: F401


def open_renderer(model: mujoco.MjModel, height: int, width: int) -> mujoco.Renderer:
    """A ``mujoco.Renderer`` of ``model``, Triton loaded before its GL context (see above)."""
    _load_triton_first()
    return mujoco.Renderer(model, height=height, width=width)
