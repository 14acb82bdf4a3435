"""The window's dock layout: a sensible default, kept between sessions in an injected
settings file (never the user's home), View › Reset Layout, and a layout saved by a
build with other docks (or an unreadable one) giving the default."""

from __future__ import annotations

import pytest
from PySide6 import QtCore, QtWidgets

from ui.window_layout import KEY_DOCKS, KEY_STATE, dock_arrangement

METHOD_DOCKS = {"Surfaces", "Virtual Growth", "Tile Sets", "Studies", "Phasor Infill", "Reaction Diffusion",
                "Implicit Media"}


@pytest.fixture
def open_window(qtbot, tmp_path, prompter):
    """Windows on a settings file, shown at the geometry they restore (unlike make_window,
    which resizes); each is closed at teardown."""
    from app.gui import create_main_window

    windows = []

    def make(settings):
        w = create_main_window(None, autosave_dir=tmp_path / "autosave", prompter=prompter, settings=settings)
        w.show()
        qtbot.waitExposed(w)
        qtbot.wait(30)
        windows.append(w)
        return w

    yield make
    for w in windows:
        prompter.unsaved_answer = "discard"
        w.close()
        assert w.viewport._closed
        w.deleteLater()
    qtbot.wait(10)


def _area(window, title):
    dock = next(d for d in window.findChildren(QtWidgets.QDockWidget) if d.windowTitle() == title)
    return window.dockWidgetArea(dock).name


def test_the_default_layout(window, qtbot):
    window.resize(1366, 728)
    qtbot.waitUntil(lambda: window.width() == 1366 and window.height() == 728, timeout=5000)
    qtbot.wait(30)
    assert window.layout_settings is None                  # nothing kept, nothing written
    assert window.centralWidget() is window.viewport
    assert _area(window, "Node graph") == "LeftDockWidgetArea"
    assert _area(window, "Inspector") == "RightDockWidgetArea"
    assert _area(window, "Log") == "BottomDockWidgetArea"
    tabbed = {d.windowTitle() for d in window.tabifiedDockWidgets(window.inspector_dock)}
    assert tabbed == METHOD_DOCKS
    assert not window.inspector_dock.visibleRegion().isEmpty()      # the inspector's tab is in front
    assert all(not d.isFloating() for d in window.findChildren(QtWidgets.QDockWidget))
    # the viewport keeps most of the height and a fair share of the width
    assert window.log_dock.height() <= 0.2 * window.height()
    assert window.viewport.height() >= 0.7 * window.height()
    assert window.viewport.width() >= 0.28 * window.width()
    assert window.editor_dock.width() >= 0.2 * window.width()
    # the right column runs the window's whole height, beside the log
    assert window.inspector_dock.geometry().bottom() > window.log_dock.geometry().top()


def test_the_layout_is_saved_on_close_and_restored(open_window, prompter, tmp_path, qtbot):
    from engine.graph import AddNode

    ini = tmp_path / "layout.ini"
    first = open_window(ini)
    assert not first.layout_restored
    avail = first.screen().availableGeometry()        # a restored geometry is kept on the screen
    size = QtCore.QSize(min(1366, avail.width() - 40), min(728, avail.height() - 60))
    first.resize(size)
    first.addDockWidget(QtCore.Qt.DockWidgetArea.LeftDockWidgetArea, first.phasor_dock)
    first.study_dock.toggleViewAction().trigger()     # View › Docks › Studies off
    first.log_dock.setFloating(True)
    qtbot.wait(30)
    first.resizeDocks([first.editor_dock], [300], QtCore.Qt.Orientation.Horizontal)
    qtbot.wait(30)
    arranged = dock_arrangement(first)
    editor_width = first.editor_dock.width()
    # a close the user cancels keeps the window, and writes nothing
    first.undo.push(AddNode("Vertex", {}, (0, 0)))
    prompter.unsaved_answer = "cancel"
    assert not first.close()
    assert prompter.unsaved_asked == 1 and not ini.exists()
    prompter.unsaved_answer = "discard"
    assert first.close()
    assert ini.is_file()

    second = open_window(ini)
    assert second.layout_restored
    qtbot.wait(30)
    assert dock_arrangement(second) == arranged
    assert _area(second, "Phasor Infill") == "LeftDockWidgetArea"
    assert second.study_dock.isHidden() and second.log_dock.isFloating()
    assert second.size() == size
    assert abs(second.editor_dock.width() - editor_width) <= 4


def test_reset_layout_returns_to_the_default(window, qtbot):
    default = dock_arrangement(window)
    editor_width = window.editor_dock.width()
    window.addDockWidget(QtCore.Qt.DockWidgetArea.BottomDockWidgetArea, window.rd_dock)
    window.tileset_dock.setFloating(True)
    window.inspector_dock.toggleViewAction().trigger()
    window.log_dock.toggleViewAction().trigger()
    window.phasor_dock.raise_()
    qtbot.wait(30)
    assert dock_arrangement(window) != default
    view = next(a.menu() for a in window.menuBar().actions() if a.text() == "&View")
    reset = next(a for a in view.actions() if a.text().replace("&", "") == "Reset Layout")
    reset.trigger()
    qtbot.wait(50)
    assert dock_arrangement(window) == default
    assert not window.inspector_dock.visibleRegion().isEmpty()
    assert abs(window.editor_dock.width() - editor_width) <= 0.05 * window.width()
    assert window.log_lines[-1] == ("info", "layout reset to the default")


def _saved(ini, qtbot, open_window):
    w = open_window(ini)
    w.rd_dock.toggleViewAction().trigger()
    assert w.close()
    return QtCore.QSettings(str(ini), QtCore.QSettings.Format.IniFormat)


def test_a_layout_saved_with_other_docks_gives_the_default(open_window, tmp_path, qtbot):
    ini = tmp_path / "old.ini"
    settings = _saved(ini, qtbot, open_window)
    settings.setValue(KEY_DOCKS, "Inspector,Log,Node_graph,Retired_Dock")      # an older build's docks
    settings.sync()
    w = open_window(ini)
    assert not w.layout_restored
    assert not w.rd_dock.isHidden()
    assert {d.windowTitle() for d in w.tabifiedDockWidgets(w.inspector_dock)} == METHOD_DOCKS


def test_an_unreadable_saved_layout_gives_the_default(open_window, tmp_path, qtbot):
    ini = tmp_path / "bad.ini"
    settings = _saved(ini, qtbot, open_window)
    settings.setValue(KEY_STATE, QtCore.QByteArray(b"not a window state"))
    settings.sync()
    w = open_window(ini)
    assert not w.layout_restored
    assert not w.rd_dock.isHidden()
    assert {d.windowTitle() for d in w.tabifiedDockWidgets(w.inspector_dock)} == METHOD_DOCKS
    assert w.close()                      # and the next close writes a good layout again
    assert open_window(ini).layout_restored
