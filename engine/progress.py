"""Progress, cancellation, chunked loops and the parallel lock: one module for every engine package.

Kernels take ``progress=None`` or a callable ``progress(done, total) -> bool``.
Returning ``False`` asks the kernel to stop; it then raises :class:`Cancelled`.
"""

from __future__ import annotations

import threading
import time
from typing import Callable, Optional

ProgressFn = Optional[Callable[[int, int], bool]]

# A chunk of work between two progress calls should take about this long, so
# that a cancel request is honoured well within the ~100 ms the UI promises.
TARGET_CHUNK_SECONDS = 0.04


# numba's "workqueue" threading layer (the fallback when neither TBB nor
# OpenMP is available) aborts the process if two threads launch parallel
# kernels at once; the UI may evaluate nodes from several worker threads.
# Work chunks are short, so serialising them costs little.
PARALLEL_LOCK = threading.Lock()


class Cancelled(Exception):
    """Raised by a kernel when its progress callback returned ``False``."""


def report(progress: ProgressFn, done: int, total: int) -> None:
    """Call ``progress(done, total)`` and raise :class:`Cancelled` on ``False``.

    Parameters
    ----------
    progress : callable or None
        The user's callback; ``None`` means "never cancel, report nothing".
    done, total : int
        Units of work finished so far and in all.
    """
    if progress is None:
        return
    answer = progress(int(done), int(total))
    # ``None`` (a callback that forgot to return) means carry on; only an
    # explicit falsy answer such as False / np.False_ cancels.
    if answer is not None and not answer:
        raise Cancelled(f"cancelled at {done}/{total}")


def run_chunked(work: Callable[[int, int], None], total: int,
                progress: ProgressFn, *, first_chunk: int = 2) -> None:
    """Run ``work(start, stop)`` over ``range(total)`` in timed chunks.

    Without a callback the whole range is done in one call (least overhead).
    With one, the chunk size adapts so each call lasts about
    ``TARGET_CHUNK_SECONDS``; the callback is consulted before and after
    each chunk. Calls to ``work`` from different threads never overlap.

    Parameters
    ----------
    work : callable
        ``work(start, stop)`` processes items ``start <= i < stop``.
    total : int
        Number of items (e.g. grid planes).
    progress : callable or None
        See :func:`report`.
    first_chunk : int
        Size of the first, timing, chunk.
    """
    if progress is None:
        with PARALLEL_LOCK:
            work(0, total)
        return
    report(progress, 0, total)
    start, chunk = 0, max(1, first_chunk)
    while start < total:
        stop = min(total, start + chunk)
        with PARALLEL_LOCK:
            t0 = time.perf_counter()
            work(start, stop)
            elapsed = time.perf_counter() - t0
        report(progress, stop, total)
        chunk = next_chunk(chunk, stop - start, elapsed)
        start = stop


def next_chunk(chunk: int, done: int, elapsed: float, *, most: int | None = None) -> int:
    """Size of the next chunk of an adaptive loop (work between two progress
    calls), aiming at ``TARGET_CHUNK_SECONDS`` per chunk.

    The one rule of every chunked loop (:func:`run_chunked`, the growth loops
    of engine.rd.growth and engine.growth.wfc): the measured rate times the
    target, shrinking at once after a slow chunk but growing at most 4x at a
    time, so one unexpectedly fast region cannot make the next chunk (in a
    slow region) blow the latency a cancel waits for.

    Parameters
    ----------
    chunk : int >= 1
        The size asked for last time.
    done : int >= 0
        Units of work the last chunk did (at most ``chunk``: a loop may stop a
        chunk early at a boundary of its own).
    elapsed : float
        Seconds the last chunk took; 0 or less (faster than the clock): grow 4x.
    most : int or None
        Upper bound on the size (e.g. the steps between two convergence checks).

    Returns
    -------
    int, at least 1 (and at most ``most``).
    """
    grown = 4 * int(chunk)
    size = grown if elapsed <= 0 else min(grown, int(done * TARGET_CHUNK_SECONDS / elapsed))
    if most is not None:
        size = min(size, int(most))
    return max(1, size)


def stage(progress: ProgressFn, start: float, share: float) -> ProgressFn:
    """A kernel's ``progress(done, total)`` mapped onto ``[start, start + share]``
    of a bar that runs to 1 (a node with several kernel calls gives each its
    share).  None stays None (nothing to report).

    Example: ``stage(ctx.progress, 0.0, 0.5)`` for the first of two equal steps,
    ``stage(progress, k / n, 1 / n)`` for step ``k`` of ``n``.
    """
    if progress is None:
        return None

    def inner(done, total):
        return progress(start + share * done / max(total, 1), 1.0)
    return inner
