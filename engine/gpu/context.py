"""One headless OpenGL context shared by the engine's GPU kernels.

The context is a standalone EGL context (on a machine without a GPU, Mesa's
llvmpipe), separate from any context a window may own.  It is created on
first use and then kept for the life of the process.  OpenGL contexts are
current in one thread at a time, so every use goes through
:func:`gpu_session`, which holds a process-wide lock and makes the context
current in the calling thread for the duration of the ``with`` block (and
restores whatever was current before, e.g. a Qt widget's context).
"""

from __future__ import annotations

import contextlib
import threading

GL_VERSION_REQUIRED = 430  # shader storage buffers


class GpuUnavailable(RuntimeError):
    """Raised when no OpenGL >= 4.3 context can be created through EGL."""


_LOCK = threading.RLock()
_STATE = {"ctx": None, "error": None}


def _create():
    try:
        import moderngl
    except ImportError as exc:  # pragma: no cover - moderngl is a dependency
        raise GpuUnavailable(f"moderngl is not installed ({exc})") from exc
    # moderngl records every new context as its process default; put back
    # whatever was there so code using moderngl.get_context() (a window)
    # never picks up this private context by accident.
    store = getattr(moderngl, "_store", None)
    previous = getattr(store, "default_context", None)
    try:
        ctx = moderngl.create_standalone_context(backend="egl", require=GL_VERSION_REQUIRED)
    except Exception as exc:
        raise GpuUnavailable(
            f"cannot create a headless OpenGL {GL_VERSION_REQUIRED // 100}.{GL_VERSION_REQUIRED % 100 // 10} "
            f"context through EGL: {exc}.  On Linux without a GPU install Mesa's EGL "
            "(e.g. Debian packages libegl1 and libgl1-mesa-dri)") from exc
    finally:
        if store is not None:
            store.default_context = previous
    return ctx


def gpu_context():
    """The shared ``moderngl.Context``, created on first call.

    Raises
    ------
    GpuUnavailable
        If EGL or OpenGL 4.3 is missing; the failure is remembered, so later
        calls fail fast with the same message.
    """
    with _LOCK:
        if _STATE["ctx"] is None:
            if _STATE["error"] is not None:
                raise GpuUnavailable(_STATE["error"])
            try:
                _STATE["ctx"] = _create()
            except GpuUnavailable as exc:
                _STATE["error"] = str(exc)
                raise
        return _STATE["ctx"]


def gpu_available() -> bool:
    """True if :func:`gpu_context` succeeds (creates the context if needed)."""
    try:
        gpu_context()
    except GpuUnavailable:
        return False
    return True


@contextlib.contextmanager
def gpu_session():
    """``with gpu_session() as ctx:`` -- exclusive use of the shared context.

    Holds the process-wide GPU lock and makes the context current in this
    thread; nested use from the same thread is allowed.
    """
    with _LOCK:
        ctx = gpu_context()
        with ctx:
            yield ctx
