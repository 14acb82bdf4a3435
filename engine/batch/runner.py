"""Run sample tasks in-process or on Dask, handing rows over as they arrive.

Schedulers
----------
``None``
    A ``distributed.LocalCluster`` of ``n_workers`` processes with one thread
    each, started for the run and closed after it.
``"synchronous"``
    No Dask: samples run one after another in this process (the reference
    for timing and determinism; a cancel is honoured within ~100 ms).
an address string (``"tcp://host:8786"``)
    ``distributed.Client(address)``: the same code on a remote cluster.
a ``distributed.Client``
    Used as it is and left open.

At most a small window of tasks is in flight, so a cancel only has to drop a
few futures; rows are passed to ``on_row`` on this thread, in arrival order.
"""

from __future__ import annotations

import logging
import time
import uuid
from typing import Callable, Iterable

from engine.progress import Cancelled

__all__ = ["run_samples", "SYNCHRONOUS"]

SYNCHRONOUS = "synchronous"
_POLL_SECONDS = 0.1


def _keep_going(progress, done: int, total: int) -> bool:
    if progress is None:
        return True
    answer = progress(int(done), int(total))
    # None (a callback that returns nothing) means carry on, as in engine.progress
    return answer is None or bool(answer)


def run_samples(fn: Callable, config, samples: Iterable, *, on_row: Callable[[dict], None],
                scheduler=None, n_workers: int = 2, progress=None, done: int = 0,
                total: int = 0) -> bool:
    """Evaluate ``fn(config, sample)`` for every sample; pass each row to ``on_row``.

    Parameters
    ----------
    fn : callable ``(config, sample, progress=None) -> dict``, importable by workers
    config : picklable, shared by all samples (sent to the workers once)
    samples : iterable of picklable samples
    on_row : called with each row as soon as it arrives
    scheduler : None, "synchronous", address str or distributed.Client (module doc)
    n_workers : int >= 1, workers of the local cluster when ``scheduler`` is None
    progress : callable ``(done, total) -> bool``, optional; False cancels
    done, total : counts reported to ``progress`` (``done`` = rows already there)

    Returns
    -------
    bool : True if every sample ran, False if cancelled (rows so far were handed over).
    """
    if scheduler == SYNCHRONOUS:
        return _run_here(fn, config, samples, on_row, progress, done, total)
    from distributed import Client
    if isinstance(scheduler, Client):
        return _run_dask(scheduler, fn, config, samples, on_row, progress, done, total)
    if scheduler is None:
        from distributed import LocalCluster
        if isinstance(n_workers, bool) or not isinstance(n_workers, int) or n_workers < 1:
            raise ValueError(f"n_workers must be an integer >= 1; got {n_workers!r}")
        cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
        try:
            with Client(cluster) as client:
                return _run_dask(client, fn, config, samples, on_row, progress, done, total)
        finally:
            cluster.close()
    if isinstance(scheduler, str):
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise ValueError(f"cannot reach the Dask scheduler at {scheduler!r}: {exc}") from None
        with client:
            return _run_dask(client, fn, config, samples, on_row, progress, done, total)
    raise ValueError(f"scheduler must be None (local cluster), {SYNCHRONOUS!r}, a scheduler "
                     f"address or a distributed.Client; got {scheduler!r}")


def _run_here(fn, config, samples, on_row, progress, done, total) -> bool:
    last = [time.perf_counter()]

    def inner(_d, _t):
        # consulted by the solver about every 50 ms: lets a cancel stop a sample midway
        now = time.perf_counter()
        if now - last[0] < _POLL_SECONDS:
            return True
        last[0] = now
        return _keep_going(progress, done, total)

    if not _keep_going(progress, done, total):
        return False
    for sample in samples:
        try:
            row = fn(config, sample, progress=inner if progress is not None else None)
        except Cancelled:
            return False
        on_row(row)
        done += 1
        if not _keep_going(progress, done, total):
            return False
    return True


def _run_dask(client, fn, config, samples, on_row, progress, done, total) -> bool:
    from distributed import wait

    nthreads = sum(client.nthreads().values()) or 1
    window = 2 * nthreads + 2
    # hash=False: a fresh key per run, so releasing an earlier run's copy of the same
    # config cannot take this run's dependency with it
    shared = client.scatter(config, broadcast=True, hash=False)
    queue = iter(samples)
    pending: set = set()
    # keys name the sample (a failure carries it) plus a run token: a cancelled earlier
    # run's futures with the same sample must not be confused with this run's
    run = uuid.uuid4().hex[:8]

    def fill() -> None:
        while len(pending) < window:
            s = next(queue, None)
            if s is None:
                return
            key = f"growth-sample-{s.set}-{s.index}-{s.seed}-{run}"
            pending.add(client.submit(fn, shared, s, key=key, pure=False, retries=0))

    if not _keep_going(progress, done, total):
        return False
    fill()
    try:
        while pending:
            try:
                finished, _ = wait(list(pending), timeout=_POLL_SECONDS,
                                   return_when="FIRST_COMPLETED")
            except TimeoutError:
                finished = set()
            for fut in finished:
                pending.discard(fut)
                try:
                    row = fut.result()
                except Exception as exc:
                    raise RuntimeError(f"sample task {fut.key!r} failed: "
                                       f"{type(exc).__name__}: {exc}") from exc
                on_row(row)
                done += 1
            if not _keep_going(progress, done, total):
                return False
            fill()
        return True
    finally:
        if pending:
            client.cancel(list(pending), force=True)
