"""Tab in the node editor's view opens the node search (search-to-add)."""

from __future__ import annotations

from PySide6 import QtCore


def test_tab_in_the_graph_view_toggles_node_search(window, qtbot, monkeypatch):
    editor = window.editor
    calls = []
    monkeypatch.setattr(editor.search, "toggle_at_cursor", lambda: calls.append(1))
    view = editor.graph.viewer()
    view.setFocus()
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Tab)
    assert calls == [1]
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Tab, QtCore.Qt.KeyboardModifier.ShiftModifier)
    assert calls == [1]                      # Shift+Tab is not the search key
    editor.detach()                           # the window closing: Tab no longer reaches the editor
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Tab)
    assert calls == [1]
