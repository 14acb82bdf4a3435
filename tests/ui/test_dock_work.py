"""The GUI thread does no work for what nobody sees (issue 14): counted, never timed.

* the Surfaces dock's matplotlib figures are drawn only while the dock is visible,
  once per change, off the GUI thread (selections with the dock hidden draw nothing;
  showing it draws what changed meanwhile, once);
* opening an example rebuilds the node editor's scene once, with no repaint of the
  graph view while its nodes are added;
* the Tile Sets browser reads the set folders only when it is shown or a row is
  asked for;
* the Studies dock's three figures likewise draw only the visible tab, off the
  GUI thread (a window starts without drawing any of them).
"""

from __future__ import annotations

from PySide6 import QtCore

from engine.graph import GraphDocument, UndoStack
from ui.main_window import EXAMPLES_DIR
from ui.tileset_editor import TileSetEditor

SCHWARZ_P = EXAMPLES_DIR / "tpms_schwarz_p.json"
LARGEST = EXAMPLES_DIR / "tpms_our_composition.json"    # 35 nodes


def _draws(panel) -> int:
    return panel.chart.draws + panel.schematic.draws


def test_hidden_surfaces_dock_draws_nothing_and_draws_once_when_shown(window, qtbot, wait_eval):
    panel = window.surface_panel
    window.surface_dock.hide()
    qtbot.waitUntil(lambda: not panel.chart.isVisible())
    after = window.eval_count
    before = _draws(panel)
    assert window.open_example(SCHWARZ_P, ask=False)
    window.evaluate_now()
    report = wait_eval(window, after, timeout=120000)
    assert report.ok, report.errors
    nodes = list(window.doc.nodes)
    for k in range(10):                                 # ten selections, the Surface among them
        window.editor.select(nodes[k % len(nodes)] if k % 3 else "s_hexagon")
        qtbot.wait(5)
    assert panel.chart.history.size >= 2                # the data is there ...
    assert _draws(panel) == before                      # ... but nothing was drawn

    window.surface_dock.show()
    window.surface_dock.raise_()
    panel.tabs.setCurrentWidget(panel.chart)
    qtbot.waitUntil(lambda: panel.chart.drawn > 0, timeout=20000)   # drawn off the GUI thread
    qtbot.wait(50)
    assert _draws(panel) == before + 1                  # the visible chart, once
    assert len(panel.chart.axes.lines[0].get_ydata()) == panel.chart.history.size
    assert panel.chart.image is not None and not panel.chart.image.isNull()

    shown = _draws(panel)
    for k in range(10):                                 # re-selecting shows the same content
        window.editor.select(nodes[k % len(nodes)] if k % 3 else "s_hexagon")
        qtbot.wait(5)
    assert _draws(panel) == shown

    panel.tabs.setCurrentWidget(panel.schematic)        # the other tab draws when shown
    qtbot.waitUntil(lambda: panel.schematic.drawn > 0, timeout=20000)
    assert panel.schematic.points2d.shape == (6, 2)
    assert len(panel.schematic.axes.texts) == 6         # the six vertex labels
    assert _draws(panel) == shown + 1


class _Paints(QtCore.QObject):
    def __init__(self):
        super().__init__()
        self.count = 0

    def eventFilter(self, watched, event):
        if event.type() == QtCore.QEvent.Type.Paint:
            self.count += 1
        return False


def test_opening_an_example_rebuilds_the_editor_scene_once_without_repaints(window, qtbot):
    editor = window.editor
    viewport = editor.graph.viewer().viewport()
    paints = _Paints()
    viewport.installEventFilter(paints)
    window.act_auto.setChecked(False)
    rebuilds = editor.scene_rebuilds
    during = []
    window.doc.subscribe(lambda event, _p: during.append(paints.count) if event == "reset" else None)
    assert window.open_example(LARGEST, ask=False)
    assert len(window.doc.nodes) >= 30
    assert editor.scene_rebuilds == rebuilds + 1
    assert len(editor.scene_edges()) == len(window.doc.edges)
    assert paints.count == during[-1]                   # nothing painted while the scene was built
    assert editor.graph.viewer().updatesEnabled()
    qtbot.waitUntil(lambda: paints.count > during[-1])  # and it is painted afterwards
    viewport.removeEventFilter(paints)


def test_tileset_browser_reads_the_folders_only_when_shown(qtbot, tmp_path, monkeypatch):
    monkeypatch.setenv("MESOFORGE_TILESET_DIR", str(tmp_path / "user_sets"))
    doc = GraphDocument()
    w = TileSetEditor(doc, UndoStack(doc))
    qtbot.addWidget(w)
    assert w.browser.fills == 0                         # built hidden: nothing read
    w.refresh_browser()
    w.refresh_browser()
    assert w.browser.fills == 0
    w.show()
    qtbot.waitExposed(w)
    assert w.browser.fills == 1                         # shown: read once
    assert w.browser.topLevelItemCount() == 2 and w.browser.topLevelItem(0).childCount() > 0
    w.refresh_browser()                                 # visible: "Refresh list" reads at once
    assert w.browser.fills == 2
    w.hide()
    w.refresh_browser()
    assert w.browser.fills == 2
    assert w.browser_item("TL+-") is not None           # asking for a row reads the folders
    assert w.browser.fills == 3


def test_hidden_surfaces_dock_builds_its_parameter_form_only_when_shown(window, qtbot):
    panel = window.surface_panel
    window.surface_dock.hide()
    qtbot.waitUntil(lambda: not panel.params_box.isVisible())
    window.act_auto.setChecked(False)
    builds = panel.form_builds
    assert window.open_example(SCHWARZ_P, ask=False)
    for nid in list(window.doc.nodes):                  # the Surface among them, the dock hidden
        window.editor.select(nid)
    assert panel.form_builds == builds                  # no form built for a hidden dock
    window.surface_dock.show()
    window.surface_dock.raise_()
    panel.tabs.setCurrentIndex(panel.tabs.count() - 1)  # "Parameters"
    qtbot.waitUntil(lambda: panel.params_box.isVisible())
    assert panel.form_builds == builds + 1
    assert "type" in panel.editors                      # the Surface's own parameters


def _study_draws(plots) -> list[int]:
    return [c.draws for c in (plots.scatter_canvas, plots.pies_canvas, plots.polar_canvas)]


def test_studies_dock_draws_only_its_visible_tab(window, qtbot):
    plots = window.study_panel.plots
    window.study_dock.hide()
    qtbot.waitUntil(lambda: not plots.isVisible())
    qtbot.wait(50)
    start = _study_draws(plots)
    assert start[1:] == [0, 0]                          # at most the tab on top was drawn at start
    for _ in range(3):
        plots.show_rows([])                              # new rows while hidden: kept, not drawn
    assert _study_draws(plots) == start

    window.study_dock.show()
    window.study_dock.raise_()
    plots.tabs.setCurrentIndex(0)
    qtbot.waitUntil(lambda: plots.scatter_canvas.drawn > 0, timeout=20000)
    qtbot.wait(50)
    assert _study_draws(plots) == [start[0] + 1, 0, 0]  # the newest rows, once
    texts = [t.get_text() for t in plots.scatter_canvas.axes.texts]
    assert texts == ["no study rows yet"]

    plots.tabs.setCurrentIndex(2)                        # the polar tab draws when shown
    qtbot.waitUntil(lambda: plots.polar_canvas.drawn > 0, timeout=20000)
    assert _study_draws(plots) == [start[0] + 1, 0, 1]
    assert plots.polar_curve() is None                   # no rows: no curve, nothing else drawn
    assert _study_draws(plots) == [start[0] + 1, 0, 1]
