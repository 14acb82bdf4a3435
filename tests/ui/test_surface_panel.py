"""The Surfaces dock in a real window: reports, convergence, the boundary loop, edits, errors.

Expected values come from elsewhere: the area from the engine's Evaluator run
here on the same example, the loop vertices from the example's Vertex nodes,
the failing vertex from the position moved here.
"""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtWidgets

from engine.graph import AddNode, Connect, Evaluator, SetParam, load_project
from ui.main_window import EXAMPLES_DIR

SCHWARZ_P = EXAMPLES_DIR / "tpms_schwarz_p.json"
SURFACE = "s_hexagon"


@pytest.fixture(scope="module")
def engine_area():
    report = Evaluator().evaluate(load_project(SCHWARZ_P), targets=[SURFACE])
    return report.output(SURFACE, "report").area


def open_schwarz_p(window, wait_eval):
    after = window.eval_count
    assert window.open_example(SCHWARZ_P, ask=False)
    window.evaluate_now()
    return wait_eval(window, after, timeout=120000)


def test_schwarz_p_report_chart_and_loop_show_in_the_dock(window, wait_eval, engine_area):
    report = open_schwarz_p(window, wait_eval)
    assert report.ok, report.errors
    titles = {d.windowTitle() for d in window.findChildren(QtWidgets.QDockWidget)}
    assert "Surfaces" in titles
    panel = window.surface_panel
    assert panel.listed_ids() == [SURFACE]
    assert panel.node_id == SURFACE
    shown = float(panel.report_labels["area"].text().split()[0])
    assert shown == pytest.approx(engine_area, rel=0.01)
    assert panel.report_labels["solver"].text() == "conjugate"
    assert panel.report_labels["converged"].text() == "yes"
    assert panel.error_text() == ""
    history = panel.chart.history
    assert history.size >= 2 and np.all(np.isfinite(history))
    assert history[-1] == pytest.approx(float(panel.report_labels["energy"].text()), rel=1e-5)
    panel.chart.ensure_drawn()         # a hidden dock's chart is laid out only when shown
    assert len(panel.chart.axes.lines) >= 1 and len(panel.chart.axes.lines[0].get_ydata()) == history.size
    # the hexagon in its best-fit plane: six vertices, every segment slides for a conjugate solve
    assert panel.schematic.points2d.shape == (6, 2)
    assert panel.schematic.sliding.all()
    assert panel.schematic.labels[0].startswith("0")


def test_selection_follows_the_editor_and_the_list(window, qtbot, wait_eval):
    open_schwarz_p(window, wait_eval)
    panel = window.surface_panel
    dual = window.undo.push(AddNode("DualSurface", {}, (600, 400))).node_id
    window.undo.push(Connect(SURFACE, "skeleton", dual, "skeleton"))
    assert panel.listed_ids() == [SURFACE, dual]
    window.editor.select(dual)
    assert panel.node_id == dual
    assert SURFACE in panel.title.text()                   # its source
    assert set(panel.editors) == {"quarter_turn"}            # its own parameters
    panel.node_list.setCurrentRow(panel.listed_ids().index(SURFACE))
    assert window.editor.selected_ids() == [SURFACE]
    assert window.inspector.node_id == SURFACE
    assert "type" in panel.editors
    window.editor.select("mirror_x")                        # not a surface node: keeps the one shown
    assert panel.node_id == SURFACE
    qtbot.waitUntil(lambda: window.evaluation_idle, timeout=60000)


