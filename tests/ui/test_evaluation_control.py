"""Evaluation runs off the GUI thread, can be cancelled, and restarts on newer edits."""

from __future__ import annotations

import pytest

from PySide6 import QtCore

from engine.graph import SetParam
from engine.graph.node import EvalContext

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions


@pytest.fixture
def progress_checks(monkeypatch):
    """Counts the kernels' progress checks (EvalContext.progress calls) made
    after the evaluation was cancelled (those that answered "stop")."""
    seen = {"all": 0, "after_cancel": 0}
    original = EvalContext.progress

    def counted(self, done, total):
        go_on = original(self, done, total)
        seen["all"] += 1
        seen["after_cancel"] += not go_on
        return go_on

    monkeypatch.setattr(EvalContext, "progress", counted)
    return seen


def test_cancel_slow_evaluation_keeps_window_responsive(window, qtbot, slow_graph, wait_eval,
                                                       progress_checks):
    # Warm up first: numba compiles the kernels on first use and holds the GIL meanwhile.
    ids = slow_graph(window.undo, resolution=16)
    wait_eval(window, 0)
    window.act_auto.setChecked(False)
    window.undo.push(SetParam(ids["obj"], "resolution", 256))
    assert window.evaluation_idle                         # auto-evaluate off: nothing scheduled
    beats = {"running": 0}                                # GUI heartbeats while the worker runs
    timer = QtCore.QTimer()
    timer.timeout.connect(lambda: beats.update(running=beats["running"] + window.worker.is_running))
    timer.start(20)
    window.evaluate_now()
    assert window.worker.is_running
    assert window.cancel_button.isEnabled()
    # cancel while the Object node computes its distance field (it reports progress)
    qtbot.waitUntil(lambda: window.progress.format().startswith(ids["obj"]), timeout=60000)
    qtbot.waitUntil(lambda: beats["running"] >= 5, timeout=60000)
    assert window.worker.is_running, "the slow graph finished before it could be cancelled"
    qtbot.mouseClick(window.cancel_button, QtCore.Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.evaluation_idle, timeout=60000)   # generous; counts below
    timer.stop()
    # the kernel stopped at the first progress check that saw the cancel
    assert progress_checks["after_cancel"] <= 1, progress_checks
    report = window.last_report
    assert report.cancelled
    assert report.results[ids["obj"]].status == "cancelled"
    assert window.progress.format() == "cancelled"
    assert not window.cancel_button.isEnabled()
    # Kernels hold the GIL in stretches (numba without nogil, big numpy reductions), so
    # the event loop runs less often than the 20 ms timer asks; it must still run.
    assert beats["running"] >= 5


def test_newer_edit_supersedes_running_evaluation(window, qtbot, slow_graph, wait_eval):
    window.act_auto.setChecked(False)
    ids = slow_graph(window.undo, resolution=256)
    window.evaluate_now()
    qtbot.waitUntil(lambda: window.progress.format().startswith(ids["obj"]), timeout=30000)
    window.act_auto.setChecked(True)
    n = window.eval_count
    window.undo.push(SetParam(ids["obj"], "resolution", 24))   # debounced restart with the new snapshot
    report = wait_eval(window, n)
    assert not report.cancelled and report.ok, report.errors
    assert window.eval_count == n + 1                          # the superseded run was not reported
    assert window.current_solid().resolution == 24


def test_debounce_merges_quick_edits(window, qtbot, strut_graph, wait_eval):
    ids = strut_graph(window.undo, resolution=16)
    wait_eval(window, 0)
    started = []
    window.worker.started.connect(started.append)
    n = window.eval_count
    for r in (17, 18, 19, 20):
        window.undo.push(SetParam(ids["obj"], "resolution", r), merge=True)
    wait_eval(window, n)
    assert len(started) == 1
    assert window.current_solid().resolution == 20


def test_closing_during_evaluation_stops_the_worker(make_window, qtbot, slow_graph, progress_checks):
    window = make_window()
    window.act_auto.setChecked(False)
    ids = slow_graph(window.undo, resolution=256)
    window.evaluate_now()
    qtbot.waitUntil(lambda: window.progress.format().startswith(ids["obj"]), timeout=60000)
    assert window.close()                                 # the prompter discards the changes
    # closing cancelled the evaluation at its next progress check; it did not wait it out
    assert progress_checks["after_cancel"] <= 1, progress_checks
    assert not window.worker.is_busy and window.viewport._closed
