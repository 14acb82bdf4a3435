"""The Mesoforge main window: node editor, viewport, inspector, log.

The window owns one GraphDocument (kept for its whole life; opening a file
replaces its content), its UndoStack and one EvalWorker (so the evaluator's
cache survives edits).  Document changes schedule a debounced evaluation on
the worker thread; reports come back as signals and are drawn here.  Every
question to the user goes through a `Prompter`, which tests replace.

The window's parts live in small mixins: its widgets and docks
(`ui.window_docks`), actions and menus (`ui.window_menus`), evaluation
control (`ui.window_evaluation`) and files, export and autosave
(`ui.window_files`), its dock layout kept between sessions
(`ui.window_layout`); this module keeps the state, the log, the title and
what the viewport shows.
"""

from __future__ import annotations

import html
import time
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from engine.autosave import AutosaveManager
from engine.graph import EvalReport, GraphDocument, NodeResult, UndoStack
from engine.geometry.values import Solid

from .dialogs import Prompter
from .eval_worker import EvalWorker
from .view_content import empty_hint
from .viewport import pick_display_nodes, pick_stiffness_node, skeleton_of, solid_of, stiffness_of
from .window_docks import WindowDocks
from .window_evaluation import WindowEvaluation
from .window_files import WindowFiles
from .window_layout import WindowLayout, open_settings
from .window_menus import EXAMPLES_DIR, WindowMenus

__all__ = ["MainWindow", "EXAMPLES_DIR", "DEFAULT_EXAMPLE"]

DEFAULT_EXAMPLE = "octet.json"
EVAL_DEBOUNCE_MS = 150
AUTOSAVE_INTERVAL_MS = 3 * 60 * 1000


class MainWindow(WindowDocks, WindowLayout, WindowMenus, WindowEvaluation, WindowFiles, QtWidgets.QMainWindow):
    """Node editor (left), 3D viewport (centre), inspector (right), log (bottom)."""

    evaluation_finished = QtCore.Signal(object)

    def __init__(self, *, autosave_dir: str | Path | None = None, prompter: Prompter | None = None,
                 autosave_interval_ms: int = AUTOSAVE_INTERVAL_MS,
                 settings: QtCore.QSettings | str | Path | None = None, parent=None):
        """`settings`: where the window's layout is kept between sessions (a QSettings, or the
        path of an ini file); None keeps nothing and starts with the default layout."""
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
        self.layout_settings = open_settings(settings)

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
        self.doc.subscribe(self._on_doc_event_overlays)
        self.viewport.overlay_owner = self._overlay_owner
        self.undo.subscribe(self._on_undo_changed)
        self.worker.started.connect(self._on_eval_started)
        self.worker.progress.connect(self._on_eval_progress)
        self.worker.node_done.connect(self._on_eval_node_done)
        self.worker.finished.connect(self._on_eval_finished)
        self.editor.selection_changed.connect(self._on_selection_changed)
        self.editor.message.connect(self.log)
        self.inspector.message.connect(self.log)

        self.resize(self.default_window_size())
        self.restore_layout()
        self._on_undo_changed()

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
        self.viewport.drop_overlays(self._owns_overlay)
        errors = self.last_report.errors if self.last_report is not None else None
        self.viewport.show_result(solid, skeleton, "\n".join(caption),
                                  skeleton_emphasis=bool(sel and sel == skel_id), stiffness=stiffness,
                                  sphere_caption=sphere_caption,
                                  empty_hint=empty_hint(self.doc, errors, bool(outputs)))

    def _overlay_owner(self):
        """Owner of a new viewport overlay (the Phasor dock's toolpaths): this document and
        the dock's node."""
        return (self._generation, self.phasor_panel.noise_id or self.phasor_panel.fields_id)

    def _owns_overlay(self, owner) -> bool:
        """An overlay stays while its document is open and its node is in it."""
        if not isinstance(owner, tuple) or len(owner) != 2:
            return owner is None
        generation, node_id = owner
        return generation == self._generation and (node_id is None or node_id in self.doc.nodes)

    def _on_doc_event_overlays(self, event: str, payload) -> None:
        if event in ("node_removed", "reset"):
            self.viewport.drop_overlays(self._owns_overlay)

    def current_solid(self) -> Solid | None:
        return self.viewport.solid

    def showEvent(self, event: QtGui.QShowEvent) -> None:
        super().showEvent(event)
        if not getattr(self, "_docks_sized", False):
            # Dock sizes only stick once the window has its real geometry; a restored
            # layout brings its own.
            self._docks_sized = True
            if not self.layout_restored:
                self.size_default_docks()
            QtCore.QTimer.singleShot(0, self.editor.fit_view)

    # -- closing ---------------------------------------------------------------------------
    def closeEvent(self, event: QtGui.QCloseEvent) -> None:
        if not self._shutting_down and not (self.maybe_save() and self._tileset_edits_may_go()):
            event.ignore()
            return
        if not self._shutting_down:
            self.save_layout()
        self.shutdown()
        event.accept()

    def shutdown(self) -> None:
        """Stop timers and the worker, release the render window, drop the autosave."""
        if self._shutting_down:
            return
        self._shutting_down = True
        self._debounce.stop()
        self._autosave_timer.stop()
        self.undo_keys.stop()
        self.growth_panel.detach()
        self.phasor_panel.shutdown()
        self.rd_panel.shutdown()
        self.surface_panel.shutdown()
        self.implicit_panel.shutdown()
        self.subgraph_panel.detach()
        self.worker.shutdown()
        self.editor.detach()
        self.inspector.detach()
        self.tileset_editor.detach()
        self.study_panel.shutdown()
        self.doc.unsubscribe(self._on_doc_event)
        self.autosave.clear()
        self.stop_export()
        self.viewport.close_plotter()
