"""The Mesoforge main window: node editor, viewport, inspector, log.

The window owns one GraphDocument (kept for its whole life; opening a file
replaces its content), its UndoStack and one EvalWorker (so the evaluator's
cache survives edits).  Document changes schedule a debounced evaluation on
the worker thread; reports come back as signals and are drawn here.  Every
question to the user goes through a `Prompter`, which tests replace.
"""

from __future__ import annotations

import html
import time
from pathlib import Path

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from app.autosave import AutosaveManager
from engine.graph import (EvalReport, GraphDocument, NodeResult, ProjectFileError, UndoStack, load_project,
                          save_project)
from engine.graph.values import Solid

from .dialogs import MESH_FILTERS, Prompter
from .eval_worker import EvalWorker
from .growth_panel import GrowthPanel
from .phasor_panel import PhasorPanel
from .rd_panel import RDPanel
from .study_panel import StudyPanel
from .surface_panel import SurfacePanel
from .tileset_editor import TileSetEditor
from .inspector import Inspector
from .node_editor import NodeEditor
from .viewport import Viewport, pick_display_nodes, pick_stiffness_node, skeleton_of, solid_of, stiffness_of

EXAMPLES_DIR = Path(__file__).resolve().parents[1] / "resources" / "examples"
DEFAULT_EXAMPLE = "octet.json"
EVAL_DEBOUNCE_MS = 150
AUTOSAVE_INTERVAL_MS = 3 * 60 * 1000