def test_a_parameter_edit_is_one_undo_item_and_solve_again_evaluates(window, qtbot, wait_eval):
    open_schwarz_p(window, wait_eval)
    panel = window.surface_panel
    before = len(window.undo._done)
    box = panel.editor_widget("edge_length")
    box.setValue(0.04)
    assert len(window.undo._done) == before + 1
    assert window.doc.nodes[SURFACE].params["edge_length"] == pytest.approx(0.04)
    assert "changed since this solve" in panel.status_label.text()
    window.undo.undo()
    assert len(window.undo._done) == before
    assert window.doc.nodes[SURFACE].params["edge_length"] == pytest.approx(0.025)
    assert box.value() == pytest.approx(0.025)
    # alpha only matters for the direct thin shell
    assert not panel.form.isRowVisible(panel.editor_widget("alpha"))
    combo = panel.editor_widget("type")
    combo.setCurrentIndex(combo.findData("direct"))
    assert len(window.undo._done) == before + 1
    assert panel.form.isRowVisible(panel.editor_widget("alpha"))
    assert not panel.schematic.sliding.any()                  # a thin shell is pinned to its loop
    window.undo.undo()
    assert window.doc.nodes[SURFACE].params["type"] == "conjugate"
    assert combo.currentData() == "conjugate"
    qtbot.waitUntil(lambda: window.evaluation_idle, timeout=60000)
    window.act_auto.setChecked(False)
    after = window.eval_count
    with qtbot.waitSignal(panel.evaluate_requested, timeout=5000):
        panel.solve_button.click()
    wait_eval(window, after)
    assert panel.report_labels["solver"].text() == "conjugate"


def test_a_failing_conjugate_surface_shows_the_error_naming_the_vertex(window, wait_eval):
    open_schwarz_p(window, wait_eval)
    panel = window.surface_panel
    after = window.eval_count
    # on the face x = 0 but on no FBV edge
    window.undo.push(SetParam("v_hexagon0", "position", [0.0, 0.4, 0.25]))
    report = wait_eval(window, after)
    assert SURFACE in report.errors
    text = panel.error_text()
    assert text == report.errors[SURFACE]                     # verbatim
    assert "loop vertex 0" in text and "rule on-edge" in text
    assert panel.error_label.isVisible() and "#e04040" in panel.error_label.styleSheet()
    assert panel.report_labels["area"].text() == "—"
    assert panel.chart.history.size == 0
    assert panel.schematic.marked == 0
    np.testing.assert_allclose(panel.schematic.points2d.shape, (6, 2))


def test_what_slides_follows_the_solver_and_the_report():
    from engine.geometry.surfaces.values import SurfaceReport
    from ui.surface_panel import error_vertex, sliding_segments

    segment_chain = [0, 0, 1, 1, 2]
    smooth = [True, False, True]
    assert sliding_segments("conjugate", segment_chain, smooth, None).all()
    assert not sliding_segments("direct", segment_chain, smooth, None).any()
    # before a solve: the smooth chains; after: the chains the solver slid
    assert sliding_segments("mixed_minimal", segment_chain, smooth, None).tolist() == [1, 1, 0, 0, 1]
    rep = SurfaceReport("mixed_minimal", 3, 1.0, 1.0, 0.0, 0.0, 0.1,
                        details={"sliding": [{"chain": 2, "plane": "x = 1", "source": "fbv face"}]})
    assert sliding_segments("mixed_minimal", segment_chain, smooth, rep).tolist() == [0, 0, 0, 0, 1]
    assert error_vertex("node 's' (Surface): loop vertex 12 (chain 1, vertex 3), rule on-edge: …") == 12
    assert error_vertex("a surface needs edge chains") is None


def test_a_typed_out_of_range_value_is_refused_at_its_field(window, qtbot, wait_eval):
    from PySide6.QtCore import Qt

    from engine.graph import document_to_dict

    open_schwarz_p(window, wait_eval)
    window.act_auto.setChecked(False)
    panel = window.surface_panel
    window.surface_dock.raise_()
    before, depth = document_to_dict(window.doc), len(window.undo._done)
    box = panel.editor_widget("edge_length")
    box.lineEdit().selectAll()
    qtbot.keyClicks(box.lineEdit(), "3")                     # allowed: [0.005, 1] cell
    qtbot.keyClick(box, Qt.Key.Key_Return)
    assert document_to_dict(window.doc) == before and len(window.undo._done) == depth
    message = panel.param_form.messages["edge_length"]
    assert panel.refused_label is message and message.refused
    assert "edge_length = 3 refused" in message.text() and "[0.005, 1] cell" in message.text()
    assert box.property("refused") is True and box.value() == pytest.approx(0.025)
    box.setValue(0.03)                                        # a good value clears it
    assert window.doc.nodes[SURFACE].params["edge_length"] == pytest.approx(0.03)
    assert not message.refused and box.property("refused") is False
    window.undo.undo()                                        # and undo shows the stored value
    assert box.value() == pytest.approx(0.025)
