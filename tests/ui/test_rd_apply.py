"""Apply after a live growth: the RD dock hands the finished growth to the window's evaluator.

A real MainWindow (auto-evaluation off) holds RDFields (a 24 x 12 .npz)
-> RDGrow (48 x 24 cells) -> RDCompile.  After a first evaluation the
RDGrow node's step limit is changed, so the evaluator has no result for
it; the dock grows live to the end and Apply is clicked.  What ran is
counted (RDGrow's evaluate calls, the report's statuses), never timed; the
compiled lattice is compared with a fresh evaluation of the same document.
"""

from __future__ import annotations

import numpy as np
import pytest

import engine.nodes  # noqa: F401  (registers the node types)
from engine.graph import AddNode, Connect, Evaluator, SetParam
from engine.nodes.rd import RDGrowNode

NX, NY = 24, 12
GROW = {"resolution": [48, 24], "gamma": 4.0, "max_steps": 200, "eps": 1e-14}


@pytest.fixture
def fields_path(tmp_path):
    path = tmp_path / "f.npz"
    rho = np.zeros((NY, NX))
    rho[2:10, 2:22] = 1.0
    theta = 0.3 + 0.02 * np.arange(NX)[None, :] + 0.0 * np.arange(NY)[:, None]
    c, s = np.cos(theta), np.sin(theta)
    np.savez(path, rho=rho, R=np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2))
    return path


@pytest.fixture
def grow_calls(monkeypatch):
    """RDGrow's evaluate calls (from the window's worker thread)."""
    calls = []
    real = RDGrowNode.evaluate

    def counting(self, inputs, params, ctx):
        calls.append(ctx.node_id)
        return real(self, inputs, params, ctx)

    monkeypatch.setattr(RDGrowNode, "evaluate", counting)
    return calls


@pytest.fixture
def rd_window(window, fields_path, wait_eval):
    """(window, {"f", "g", "c": node ids}) evaluated once; then RDGrow's max_steps changed, not evaluated."""
    window.act_auto.setChecked(False)
    undo = window.undo
    ids = {"f": undo.push(AddNode("RDFields", {"path": str(fields_path)})).node_id,
           "g": undo.push(AddNode("RDGrow", dict(GROW))).node_id,
           "c": undo.push(AddNode("RDCompile", {"iso": 0.6})).node_id}
    undo.push(Connect(ids["f"], "rdfields", ids["g"], "rdfields"))
    undo.push(Connect(ids["g"], "structures", ids["c"], "structures"))
    count = window.eval_count
    window.evaluate_now()
    assert wait_eval(window, count).ok
    undo.push(SetParam(ids["g"], "max_steps", 260))        # the evaluator holds no result for this
    return window, ids


def grow_live_to_the_end(qtbot, panel):
    assert panel.start_live()
    assert panel.worker.wait_stopped(120000)
    qtbot.waitUntil(lambda: panel.worker.status == "done", timeout=10000)
    assert panel.worker.last_frame.steps == (260, 260)


def apply(qtbot, window, panel, wait_eval):
    count = window.eval_count
    with qtbot.waitSignal(panel.evaluate_requested, timeout=1000):
        panel.apply_button.click()
    report = wait_eval(window, count)
    assert report.ok, report.errors
    return report


def test_apply_after_a_finished_live_growth_evaluates_only_what_follows(qtbot, rd_window, wait_eval, grow_calls):
    window, ids = rd_window
    panel = window.rd_panel
    grow_live_to_the_end(qtbot, panel)
    report = apply(qtbot, window, panel, wait_eval)
    assert report.results[ids["g"]].status == "cached"
    assert report.results[ids["c"]].status == "evaluated"
    assert grow_calls == []                                         # the window's evaluation grew nothing
    assert report.output(ids["g"]) is panel.worker.session.value   # the live growth's own value

    fresh = Evaluator().evaluate(window.doc.snapshot())
    assert grow_calls == [ids["g"]]
    ours, theirs = report.output(ids["c"], "field"), fresh.output(ids["c"], "field")
    assert ours.values.dtype == theirs.values.dtype and ours.values.tobytes() == theirs.values.tobytes()
    assert report.output(ids["g"]).s.tobytes() == fresh.output(ids["g"]).s.tobytes()
    # what the project would store is the node's state as after an evaluation of it
    assert set(window.worker.evaluator.export_state()) == {ids["g"]}


def test_brush_edits_are_applied_in_the_growth_thread_and_taken_with_it(qtbot, rd_window, wait_eval, grow_calls):
    window, ids = rd_window
    edit = {"mode": "erase", "centre": [24.0, 12.0], "radius": 3.0}
    window.undo.push(SetParam(ids["g"], "edits", [edit]))
    panel = window.rd_panel
    grow_live_to_the_end(qtbot, panel)
    assert panel.worker.session.value.edits == (edit,)             # made before Apply, off the GUI thread
    report = apply(qtbot, window, panel, wait_eval)
    assert report.results[ids["g"]].status == "cached" and grow_calls == []
    fresh = Evaluator().evaluate(window.doc.snapshot())
    assert report.output(ids["c"], "field").values.tobytes() == fresh.output(ids["c"], "field").values.tobytes()


def test_a_growth_with_other_parameters_is_not_taken(qtbot, rd_window, wait_eval, grow_calls):
    window, ids = rd_window
    panel = window.rd_panel
    grow_live_to_the_end(qtbot, panel)
    window.undo.push(SetParam(ids["g"], "gamma", 3.0))            # changed after the growth
    report = apply(qtbot, window, panel, wait_eval)
    assert report.results[ids["g"]].status == "evaluated" and grow_calls == [ids["g"]]
    assert report.output(ids["g"]) is not panel.worker.session.value


def test_a_cancelled_growth_is_not_offered(qtbot, rd_window):
    window, ids = rd_window
    panel = window.rd_panel
    offered = []
    panel.live_box.adopt_result = lambda *args: offered.append(args) or True
    window.undo.push(SetParam(ids["g"], "max_steps", 1_000_000))  # cannot finish before the cancel
    panel.every_spin.setValue(20)
    frames = []
    panel.live_box.frame.connect(frames.append)
    assert panel.start_live()
    qtbot.waitUntil(lambda: len(frames) >= 1, timeout=60000)
    panel.cancel_live()
    assert panel.worker.wait_stopped()
    qtbot.waitUntil(lambda: panel.worker.status == "cancelled", timeout=10000)
    assert panel.live_box.adopt(window.doc.nodes[ids["g"]], window.doc) is False
    assert offered == [] and panel.worker.session.value is None
