"""The window fits a 1366 x 768 laptop (1366 x 728 once a taskbar is drawn): docks taller
than the screen scroll, the Phasor dock's histograms are reached by scrolling after a
preview, and every dock's tab title is written out in full."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtCore, QtWidgets

LAPTOP = (1366, 728)


def _settle(qtbot, window, size=LAPTOP):
    window.resize(*size)
    qtbot.waitUntil(lambda: (window.width(), window.height()) == size, timeout=5000)
    qtbot.wait(50)


def _scrolled_docks(window):
    return [d for d in window.findChildren(QtWidgets.QDockWidget) if isinstance(d.widget(), QtWidgets.QScrollArea)]


def test_the_window_accepts_a_1366x728_geometry(window, qtbot):
    hint, minimum = window.minimumSizeHint(), window.minimumSize()
    assert hint.width() <= LAPTOP[0] and hint.height() <= LAPTOP[1], hint
    assert minimum.width() <= LAPTOP[0] and minimum.height() <= LAPTOP[1], minimum
    _settle(qtbot, window)
    assert window.geometry().size() == QtCore.QSize(*LAPTOP)
    assert window.viewport.width() >= 0.25 * LAPTOP[0] and window.viewport.height() >= 0.6 * LAPTOP[1]


def test_every_form_dock_scrolls_to_all_of_its_content(window, qtbot):
    _settle(qtbot, window)
    docks = _scrolled_docks(window)
    titles = {d.windowTitle() for d in docks}
    assert {"Inspector", "Virtual Growth", "Tile Sets", "Phasor Infill", "Reaction Diffusion", "Studies",
            "Surfaces", "Implicit Media"} <= titles
    # the rest scroll themselves: the node graph is a graphics view, the log a text view
    others = [d for d in window.findChildren(QtWidgets.QDockWidget) if d not in docks]
    for dock in others:
        assert dock.findChildren(QtWidgets.QAbstractScrollArea) or isinstance(dock.widget(),
                                                                             QtWidgets.QAbstractScrollArea)
    tall = 0
    for dock in docks:
        dock.raise_()
        qtbot.waitUntil(lambda d=dock: d.widget().isVisible(), timeout=3000)
        qtbot.wait(20)
        area = dock.widget()
        content = area.widget()
        need = content.minimumSizeHint()
        # never squashed below what it needs; the rest is a scroll away
        assert content.height() >= need.height() and content.width() >= need.width(), dock.windowTitle()
        bar = area.verticalScrollBar()
        assert bar.maximum() == max(0, content.height() - area.viewport().height()), dock.windowTitle()
        tall += bar.maximum() > 0
        assert window.size() == QtCore.QSize(*LAPTOP)
    assert tall >= 1, "at 728 px the tallest method dock (Reaction Diffusion) must scroll"


def _write_gcode(path):
    from engine.fab import Layer, write_gcode

    layers = []
    for k in range(4):
        z = 0.2 * (k + 1)
        # each layer shifted sideways: the upper lines hang over, the close pairs overlap
        x0 = 3.0 * k
        paths = [np.array([[x0, y], [x0 + 10.0, y]]) for y in np.arange(0.0, 4.0, 0.25)]
        layers.append(Layer(z=z, paths=tuple(paths), kinds=("infill",) * len(paths)))
    write_gcode(layers, path)


def test_the_phasor_histograms_are_reached_by_scrolling_after_a_preview(window, qtbot, tmp_path):
    _settle(qtbot, window)
    window.phasor_dock.raise_()
    qtbot.waitUntil(window.phasor_dock.widget().isVisible, timeout=3000)
    box = window.phasor_panel.print_box
    gcode = tmp_path / "lines.gcode"
    _write_gcode(gcode)
    assert box.preview_gcode(gcode)
    assert box.check_button.isEnabled()
    with qtbot.waitSignal(box.printability, timeout=60000):
        qtbot.mouseClick(box.check_button, QtCore.Qt.MouseButton.LeftButton)
    view = box.printability_view
    assert view is not None and view.isVisible()
    qtbot.wait(50)
    assert window.size() == QtCore.QSize(*LAPTOP), "the window must not grow past the screen"
    area = window.phasor_dock.widget()
    bar = area.verticalScrollBar()
    assert bar.maximum() > 0                             # the dock is taller than the screen now
    area.ensureWidgetVisible(view.canvas, 0, 0)
    qtbot.wait(20)
    top_left = view.canvas.mapTo(area.viewport(), QtCore.QPoint(0, 0))
    shown = QtCore.QRect(top_left, view.canvas.size())
    assert area.viewport().rect().contains(shown), (shown, area.viewport().rect())
    assert bar.value() > 0


@pytest.mark.parametrize("size", [LAPTOP, (1920, 1040)])
def test_dock_tab_titles_are_not_elided(window, qtbot, size):
    _settle(qtbot, window, size)
    titles = {d.windowTitle() for d in window.findChildren(QtWidgets.QDockWidget)}
    bars = [b for b in window.findChildren(QtWidgets.QTabBar) if b.parent() is window and b.isVisible()]
    assert bars and max(b.count() for b in bars) >= 7       # the inspector and the method docks
    for bar in bars:
        for i in range(bar.count()):
            text = bar.tabText(i)
            assert text in titles
            rect = bar.tabRect(i)
            assert bar.rect().contains(rect), f"tab {text!r} is scrolled out of its bar"
            along = max(rect.width(), rect.height())      # side tabs run along their height
            assert along >= bar.fontMetrics().horizontalAdvance(text), f"tab {text!r} is elided"
