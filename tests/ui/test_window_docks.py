"""The virtual-growth docks live in the window and act on its document."""

import json

from PySide6 import QtWidgets

from engine.graph import AddNode
from engine.growth import list_tilesets


def test_growth_docks_are_in_the_window_and_act_on_its_undo_stack(window):
    titles = {d.windowTitle() for d in window.findChildren(QtWidgets.QDockWidget)}
    assert {"Virtual Growth", "Tile Sets", "Studies", "Inspector"} <= titles
    assert window.growth_panel.undo is window.undo
    nid = window.undo.push(AddNode("TileSet", {"name": "TL+-"}, (0, 0))).node_id
    window._on_selection_changed(nid)
    assert window.tileset_editor.node_id == nid
    assert window.tileset_editor.open_path(list_tilesets()["tl_extended"])
    pushed_before = window.undo.undo_text()
    window.tileset_editor.use_in_node()
    assert window.undo.undo_text() != pushed_before
    window.undo.undo()
    assert window.undo.undo_text() == pushed_before


def test_phasor_example_paints_in_the_window_and_toolpaths_show_in_the_viewport(window, qtbot, wait_eval):
    import numpy as np

    from ui.main_window import EXAMPLES_DIR

    after = window.eval_count
    assert window.open_example(EXAMPLES_DIR / "phasor_slab.json", ask=False)
    window.evaluate_now()
    report = wait_eval(window, after, timeout=120000)
    assert report.ok, report.errors
    assert window.phasor_panel.fields_id is not None
    titles = {d.windowTitle() for d in window.findChildren(QtWidgets.QDockWidget)}
    assert "Phasor Infill" in titles
    points = np.array([[0, 0, 0.2], [10, 0, 0.2], [10, 10, 0.2]], float)
    segments = np.array([[0, 1], [1, 2]])
    colours = np.array([[255, 0, 0], [0, 0, 255]], np.uint8)
    window.phasor_panel.preview_lines.emit(points, segments, colours)
    assert window.viewport.toolpath_segment_count() == 2


def test_topopt_loads_and_supports_are_edited_as_json_in_the_inspector(window, qtbot):
    nid = window.undo.push(AddNode("TopOpt", {"preset": "cantilever", "resolution": [24, 12]}, (0, 0))).node_id
    window._on_selection_changed(nid)
    editor = window.inspector.editors["problem"]
    dialog = editor.open_dialog(modal=False)
    dialog.text.setPlainText("{not json")
    assert not dialog.try_accept()
    assert "not valid JSON" in dialog.error.text() and dialog.isVisible()
    # a downward unit load at the middle of the right edge, as a second load case
    new = {"load_cases": [[{"node": [24, 6], "force": [0.0, -1.0]}], [{"node": [24, 12], "force": [0.0, -1.0]}]]}
    dialog.text.setPlainText(json.dumps(new))
    assert dialog.try_accept()
    assert window.doc.node(nid).params["problem"] == new
    window.undo.undo()
    assert window.doc.node(nid).params["problem"] == {}


def test_a_tpms_example_opens_and_shows_its_shell_in_the_viewport(window, wait_eval):
    from ui.main_window import EXAMPLES_DIR

    after = window.eval_count
    assert window.open_example(EXAMPLES_DIR / "tpms_schwarz_p.json", ask=False)
    window.evaluate_now()
    report = wait_eval(window, after, timeout=120000)
    assert report.ok, report.errors
    surfaces = [nid for nid, n in window.doc.nodes.items() if n.type_name == "Surface"]
    assert surfaces and all(report.output(nid, "report").area > 0 for nid in surfaces)
    assert window.viewport.mesh_point_count() > 0
