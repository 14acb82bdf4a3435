"""The virtual-growth docks live in the window and act on its document."""

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