class MainWindow(QtWidgets.QMainWindow):
    """Node editor (left), 3D viewport (centre), inspector (right), log (bottom)."""

    evaluation_finished = QtCore.Signal(object)

    def __init__(self, *, autosave_dir: str | Path | None = None, prompter: Prompter | None = None,
                 autosave_interval_ms: int = AUTOSAVE_INTERVAL_MS, parent=None):
        super().__init__(parent)
        self.setObjectName("MesoforgeMainWindow")
        self.prompter = prompter or Prompter(self)
        self.doc = GraphDocument()
        self.undo = UndoStack(self.doc)
        self.project_path: Path | None = None
        self.display_name = "untitled"
        self._dirty_without_undo = False  # e.g. a recovered autosave not yet saved
        self.last_report: EvalReport | None = None
        self.eval_count = 0  # finished (not superseded) evaluations, for waiting in tests
        self.shown_solid_id: str | None = None
        self.shown_skeleton_id: str | None = None
        self.shown_stiffness_id: str | None = None  # the Stiffness the viewport draws a material sphere of
        self.log_lines: list[tuple[str, str]] = []
        self._eval_total = 0
        self._eval_done: list[NodeResult] = []
        self._shutting_down = False
        self._generation = 0  # bumped whenever the document is replaced (new / open / recover)

        self.worker = EvalWorker(parent=self)
        self.autosave = AutosaveManager(autosave_dir)

        self._build_widgets()
        self._build_actions()
        self._build_menus()

        self._debounce = QtCore.QTimer(self)
        self._debounce.setSingleShot(True)
        self._debounce.setInterval(EVAL_DEBOUNCE_MS)
        self._debounce.timeout.connect(self.evaluate_now)
        self._autosave_timer = QtCore.QTimer(self)
        self._autosave_timer.setInterval(int(autosave_interval_ms))
        self._autosave_timer.timeout.connect(self.autosave_now)
        self._autosave_timer.start()

        self.doc.subscribe(self._on_doc_event)
        self.undo.subscribe(self._on_undo_changed)
        self.worker.started.connect(self._on_eval_started)
        self.worker.progress.connect(self._on_eval_progress)
        self.worker.node_done.connect(self._on_eval_node_done)
        self.worker.finished.connect(self._on_eval_finished)
        self.editor.selection_changed.connect(self._on_selection_changed)
        self.editor.message.connect(self.log)
        self.inspector.message.connect(self.log)

        self.resize(1500, 900)
        self._on_undo_changed()

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

    def _action(self, text: str, slot, shortcut=None, checkable=False, checked=False) -> QtGui.QAction:
        action = QtGui.QAction(text, self)
        if shortcut is not None:
            action.setShortcut(QtGui.QKeySequence(shortcut))
        if checkable:
            action.setCheckable(True)
            action.setChecked(checked)
            action.toggled.connect(slot)
        else:
            action.triggered.connect(lambda _checked=False: slot())
        self.addAction(action)
        return action

    def _build_actions(self) -> None:
        K = QtGui.QKeySequence.StandardKey
        self.act_new = self._action("&New", self.new_project, K.New)
        self.act_open = self._action("&Open…", self.open_project, K.Open)
        self.act_save = self._action("&Save", self.save, K.Save)
        self.act_save_as = self._action("Save &As…", self.save_as, K.SaveAs)
        self.act_export = self._action("&Export Mesh…", self.export_mesh, "Ctrl+E")
        self.act_quit = self._action("&Quit", self.close, K.Quit)
        self.act_undo = self._action("&Undo", self.undo_edit, K.Undo)
        self.act_redo = self._action("&Redo", self.redo_edit, K.Redo)
        self.act_delete = self._action("&Delete Node", self.editor.delete_selected, K.Delete)
        self.act_tiling = self._action("Tile 3×3×3", lambda on: self.viewport.set_tiling(3 if on else 1),
                                       "T", checkable=True)
        self.act_skeleton = self._action("Show &Skeleton", self.viewport.set_show_skeleton, checkable=True,
                                         checked=True)
        self.act_solid = self._action("Show S&olid", self.viewport.set_show_solid, checkable=True, checked=True)
        self.act_sphere = self._action("Show &Material Sphere", self.viewport.set_show_sphere, checkable=True,
                                       checked=True)
        self.act_fit = self._action("Fit Node Graph", self.editor.fit_view, "F")
        self.act_arrange = self._action("Arrange Nodes", self.editor.arrange_nodes, "Ctrl+L")
        self.act_reset_camera = self._action("Reset Camera", self.viewport.reset_camera, "R")
        self.act_evaluate = self._action("&Evaluate Now", self.evaluate_now, "F5")
        self.act_auto = self._action("&Auto-evaluate", self._on_auto_toggled, checkable=True, checked=True)
        self.act_cancel = self._action("&Cancel Evaluation", self.cancel_evaluation, "Ctrl+.")

    def _build_menus(self) -> None:
        bar = self.menuBar()
        file_menu = bar.addMenu("&File")
        file_menu.addAction(self.act_new)
        file_menu.addAction(self.act_open)
        self.examples_menu = file_menu.addMenu("Open &Example")
        self.examples_menu.aboutToShow.connect(self._fill_examples_menu)
        self._fill_examples_menu()
        file_menu.addSeparator()
        file_menu.addAction(self.act_save)
        file_menu.addAction(self.act_save_as)
        file_menu.addAction(self.act_export)
        file_menu.addSeparator()
        file_menu.addAction(self.act_quit)

        edit_menu = bar.addMenu("&Edit")
        edit_menu.addAction(self.act_undo)
        edit_menu.addAction(self.act_redo)
        edit_menu.addSeparator()
        edit_menu.addAction(self.act_delete)

        view_menu = bar.addMenu("&View")
        tiling = view_menu.addMenu("Tiling")
        group = QtGui.QActionGroup(self)
        self.act_tile1 = QtGui.QAction("1×1×1", self, checkable=True, checked=True)
        self.act_tile3 = QtGui.QAction("3×3×3", self, checkable=True)
        for a in (self.act_tile1, self.act_tile3):
            group.addAction(a)
            tiling.addAction(a)
        self.act_tile3.toggled.connect(self.act_tiling.setChecked)
        self.act_tiling.toggled.connect(self.act_tile3.setChecked)
        self.act_tiling.toggled.connect(lambda on: self.act_tile1.setChecked(not on))
        view_menu.addAction(self.act_tiling)
        view_menu.addAction(self.act_skeleton)
        view_menu.addAction(self.act_solid)
        view_menu.addAction(self.act_sphere)
        view_menu.addSeparator()
        view_menu.addAction(self.act_fit)
        view_menu.addAction(self.act_arrange)
        view_menu.addAction(self.act_reset_camera)
        view_menu.addSeparator()
        for dock in (self.editor_dock, self.inspector_dock, self.growth_dock, self.log_dock):
            view_menu.addAction(dock.toggleViewAction())

        eval_menu = bar.addMenu("E&valuate")
        eval_menu.addAction(self.act_evaluate)
        eval_menu.addAction(self.act_auto)
        eval_menu.addAction(self.act_cancel)

    def _fill_examples_menu(self) -> None:
        self.examples_menu.clear()
        files = self.example_files()
        for path in files:
            action = self.examples_menu.addAction(path.stem.replace("_", " "))
            action.triggered.connect(lambda _c=False, p=path: self.open_example(p))
        if not files:
            none = self.examples_menu.addAction("(no examples found)")
            none.setEnabled(False)

    @staticmethod
    def example_files() -> list[Path]:
        return sorted(EXAMPLES_DIR.glob("*.json")) if EXAMPLES_DIR.is_dir() else []

    # -- log / status -----------------------------------------------------------------------
    @QtCore.Slot(str, str)
    def log(self, level: str, text: str) -> None:
        self.log_lines.append((level, text))
        stamp = time.strftime("%H:%M:%S")
        colour = {"error": "#e05050", "warning": "#e0a030"}.get(level)
        body = html.escape(text)
        if colour:
            body = f"<span style='color:{colour}'>{body}</span>"
        self.log_view.appendHtml(f"<span style='color:#888'>{stamp}</span> {body}")
        self.statusBar().showMessage(text, 8000 if level != "error" else 15000)

    def show_error(self, title: str, text: str) -> None:
        self.log("error", text)
        self.prompter.error(title, text)

    # -- title / modified state ----------------------------------------------------------
    @property
    def is_modified(self) -> bool:
        return self._dirty_without_undo or not self.undo.is_clean

    def _update_title(self) -> None:
        star = "*" if self.is_modified else ""
        self.setWindowTitle(f"{self.display_name}{star} — Mesoforge")

    def _on_undo_changed(self) -> None:
        self.act_undo.setEnabled(self.undo.can_undo)
        self.act_redo.setEnabled(self.undo.can_redo)
        self.act_undo.setText(f"&Undo {self.undo.undo_text()}" if self.undo.can_undo else "&Undo")
        self.act_redo.setText(f"&Redo {self.undo.redo_text()}" if self.undo.can_redo else "&Redo")
        self._update_title()

    def undo_edit(self) -> None:
        self._guarded(self.undo.undo)

    def redo_edit(self) -> None:
        self._guarded(self.undo.redo)

    def _guarded(self, fn) -> None:
        try:
            fn()
        except Exception as exc:  # an engine refusal must never take the window down
            self.log("error", f"{type(exc).__name__}: {exc}")

    # -- document events -> evaluation ---------------------------------------------------
    def _on_doc_event(self, event: str, payload) -> None:
        if event in ("node_moved", "label_changed"):
            return  # layout only: results cannot change
        if event == "node_removed" and payload == self.shown_stiffness_id:
            self.update_viewport()  # its material sphere goes now, not after the next evaluation
        if self.act_auto.isChecked():
            self._debounce.start()

    def _on_auto_toggled(self, on: bool) -> None:
        if on:
            self._debounce.start()

    def evaluate_now(self) -> None:
        """Evaluate the current document on the worker thread (never here)."""
        self._debounce.stop()
        if self._shutting_down:
            return
        try:
            snapshot = self.doc.snapshot()
        except Exception as exc:
            self.log("error", f"cannot evaluate: {exc}")
            return
        self._eval_total = len(snapshot.nodes)
        self.worker.request(snapshot, tag=self._generation)

    def cancel_evaluation(self) -> None:
        self._debounce.stop()
        if self.worker.is_busy:
            self.log("info", "cancelling evaluation…")
        self.worker.cancel()

    @property
    def evaluation_idle(self) -> bool:
        """No evaluation running, queued or waiting for the debounce timer."""
        return not self.worker.is_busy and not self._debounce.isActive()

    def _on_eval_started(self, _number: int) -> None:
        self._eval_done = []
        self.cancel_button.setEnabled(True)
        self.progress.setValue(0)
        self.progress.setFormat("evaluating…")

    def _on_eval_progress(self, node_id: str, fraction: float) -> None:
        total = max(self._eval_total, 1)
        done = len(self._eval_done)
        self.progress.setValue(int(1000 * min(1.0, (done + fraction) / total)))
        self.progress.setFormat(f"{node_id}: {int(100 * fraction)}%   ({done}/{total} nodes)")

    def _on_eval_node_done(self, result: NodeResult) -> None:
        self._eval_done.append(result)
        total = max(self._eval_total, 1)
        self.progress.setValue(int(1000 * min(1.0, len(self._eval_done) / total)))
        self.progress.setFormat(f"{result.node_id}: {result.status}   ({len(self._eval_done)}/{total} nodes)")

    def _on_eval_finished(self, report: EvalReport) -> None:
        self.cancel_button.setEnabled(self.worker.is_busy)
        if getattr(report, "superseded", False):
            return  # a newer snapshot is already being evaluated
        if getattr(report, "tag", self._generation) != self._generation:
            return  # belongs to a document that has been replaced since
        internal = getattr(report, "internal_error", "")
        if internal:
            self.log("error", f"evaluation failed: {internal}")
        self.last_report = report
        self.eval_count += 1
        self.progress.setValue(0 if report.cancelled else 1000)
        self.progress.setFormat("cancelled" if report.cancelled else f"done in {report.seconds:.2f} s")
        self._log_report(report)
        if not report.cancelled:
            self.editor.set_results(report.results)
            self.inspector.set_results(report.results, report.outputs)
            self.update_viewport()
        self.evaluation_finished.emit(report)

    def _log_report(self, report: EvalReport) -> None:
        by_status: dict[str, list[str]] = {}
        for r in report.results.values():
            item = f"{r.node_id} ({r.seconds:.2f} s)" if r.status == "evaluated" else r.node_id
            by_status.setdefault(r.status, []).append(item)
        parts = [f"{status}: {', '.join(items)}" for status, items in by_status.items()]
        head = "evaluation cancelled" if report.cancelled else f"evaluated in {report.seconds:.2f} s"
        self.log("info", f"{head} — " + "; ".join(parts) if parts else head)
        for nid, err in report.errors.items():
            self.log("error", err)
        for warning in report.warnings.values():
            self.log("warning", warning)

    # -- viewport -----------------------------------------------------------------------------
    def _on_selection_changed(self, node_id) -> None:
        self.inspector.set_node(node_id)
        self.tileset_editor.set_selected(node_id)
        self.update_viewport()

    def update_viewport(self) -> None:
        outputs = self.last_report.outputs if self.last_report is not None else {}
        selected = self.editor.selected_ids()
        sel = selected[0] if selected else None
        solid_id, skel_id = pick_display_nodes(self.doc, outputs, sel)
        solid = solid_of(outputs[solid_id]) if solid_id else None
        skeleton = skeleton_of(outputs[skel_id]) if skel_id else None
        caption = []
        if solid_id:
            caption.append(f"solid: {solid_id} ({len(solid.vertices)} vertices, "
                           f"volume fraction {solid.volume_fraction:.3f})")
        if skel_id:
            caption.append(f"skeleton: {skel_id}")
        stiffness_id = pick_stiffness_node(self.doc, outputs, sel)
        stiffness = stiffness_of(outputs[stiffness_id]) if stiffness_id else None
        sphere_caption = ""
        if stiffness is not None:
            sphere_caption = (f"material sphere: {stiffness_id} ({stiffness.symmetry}, "
                              f"E_avg {stiffness.constants.get('E_avg', float('nan')):.4g})")
        self.shown_solid_id, self.shown_skeleton_id = solid_id, skel_id
        self.shown_stiffness_id = stiffness_id
        self.growth_panel.set_context(self.doc, outputs, sel)
        self.phasor_panel.set_context(self.doc, outputs, sel)
        self.rd_panel.set_context(self.doc, outputs, sel)
        self.viewport.show_result(solid, skeleton, "\n".join(caption),
                                  skeleton_emphasis=bool(sel and sel == skel_id), stiffness=stiffness,
                                  sphere_caption=sphere_caption)

    def current_solid(self) -> Solid | None:
        return self.viewport.solid

    # -- files ---------------------------------------------------------------------------------
    def _replace_document(self, new_doc: GraphDocument, path: Path | None, name: str) -> None:
        self.worker.cancel()
        self._generation += 1
        self.last_report = None
        self.doc.replace_with(new_doc)
        # stateful nodes (a repainted Grow) resume from the results stored in the file;
        # this also drops the replaced document's, which its node ids must not inherit
        state_warnings = self.worker.evaluator.import_state(self.doc.node_state)
        for warning in [*new_doc.load_warnings, *state_warnings]:
            self.log("warning", warning)
        self.undo.clear()
        self.project_path = path
        self.display_name = name
        self._dirty_without_undo = False
        self.editor.set_results({})
        self.inspector.set_results({}, {})
        self.update_viewport()
        self._update_title()
        QtCore.QTimer.singleShot(0, self.editor.fit_view)

    def maybe_save(self) -> bool:
        """Ask about unsaved changes; False if the user cancelled (or saving failed)."""
        if not self.is_modified:
            return True
        answer = self.prompter.ask_unsaved(self.display_name)
        if answer == "save":
            return self.save()
        return answer == "discard"

    def _tileset_edits_may_go(self) -> bool:
        """Unsaved edits in the Tile Sets dock are only dropped when the user says so."""
        return not self.tileset_editor.unsaved or self.tileset_editor.confirm(
            "Unsaved tile set", "The Tile Sets dock has unsaved edits. Quit and discard them?")

    def new_project(self) -> bool:
        if not self.maybe_save():
            return False
        self._replace_document(GraphDocument(), None, "untitled")
        self.autosave.clear()
        self.log("info", "new project")
        return True

    def open_project(self, path: str | Path | None = None, *, ask: bool = True) -> bool:
        """Open a project file; on a bad file show why and keep the open project untouched."""
        if ask and not self.maybe_save():
            return False
        if path is None:
            start = str(self.project_path.parent) if self.project_path else str(Path.cwd())
            path = self.prompter.open_path("Open project", start)
            if not path:
                return False
        path = Path(path)
        try:
            new_doc = load_project(path)
        except ProjectFileError as exc:
            self.show_error("Cannot open project", str(exc))
            return False
        self._replace_document(new_doc, path, path.name)
        self.autosave.clear()
        self.log("info", f"opened {path}")
        return True

    def open_example(self, path: str | Path, *, ask: bool = True) -> bool:
        """Open an example as an untitled copy (saving never overwrites the shipped file)."""
        if ask and not self.maybe_save():
            return False
        path = Path(path)
        try:
            new_doc = load_project(path)
        except ProjectFileError as exc:
            self.show_error("Cannot open example", str(exc))
            return False
        self._replace_document(new_doc, None, f"{path.stem} (example)")
        self.log("info", f"opened example {path.name}")
        return True

    def save(self) -> bool:
        if self.project_path is None:
            return self.save_as()
        return self._write(self.project_path)

    def save_as(self, path: str | Path | None = None) -> bool:
        if path is None:
            start = str(self.project_path) if self.project_path else str(Path.cwd() / "untitled.json")
            path = self.prompter.save_path("Save project as", start)
            if not path:
                return False
        return self._write(Path(path))

    def _take_node_state(self) -> None:
        """Put the evaluator's stateful-node results into the document before writing it."""
        self.doc.node_state = self.worker.evaluator.export_state()

    def _write(self, path: Path) -> bool:
        try:
            self._take_node_state()
            save_project(self.doc, path)
        except (OSError, ValueError) as exc:
            self.show_error("Cannot save project", f"cannot save {str(path)!r}: {exc}")
            return False
        self.project_path = path
        self.display_name = path.name
        self._dirty_without_undo = False
        self.undo.set_clean()
        self.autosave.clear()
        self.log("info", f"saved {path}")
        self._update_title()
        return True

    def export_mesh(self, path: str | Path | None = None) -> bool:
        """Write the shown solid (with the current tiling) as STL / OBJ / PLY / 3MF."""
        solid = self.current_solid()
        if solid is None:
            self.show_error("Export mesh", "there is no solid to export yet: evaluate a graph with an Object node")
            return False
        if path is None:
            stem = self.project_path.stem if self.project_path else "mesoforge"
            path = self.prompter.save_path("Export mesh", str(Path.cwd() / f"{stem}.stl"),
                                           ";;".join(MESH_FILTERS))
            if not path:
                return False
        path = Path(path)
        if path.suffix.lower() not in MESH_FILTERS.values():
            self.show_error("Export mesh", f"cannot export {str(path)!r}: expected a file ending in "
                                           f"{', '.join(MESH_FILTERS.values())}")
            return False
        try:
            from engine.geometry.mesh_io import export_mesh
            vertices, faces = self._export_arrays(solid, self.viewport.tiles)
            export_mesh(vertices, faces, path)
        except Exception as exc:  # report any I/O or kernel failure; never crash the window
            self.show_error("Export mesh", f"cannot export {str(path)!r}: {exc}")
            return False
        self.log("info", f"exported {len(faces)} triangles ({self.viewport.tiles}³ cells) to {path}")
        return True

    @staticmethod
    def _export_arrays(solid: Solid, tiles: int) -> tuple[np.ndarray, np.ndarray]:
        if tiles == 1 or not solid.periodic:
            return np.asarray(solid.vertices), np.asarray(solid.faces)
        from engine.geometry.marching import periodic_mesh
        from engine.memory import check_budget, tiled_mesh_bytes
        check_budget(tiled_mesh_bytes(solid.sdf.shape, (tiles,) * 3, len(solid.faces)),
                     what=f"exporting {tiles}x{tiles}x{tiles} cells", lower="the tiles or the resolution")
        # One marching-cubes pass over the tiled field gives a watertight block
        # (copies of the cell mesh would leave duplicate seams).
        return periodic_mesh(solid.sdf, tiles=(tiles, tiles, tiles), cell_size=solid.cell_size, cell=solid.cell)

    # -- autosave / recovery --------------------------------------------------------------
    def autosave_now(self) -> bool:
        if not self.is_modified:
            return False
        try:
            self._take_node_state()
            self.autosave.save(self.doc, self.project_path)
        except (OSError, ValueError) as exc:
            self.log("warning", f"autosave failed: {exc}")
            return False
        return True

    def offer_recovery(self) -> bool:
        """If a crashed session left autosaves, offer to recover the newest; True if recovered."""
        items = self.autosave.find_recoverable()
        if not items:
            return False
        recovered = False
        if self.prompter.ask_recover(items):
            item = items[0]
            try:
                new_doc = self.autosave.load(item)
            except ProjectFileError as exc:
                self.show_error("Cannot recover", str(exc))
            else:
                path = Path(item.original_path) if item.original_path else None
                self._replace_document(new_doc, path, path.name if path else "recovered")
                self._dirty_without_undo = True
                self._update_title()
                self.log("info", f"recovered autosave of {item.display_name}")
                recovered = True
        for item in items:
            self.autosave.discard(item)
        if recovered:
            self.autosave_now()
        return recovered

    def showEvent(self, event: QtGui.QShowEvent) -> None:
        super().showEvent(event)
        if not getattr(self, "_docks_sized", False):
            # Dock sizes only stick once the window has its real geometry.
            self._docks_sized = True
            w = self.width()
            self.resizeDocks([self.editor_dock, self.inspector_dock], [int(w * 0.38), int(w * 0.2)],
                             QtCore.Qt.Orientation.Horizontal)
            self.resizeDocks([self.log_dock], [int(self.height() * 0.16)], QtCore.Qt.Orientation.Vertical)
            QtCore.QTimer.singleShot(0, self.editor.fit_view)

    # -- closing ---------------------------------------------------------------------------
    def closeEvent(self, event: QtGui.QCloseEvent) -> None:
        if not self._shutting_down and not (self.maybe_save() and self._tileset_edits_may_go()):
            event.ignore()
            return
        self.shutdown()
        event.accept()

    def shutdown(self) -> None:
        """Stop timers and the worker, release the render window, drop the autosave."""
        if self._shutting_down:
            return
        self._shutting_down = True
        self._debounce.stop()
        self._autosave_timer.stop()
        self.growth_panel.detach()
        self.phasor_panel.shutdown()
        self.rd_panel.shutdown()
        self.surface_panel.shutdown()
        self.worker.shutdown()
        self.editor.detach()
        self.inspector.detach()
        self.tileset_editor.detach()
        self.study_panel.shutdown()
        self.doc.unsubscribe(self._on_doc_event)
        self.autosave.clear()
        self.viewport.close_plotter()
