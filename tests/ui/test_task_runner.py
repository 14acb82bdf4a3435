"""ui.task_runner: one runner for every dock (supersede, coalesce, progress, frames, cancel).

Tasks here block on events the test sets, so what runs when is decided by
the test, not by timing."""

from __future__ import annotations

import threading

import pytest

from engine.progress import Cancelled, report
from ui.task_runner import TaskRunner


class Recorder:
    def __init__(self, runner: TaskRunner):
        self.events = []
        runner.started.connect(lambda t: self.events.append(("started", t.data)))
        runner.finished.connect(lambda t, r: self.events.append(("finished", t.data, r)))
        runner.failed.connect(lambda t, m: self.events.append(("failed", t.data, m)))
        runner.cancelled.connect(lambda t: self.events.append(("cancelled", t.data)))
        runner.published.connect(lambda t, o: self.events.append(("published", t.data, o)))
        runner.progress.connect(lambda t, d, n: self.events.append(("progress", t.data, d, n)))

    def of(self, kind):
        return [e[1:] for e in self.events if e[0] == kind]


def blocking(gate: threading.Event, entered: threading.Event | None = None, result=None):
    """A task that waits for ``gate`` while polling its progress (so a cancel stops it)."""
    def fn(task):
        if entered is not None:
            entered.set()
        while not gate.wait(0.005):
            report(task.progress, 0, 1)
        return result
    return fn


@pytest.fixture
def runner(qtbot):
    r = TaskRunner()
    yield r
    r.shutdown()


def test_a_task_runs_off_the_gui_thread_and_its_result_arrives(runner, qtbot):
    rec = Recorder(runner)
    gui = threading.get_ident()
    runner.submit(lambda task: threading.get_ident(), data="a")
    assert runner.wait_idle(10000)
    (data, worker), = rec.of("finished")
    assert data == "a" and worker != gui and rec.of("started") == [("a",)]


def test_a_new_request_supersedes_the_running_one_and_replaces_the_waiting_one(runner, qtbot):
    rec = Recorder(runner)
    gate, entered = threading.Event(), threading.Event()
    runner.submit(blocking(gate, entered, "first"), data="first")
    assert entered.wait(10)
    runner.submit(lambda t: "second", data="second", supersede=False)   # waits: first keeps running
    assert runner.running.data == "first" and runner.pending.data == "second"
    runner.submit(lambda t: "third", data="third")       # replaces "second", stops "first"
    assert runner.wait_idle(10000)
    assert rec.of("finished") == [("third", "third")]
    assert sorted(rec.of("cancelled")) == [("first",), ("second",)]
    assert [e[0] for e in rec.of("started")] == ["first", "third"]


def test_without_supersede_the_running_task_lands_first(runner, qtbot):
    rec = Recorder(runner)
    gate, entered = threading.Event(), threading.Event()
    runner.submit(blocking(gate, entered, 1), data="paint-1")
    assert entered.wait(10)
    runner.submit(lambda t: 2, data="paint-2", supersede=False)
    gate.set()
    assert runner.wait_idle(10000)
    assert rec.of("finished") == [("paint-1", 1), ("paint-2", 2)] and rec.of("cancelled") == []


def test_cancel_stops_the_running_task_and_drops_the_waiting_one(runner, qtbot):
    rec = Recorder(runner)
    gate, entered = threading.Event(), threading.Event()
    runner.submit(blocking(gate, entered), data="long")
    assert entered.wait(10)
    runner.submit(lambda t: "never", data="queued", supersede=False)
    busy = []
    runner.busy_changed.connect(busy.append)
    runner.cancel()
    assert runner.wait_idle(10000)
    assert sorted(rec.of("cancelled")) == [("long",), ("queued",)] and rec.of("finished") == []
    assert busy == [False] and not runner.is_busy


def test_failures_are_reported_not_raised_and_the_next_task_runs(runner, qtbot):
    rec = Recorder(runner)

    def broken(task):
        raise ValueError("bad cell")
    runner.submit(broken, data="x")
    assert runner.wait_idle(10000)
    runner.submit(lambda t: 5, data="y")
    assert runner.wait_idle(10000)
    assert rec.of("failed") == [("x", "ValueError: bad cell")] and rec.of("finished") == [("y", 5)]


def test_frames_are_coalesced_and_the_last_lands_before_the_result(runner, qtbot):
    rec = Recorder(runner)

    def frames(task):
        for k in range(50):          # published faster than the GUI takes them
            task.publish(k)
        return "done"
    runner.submit(frames, data="live")
    assert runner.wait_idle(10000)
    shown = [e[1] for e in rec.of("published")]
    assert shown and shown[-1] == 49 and shown == sorted(shown) and len(shown) <= 50
    kinds = [e[0] for e in rec.events if e[0] in ("published", "finished")]
    assert kinds[-1] == "finished" and kinds[-2] == "published"


def test_progress_reaches_the_gui_throttled_but_always_the_last(runner, qtbot):
    rec = Recorder(runner)

    def work(task):
        for k in range(1, 2001):
            assert task.progress(k, 2000)
        return None
    runner.submit(work, data="p")
    assert runner.wait_idle(10000)
    got = rec.of("progress")
    assert got[-1] == ("p", 2000.0, 2000.0) and 1 <= len(got) < 2000


def test_a_cancelled_token_stops_kernels_through_progress(runner, qtbot):
    rec = Recorder(runner)
    seen = []

    def fn(task):
        task.cancel()
        seen.append(task.progress(1, 2))
        report(task.progress, 1, 2)      # raises Cancelled
        return "unreachable"
    runner.submit(fn, data="c")
    assert runner.wait_idle(10000)
    assert seen == [False] and rec.of("cancelled") == [("c",)] and rec.of("finished") == []
    with pytest.raises(Cancelled):
        report(lambda d, t: False, 0, 1)
