"""The main window's actions (with their shortcuts) and its menu bar."""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtGui, QtWidgets

from .example_gallery import show_gallery
from .help_dialogs import build_help_menu
from .subgraph_actions import build_annotation_actions, fill_edit_menu
from .undo_keys import REDO_KEYS, UNDO_KEYS, UndoKeys

EXAMPLES_DIR = Path(__file__).resolve().parents[1] / "resources" / "examples"


class WindowMenus:
    """Mixin of `MainWindow`: its QActions and the File / Edit / View / Evaluate
    menus (``self`` is the QMainWindow; the slots are its methods)."""

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
        # Ctrl+Z, Ctrl+Shift+Z and Ctrl+Y from any widget of the window and its docks (a window
        # shortcut also fires in a floating dock); in text fields, which claim them for their own
        # text undo, through UndoKeys
        self.act_undo.setShortcuts(list(UNDO_KEYS))
        self.act_redo.setShortcuts(list(REDO_KEYS))
        self.undo_keys = UndoKeys(self, self.undo_edit, self.redo_edit)
        # node copy / paste / duplicate (ui.node_clipboard); text fields keep their own Ctrl+C / Ctrl+V
        self.act_copy = self._action("&Copy Nodes", self.editor.clipboard.copy, K.Copy)
        self.act_paste = self._action("&Paste Nodes", self.editor.clipboard.paste, K.Paste)
        self.act_duplicate = self._action("D&uplicate Nodes", self.editor.clipboard.duplicate, "Ctrl+D")
        self.act_delete = self._action("&Delete Node", self.editor.delete_selected, K.Delete)
        build_annotation_actions(self)  # frames and subgraphs (ui.subgraph_actions)
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
        self.act_reset_layout = self._action("Reset &Layout", self.reset_layout)

    def _build_menus(self) -> None:
        bar = self.menuBar()
        file_menu = bar.addMenu("&File")
        file_menu.addAction(self.act_new)
        file_menu.addAction(self.act_open)
        self.examples_menu = file_menu.addMenu("Open &Example")
        self.examples_menu.aboutToShow.connect(self._fill_examples_menu)
        self._fill_examples_menu()
        self.act_gallery = self._action("Example &Gallery…", lambda: show_gallery(self), "Ctrl+Shift+O")
        file_menu.addAction(self.act_gallery)          # thumbnails, families, summaries (ui.example_gallery)
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
        for action in (self.act_copy, self.act_paste, self.act_duplicate):
            edit_menu.addAction(action)
        edit_menu.addAction(self.act_delete)
        fill_edit_menu(self, edit_menu)

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
        docks = view_menu.addMenu("Docks")           # every dock, by title
        for dock in sorted(self.findChildren(QtWidgets.QDockWidget), key=lambda d: d.windowTitle()):
            docks.addAction(dock.toggleViewAction())
        view_menu.addAction(self.act_reset_layout)     # every dock back in its default place

        eval_menu = bar.addMenu("E&valuate")
        eval_menu.addAction(self.act_evaluate)
        eval_menu.addAction(self.act_auto)
        eval_menu.addAction(self.act_cancel)
        build_help_menu(self, bar)      # Help › Shortcuts / About, then tips on every action (ui.help_dialogs)

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
