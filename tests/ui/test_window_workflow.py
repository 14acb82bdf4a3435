"""The whole window on a small graph: evaluate, inspect, edit, undo, save, reopen, screenshot."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtGui

from engine.graph import document_to_dict

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions


def png_pixels(path) -> np.ndarray:
    img = QtGui.QImage(str(path)).convertToFormat(QtGui.QImage.Format.Format_RGB888)
    assert not img.isNull()
    w, h, stride = img.width(), img.height(), img.bytesPerLine()
    buf = np.frombuffer(img.constBits(), dtype=np.uint8, count=stride * h).reshape(h, stride)
    return buf[:, : 3 * w].reshape(h, w, 3)


def test_small_graph_evaluates_and_viewport_shows_mesh(window, strut_graph, wait_eval):
    ids = strut_graph(window.undo)
    report = wait_eval(window, 0)
    assert report.ok, report.errors
    assert window.shown_solid_id == ids["obj"]          # the solid feeding the Voxel node
    assert window.shown_skeleton_id == ids["l"]
    assert window.viewport.mesh_point_count() > 0
    assert window.editor.node_status(ids["obj"]) == "evaluated"
    assert "*" in window.windowTitle()


def test_tiling_shows_27_copies(window, strut_graph, wait_eval):
    strut_graph(window.undo)
    wait_eval(window, 0)
    single = window.viewport.mesh_point_count()
    window.act_tiling.setChecked(True)
    assert window.viewport.mesh_point_count() == 27 * single
    assert window.act_tile3.isChecked()
    window.act_tile1.setChecked(True)
    assert window.viewport.mesh_point_count() == single
    window.act_solid.setChecked(False)
    assert window.viewport.mesh_point_count() == 0


def test_inspector_edits_parameter_and_undo_restores(window, qtbot, strut_graph, wait_eval):
    ids = strut_graph(window.undo)
    wait_eval(window, 0)
    window.editor.select(ids["obj"])
    assert window.inspector.node_id == ids["obj"]
    box = window.inspector.editor_widget("resolution")
    assert box.value() == 32
    assert box.minimum() == 8 and box.maximum() == 512
    n = window.eval_count
    box.setValue(40)                                    # what a user's edit ends in
    assert window.doc.nodes[ids["obj"]].params["resolution"] == 40
    assert window.undo.undo_text() == f"set {ids['obj']}.resolution"
    assert window.act_undo.text().endswith(f"set {ids['obj']}.resolution")
    report = wait_eval(window, n)
    assert report.results[ids["obj"]].status == "evaluated"
    assert report.results[ids["v1"]].status == "cached"   # upstream untouched
    assert "evaluated" in window.inspector.status_text()

    window.undo_edit()
    assert window.doc.nodes[ids["obj"]].params["resolution"] == 32
    assert box.value() == 32                            # the widget follows the document
    window.redo_edit()
    assert box.value() == 40


def test_inspector_shows_refused_value_inline(window, strut_graph, wait_eval):
    ids = strut_graph(window.undo)
    window.editor.select(ids["e"])
    before = document_to_dict(window.doc)
    depth = window.undo.can_undo, window.undo.undo_text()
    edit = window.inspector.editor_widget("order")
    edit.setText("0, x")
    edit.editingFinished.emit()
    assert window.inspector.error_label.isVisibleTo(window.inspector)
    assert "order" in window.inspector.error_label.text()
    assert document_to_dict(window.doc) == before
    assert (window.undo.can_undo, window.undo.undo_text()) == depth
    edit.setText("1, 0")
    edit.editingFinished.emit()
    assert window.doc.nodes[ids["e"]].params["order"] == [1, 0]
    assert not window.inspector.error_label.isVisibleTo(window.inspector)


def test_inspector_samples_table_and_label(window, strut_graph):
    ids = strut_graph(window.undo)
    window.editor.select(ids["l"])
    editor = window.inspector.editors["thickness"]
    assert editor.table.rowCount() == 2
    editor.add_button.click()
    assert len(window.doc.nodes[ids["l"]].params["thickness"]) == 3
    assert editor.table.rowCount() == 3
    editor.table.item(1, 1).setText("0.3")              # edit a value cell
    assert window.doc.nodes[ids["l"]].params["thickness"][1][1] == 0.3
    editor.table.item(1, 1).setText("5")                # above the 2.0 maximum: refused
    assert window.doc.nodes[ids["l"]].params["thickness"][1][1] == 0.3
    assert editor.table.item(1, 1).text() == "0.3"
    assert window.inspector.error_label.isVisibleTo(window.inspector)
    window.inspector.label_edit.setText("strut")
    window.inspector.label_edit.editingFinished.emit()
    assert window.doc.nodes[ids["l"]].label == "strut"
    assert window.editor.scene_node(ids["l"]).name().startswith("strut")


def test_save_then_reopen_gives_same_document(make_window, tmp_path, strut_graph, prompter):
    window = make_window()
    strut_graph(window.undo)
    path = tmp_path / "strut.json"
    assert window.save_as(path)
    assert window.windowTitle().startswith("strut.json")
    assert "*" not in window.windowTitle()
    other = make_window(path)
    assert other.project_path == path
    assert document_to_dict(other.doc) == document_to_dict(window.doc)
    assert other.editor.scene_node_ids() == set(window.doc.nodes)
    assert other.editor.scene_edges() == set(window.doc.edges)
    assert not prompter.errors


def test_screenshot_is_written_and_not_blank(window, tmp_path, strut_graph, wait_eval):
    strut_graph(window.undo)
    wait_eval(window, 0)
    path = window.viewport.save_screenshot(tmp_path / "view.png")
    assert path.is_file() and path.stat().st_size > 0
    pixels = png_pixels(path).astype(float)
    assert pixels.var() > 0
    # the solid is drawn in a light colour over a dark background: some bright pixels exist
    assert (pixels.mean(axis=2) > 150).any()


def test_export_mesh_uses_current_tiling(window, tmp_path, strut_graph, wait_eval):
    pytest.importorskip("engine.geometry.mesh_io")
    strut_graph(window.undo)
    wait_eval(window, 0)
    one = tmp_path / "cell.stl"
    assert window.export_mesh(one), window.prompter.errors
    window.act_tiling.setChecked(True)
    three = tmp_path / "block.obj"
    assert window.export_mesh(three), window.prompter.errors
    assert one.stat().st_size > 0 and three.stat().st_size > 0
    assert not window.export_mesh(tmp_path / "cell.xyz")  # refused with a message
    assert window.prompter.errors


def test_export_too_large_for_memory_is_refused_before_meshing(window, tmp_path, strut_graph, wait_eval,
                                                               monkeypatch):
    strut_graph(window.undo)
    wait_eval(window, 0)
    window.act_tiling.setChecked(True)
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "1M")    # the 3x3x3 block needs far more
    import engine.geometry.marching as marching
    monkeypatch.setattr(marching, "periodic_mesh", lambda *a, **k: pytest.fail("meshed anyway"))
    out = tmp_path / "block.stl"
    assert not window.export_mesh(out)
    assert not out.exists()
    assert "memory" in window.prompter.errors[-1][1] and "tiles" in window.prompter.errors[-1][1]
