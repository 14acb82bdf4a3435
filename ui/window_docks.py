"""The main window's widgets: viewport in the centre, node editor left, the
inspector and the method docks tabbed right, progress bar and log below."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from .growth_panel import GrowthPanel
from .inspector import Inspector
from .node_editor import NodeEditor
from .phasor_panel import PhasorPanel
from .rd_panel import RDPanel
from .study_panel import StudyPanel
from .surface_panel import SurfacePanel
from .tileset_editor import TileSetEditor
from .viewport import Viewport


class WindowDocks:
    """Mixin of `MainWindow`: builds its widgets and docks and wires the docks'
    signals to the window (``self`` is the QMainWindow)."""

    # -- construction -------------------------------------------------------------------------
    def _build_widgets(self) -> None:
        self.viewport = Viewport(self)
        self.setCentralWidget(self.viewport)

        self.editor = NodeEditor(self.doc, self.undo, self)
        self.editor_dock = self._dock("Node graph", self.editor, QtCore.Qt.DockWidgetArea.LeftDockWidgetArea)
        self.editor.setMinimumWidth(420)

        self.inspector = Inspector(self.doc, self.undo, self)
        scroll = QtWidgets.QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(self.inspector)
        scroll.setMinimumWidth(300)
        self.inspector_dock = self._dock("Inspector", scroll, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.growth_panel = GrowthPanel(self, undo=self.undo)
        self.growth_dock = self._dock("Virtual Growth", self.growth_panel, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.tabifyDockWidget(self.inspector_dock, self.growth_dock)
        self.tileset_editor = TileSetEditor(self.doc, self.undo, self)
        self.tileset_dock = self._dock("Tile Sets", self.tileset_editor, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.tabifyDockWidget(self.inspector_dock, self.tileset_dock)
        self.tileset_editor.message.connect(self.log)
        self.phasor_panel = PhasorPanel(self.doc, self.undo, self)
        self.phasor_dock = self._dock("Phasor Infill", self.phasor_panel, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.tabifyDockWidget(self.inspector_dock, self.phasor_dock)
        self.phasor_panel.preview_lines.connect(self.viewport.show_toolpaths)
        self.rd_panel = RDPanel(self.doc, self.undo, self)
        self.rd_dock = self._dock("Reaction Diffusion", self.rd_panel, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.tabifyDockWidget(self.inspector_dock, self.rd_dock)
        self.rd_panel.evaluate_requested.connect(self.evaluate_now)
        self.rd_panel.live_box.adopt_result = self.adopt_result     # Apply hands a finished live growth over
        self.study_panel = StudyPanel(self)
        self.study_dock = self._dock("Studies", self.study_panel, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.tabifyDockWidget(self.inspector_dock, self.study_dock)
        self.study_panel.study_finished.connect(
            lambda code: self.log("info" if code == 0 else "warning", f"study finished with exit code {code}"))
        self.surface_panel = SurfacePanel(self.doc, self.undo, self)
        self.surface_dock = self._dock("Surfaces", self.surface_panel, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)
        self.tabifyDockWidget(self.inspector_dock, self.surface_dock)
        self.surface_panel.evaluate_requested.connect(self.evaluate_now)
        self.surface_panel.node_selected.connect(self.editor.select)
        self.surface_panel.message.connect(self.log)
        self.editor.selection_changed.connect(self.surface_panel.set_selected)
        self.evaluation_finished.connect(self.surface_panel.set_report)
        self.inspector_dock.raise_()

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
        self.log_view.setMinimumHeight(70)
        lay.addWidget(self.log_view)
        self.log_dock = self._dock("Log", bottom, QtCore.Qt.DockWidgetArea.BottomDockWidgetArea)

    def _dock(self, title: str, widget: QtWidgets.QWidget, area) -> QtWidgets.QDockWidget:
        dock = QtWidgets.QDockWidget(title, self)
        dock.setObjectName(title.replace(" ", "_"))
        dock.setWidget(widget)
        dock.setFeatures(QtWidgets.QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QtWidgets.QDockWidget.DockWidgetFeature.DockWidgetFloatable)
        self.addDockWidget(area, dock)
        return dock
