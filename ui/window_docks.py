"""The main window's widgets: viewport in the centre, node editor left, the
inspector and the method docks tabbed right, progress bar and log below.

Every form dock's content sits in a scroll area, so a dock taller than the
screen scrolls instead of pushing the window's minimum height past a laptop's
screen (the node graph and the log scroll themselves).  Where the docks go by
default, and how the layout is saved and restored, is `ui.window_layout`.
"""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from .growth_panel import GrowthPanel
from .implicit_panel import ImplicitPanel
from .inspector import Inspector
from .node_editor import NodeEditor
from .phasor_panel import PhasorPanel
from .rd_panel import RDPanel
from .study_panel import StudyPanel
from .subgraph_inspector import SubgraphPanel
from .surface_panel import SurfacePanel
from .tileset_editor import TileSetEditor
from .viewport import Viewport

EDITOR_MIN_WIDTH = 280    # px: the node graph narrower than this shows too little to work in
SCROLL_MIN_WIDTH = 260    # px: a scrolled dock is never narrower (its content scrolls sideways below
                          # the content's own minimum width)
SCROLL_MIN_HEIGHT = 120   # px: nor shorter
LOG_MIN_HEIGHT = 40       # px: two lines of log under the progress bar


class WindowDocks:
    """Mixin of `MainWindow`: builds its widgets and docks and wires the docks'
    signals to the window (``self`` is the QMainWindow)."""

    # -- construction -------------------------------------------------------------------------
    def _build_widgets(self) -> None:
        self.viewport = Viewport(self)
        self.setCentralWidget(self.viewport)

        self.editor = NodeEditor(self.doc, self.undo, self)
        # copies carry the stateful nodes' latest results, and the evaluator takes a paste's
        self.editor.clipboard.state_source = self.worker.evaluator.export_state
        self.editor.clipboard.state_sink = self.worker.evaluator.add_state
        self.editor_dock = self._dock("Node graph", self.editor, scroll=False)
        self.editor.setMinimumWidth(EDITOR_MIN_WIDTH)

        self.inspector = Inspector(self.doc, self.undo, self)
        # under the node's parameters: the frame or subgraph clicked, or the one the node is in
        self.subgraph_panel = SubgraphPanel(self.doc, self.undo, self.editor.frames, self)
        self.subgraph_panel.message.connect(self.log)
        self.inspector_dock = self._dock("Inspector", _stacked(self.inspector, self.subgraph_panel))
        self.editor.frames.picked.connect(lambda _item: self.inspector_dock.raise_())
        self.subgraph_panel.setVisible(self.editor.frames.current is not None)
        self.editor.frames.current_changed.connect(lambda cur: self.subgraph_panel.setVisible(cur is not None))
        self.growth_panel = GrowthPanel(self, undo=self.undo)
        self.growth_dock = self._dock("Virtual Growth", self.growth_panel)
        self.tileset_editor = TileSetEditor(self.doc, self.undo, self)
        self.tileset_dock = self._dock("Tile Sets", self.tileset_editor)
        self.tileset_editor.message.connect(self.log)
        self.phasor_panel = PhasorPanel(self.doc, self.undo, self)
        self.phasor_dock = self._dock("Phasor Infill", self.phasor_panel)
        self.phasor_panel.preview_lines.connect(self.viewport.show_toolpaths)
        self.rd_panel = RDPanel(self.doc, self.undo, self)
        self.rd_dock = self._dock("Reaction Diffusion", self.rd_panel)
        self.rd_panel.evaluate_requested.connect(self.evaluate_now)
        self.rd_panel.live_box.adopt_result = self.adopt_result     # Apply hands a finished live growth over
        self.study_panel = StudyPanel(self)
        self.study_dock = self._dock("Studies", self.study_panel)
        self.study_panel.study_finished.connect(
            lambda code: self.log("info" if code == 0 else "warning", f"study finished with exit code {code}"))
        self.surface_panel = SurfacePanel(self.doc, self.undo, self)
        self.surface_dock = self._dock("Surfaces", self.surface_panel)
        self.surface_panel.evaluate_requested.connect(self.evaluate_now)
        self.surface_panel.node_selected.connect(self.editor.select)
        self.surface_panel.message.connect(self.log)
        self.editor.selection_changed.connect(self.surface_panel.set_selected)
        self.evaluation_finished.connect(self.surface_panel.set_report)
        self.implicit_panel = ImplicitPanel(self.doc, self.undo, self, prompter=self.prompter)
        self.implicit_dock = self._dock("Implicit Media", self.implicit_panel)
        self.implicit_panel.message.connect(self.log)
        self.editor.selection_changed.connect(self.implicit_panel.set_selected)
        self.evaluation_finished.connect(self.implicit_panel.set_report)

        bottom = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(bottom)
        lay.setContentsMargins(4, 2, 4, 4)
        row = QtWidgets.QHBoxLayout()
        self.progress = QtWidgets.QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setValue(0)
        self.progress.setTextVisible(True)
        self.progress.setFormat("idle")
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(self.cancel_evaluation)
        row.addWidget(self.progress, 1)
        row.addWidget(self.cancel_button)
        lay.addLayout(row)
        self.log_view = QtWidgets.QPlainTextEdit()
        self.log_view.setReadOnly(True)
        self.log_view.setMaximumBlockCount(2000)
        self.log_view.setMinimumHeight(LOG_MIN_HEIGHT)
        lay.addWidget(self.log_view)
        self.log_dock = self._dock("Log", bottom, scroll=False)   # the log scrolls itself
        self.arrange_default_docks()

    def _dock(self, title: str, widget: QtWidgets.QWidget, *, scroll: bool = True) -> QtWidgets.QDockWidget:
        """A movable, floatable, closable dock titled `title` (its object name, which saved layouts
        refer to, is the title with underscores); `widget` inside a scroll area unless
        ``scroll=False``.  Where it goes is `arrange_default_docks`."""
        dock = QtWidgets.QDockWidget(title, self)
        dock.setObjectName(title.replace(" ", "_"))
        dock.setWidget(scrolled(widget) if scroll else widget)
        feature = QtWidgets.QDockWidget.DockWidgetFeature
        # closable, so View › Docks can hide it (its toggle closes the dock) and show it again
        dock.setFeatures(feature.DockWidgetMovable | feature.DockWidgetFloatable | feature.DockWidgetClosable)
        self.addDockWidget(QtCore.Qt.DockWidgetArea.RightDockWidgetArea, dock)
        return dock


def scrolled(widget: QtWidgets.QWidget) -> QtWidgets.QScrollArea:
    """`widget` in a frameless scroll area that resizes it to the visible width and height,
    down to the widget's minimum size; below that (a short screen, a dock that grew after a
    preview) it scrolls, and the dock's minimum size stays small."""
    area = QtWidgets.QScrollArea()
    area.setObjectName(f"{widget.objectName() or type(widget).__name__}_scroll")
    area.setWidgetResizable(True)
    area.setFrameShape(QtWidgets.QFrame.Shape.NoFrame)
    area.setWidget(widget)
    area.setMinimumSize(SCROLL_MIN_WIDTH, SCROLL_MIN_HEIGHT)
    return area


def _stacked(*widgets: QtWidgets.QWidget) -> QtWidgets.QWidget:
    """`widgets` one above the other in one dock, the slack below them."""
    box = QtWidgets.QWidget()
    lay = QtWidgets.QVBoxLayout(box)
    lay.setContentsMargins(0, 0, 0, 0)
    for w in widgets:
        lay.addWidget(w)
    lay.addStretch(1)
    return box
