"""Phasor slice evaluation off the GUI thread, through the one `ui.task_runner.TaskRunner`.

A `SliceJob` is plain data: which pattern to show on which slice plane (and
which rectangle of it), the infill to slice, and an optional
``prepare(progress)`` step that runs first in the thread (the local kernel
update after a brush stroke, ``PhasorInfillSession.update``).  `SliceRunner`
is a TaskRunner that runs `run_slice_job` on them: a new request replaces
the waiting one and, unless ``supersede=False`` (a painting update lets the
running one land), stops the running one through its progress callback.
Nothing is drawn here: rendering stays on the GUI thread.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from engine.nodes.phasor_session import PhasorInfillSession

from .task_runner import Task, TaskRunner


@dataclass
class SliceJob:
    """One pattern image to compute.

    show : "diamonds" | "p_v" | "singularity"
    plane : SlicePlane of the whole view
    infill : PhasorInfill to evaluate, or the one ``prepare`` starts from
    rect : (r0, r1, c0, c1) pixels of ``plane`` to compute, or None for all
    prepare : callable(progress) -> (PhasorInfill, rect or None), or None; runs first,
        in the thread (the local kernel update after a brush stroke); a None rect
        means nothing visible changed
    engine : "gpu" | "numpy" asked for; after the run, what ran
    view : int, the view generation (axis / position / display) it belongs to
    purpose, fields : the caller's notes (e.g. "stroke" and the painted fields)
    serial : int, request order (the task's)
    """

    show: str
    plane: Any
    infill: Any
    rect: tuple | None = None
    engine: str = "gpu"
    prepare: Callable | None = None
    view: int = 0
    purpose: str = ""
    fields: Any = None
    serial: int = 0
    result: Any = field(default=None, repr=False)


def run_slice_job(job: SliceJob, task: Task) -> SliceJob:
    """The thread's work for ``job``: ``prepare`` then the pattern of ``job.rect``
    (``job.result``, ``job.engine``); raises Cancelled when the task is stopped."""
    if job.prepare is not None:
        job.infill, job.rect = job.prepare(task.progress)
        if job.rect is None:  # nothing visible changed
            return job
    task.check()
    job.result, job.engine = PhasorInfillSession.of_infill(job.infill).slice(
        job.plane, job.show, job.rect, engine=job.engine, progress=task.progress)
    return job


class SliceRunner(TaskRunner):
    """A TaskRunner of `SliceJob` s: ``request(job)`` submits `run_slice_job`
    with ``task.data = job``; ``finished(task, job)`` carries the job back."""

    def request(self, job: SliceJob, *, supersede: bool = True) -> Task:
        """Run ``job`` in place of any waiting one; stop the running one unless
        ``supersede`` is False (a painting update lets the previous one land)."""
        task = self.submit(lambda t: run_slice_job(job, t), data=job, supersede=supersede)
        job.serial = task.serial
        return task

