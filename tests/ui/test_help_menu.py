"""Help › Keyboard Shortcuts lists every action that has a shortcut (read from the
window's QActions); Help › About names the version, the five methods and the
libraries; every menu action has a tooltip and a status tip."""

from __future__ import annotations

from importlib import metadata

from PySide6 import QtGui, QtWidgets

from ui.help_dialogs import PAPERS


def _menu_actions(menu: QtWidgets.QMenu):
    for action in menu.actions():
        if action.menu() is not None:
            yield from _menu_actions(action.menu())
        elif not action.isSeparator():
            yield action


def _help_menu(window) -> QtWidgets.QMenu:
    (menu,) = [a.menu() for a in window.menuBar().actions() if a.menu() and a.text() == "&Help"]
    return menu


def test_help_menu_has_shortcuts_and_about(window):
    texts = [a.text() for a in _help_menu(window).actions()]
    assert "&Keyboard Shortcuts…" in texts and "&About Mesoforge…" in texts


def test_shortcuts_lists_every_action_with_a_shortcut(window, qtbot):
    window.act_shortcuts.trigger()
    dialog = window.shortcuts_dialog
    qtbot.waitExposed(dialog)
    assert not dialog.isModal()
    rows = dialog.rows()
    native = QtGui.QKeySequence.SequenceFormat.NativeText
    expected = 0
    for action in set(window.actions()) | set(window.findChildren(QtGui.QAction)):
        keys = [k.toString(native) for k in action.shortcuts() if not k.isEmpty()]
        if not keys or not action.text():
            continue
        expected += 1
        name = action.text().replace("&", "").rstrip("…")
        hits = [r for r in rows if r[0] == name]
        assert hits, f"{name!r} ({keys}) missing from the shortcuts table"
        assert any(all(k in shown for k in keys) for _, shown in hits), (name, keys, hits)
    assert expected >= 15 and len(rows) >= 15
    for must in ("Undo", "Redo", "Evaluate Now", "Example Gallery", "Keyboard Shortcuts"):
        assert any(r[0] == must for r in rows), must
    dialog.close()


def test_shortcuts_table_follows_an_action_added_later(window, qtbot):
    late = QtGui.QAction("Late &Action", window)
    late.setShortcut(QtGui.QKeySequence("Ctrl+Alt+K"))
    window.addAction(late)
    window.act_shortcuts.trigger()
    window.act_shortcuts.trigger()       # shown again: read afresh
    rows = window.shortcuts_dialog.rows()
    assert ("Late Action", QtGui.QKeySequence("Ctrl+Alt+K").toString(
        QtGui.QKeySequence.SequenceFormat.NativeText)) in rows
    window.shortcuts_dialog.close()


def test_about_names_version_methods_and_libraries(window, qtbot):
    window.act_about.trigger()
    box = window.about_box
    qtbot.waitExposed(box)
    text = box.text()
    assert metadata.version("mesoforge") in text
    assert len(PAPERS) == 5
    for method, who, title in PAPERS:
        assert method in text and who.split(",")[0] in text and title in text
    import PySide6
    for lib in ("numpy", "scipy", "vtk", "trimesh", "dask"):
        assert f"{lib} {metadata.version(lib)}" in text, lib
    assert f"PySide6 {PySide6.__version__}" in text
    box.close()


def test_every_menu_action_has_a_tooltip_and_status_tip(window):
    from ui.help_dialogs import ACTION_TIPS

    native = QtGui.QKeySequence.SequenceFormat.NativeText
    for top in window.menuBar().actions():
        for action in _menu_actions(top.menu()):
            if action.parent() is not window:          # dock toggles and tiling choices: Qt's own
                continue
            assert action.statusTip() and action.toolTip(), action.text()
            if not action.shortcut().isEmpty():
                assert action.shortcut().toString(native) in action.toolTip(), action.text()
    described = [getattr(window, name) for name in ACTION_TIPS if hasattr(window, name)]
    assert len(described) >= 20
    for action in described:
        assert action.statusTip() != action.text().replace("&", ""), action.text()
    keys = window.act_evaluate.shortcut().toString(QtGui.QKeySequence.SequenceFormat.NativeText)
    assert keys in window.act_evaluate.toolTip()
    assert "Evaluate the graph" in window.act_evaluate.statusTip()
