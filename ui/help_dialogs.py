"""Help › Shortcuts and Help › About, and the tips on the window's actions.

The shortcuts table is read from the window's QActions each time it is shown
(never a hard-coded list), so an action another part of the window adds is
listed with the key it really has. `apply_action_tips` gives every action a
tooltip (what it does, and its shortcut) and the same text as a status tip.
"""

from __future__ import annotations

import platform
from importlib import metadata

from PySide6 import QtCore, QtGui, QtWidgets

__all__ = ["ACTION_TIPS", "PAPERS", "LIBRARIES", "apply_action_tips", "build_help_menu", "shortcut_rows",
           "about_html", "ShortcutsDialog"]

# What each of the window's actions does, by its attribute on the window; an action not
# listed gets its menu text.
ACTION_TIPS = {
    "act_new": "Start an empty project",
    "act_open": "Open a project file (.json)",
    "act_gallery": "Browse the examples with pictures, families and summaries; each opens as an untitled copy",
    "act_save": "Save the project (a shipped example asks for a new path)",
    "act_save_as": "Save the project under a new path",
    "act_export": "Export the shown solid as a mesh (.stl .obj .ply .3mf), tiled as shown",
    "act_quit": "Close the window (asks about unsaved changes)",
    "act_undo": "Undo the last edit, from any widget of the window",
    "act_redo": "Redo the last undone edit",
    "act_delete": "Delete the selected nodes (undoable)",
    "act_copy": "Copy the selected nodes and the edges between them",
    "act_paste": "Paste copied nodes next to the originals (undoable)",
    "act_duplicate": "Duplicate the selected nodes (undoable)",
    "act_add_frame": "Put a titled frame (comment) around the selected nodes",
    "act_remove_frame": "Remove the frame under the cursor; its nodes stay",
    "act_make_subgraph": "Group the selected nodes into a reusable subgraph with exposed parameters",
    "act_ungroup": "Put a subgraph's nodes back into the graph",
    "act_save_subgraph": "Save the selected subgraph to the subgraph library",
    "act_collapse_subgraph": "Collapse a subgraph to one box, or expand it",
    "act_tiling": "Show the cell tiled 3×3×3 in the viewport",
    "act_skeleton": "Show the skeleton (lines and surfaces) of the shown node",
    "act_solid": "Show the thickened solid",
    "act_sphere": "Show the material sphere (directional Young's modulus) of the nearest stiffness",
    "act_fit": "Fit the whole node graph into the editor",
    "act_arrange": "Lay the nodes out in columns by depth (undoable)",
    "act_reset_camera": "Home the viewport camera on the shown content",
    "act_evaluate": "Evaluate the graph now",
    "act_auto": "Evaluate automatically after every edit",
    "act_cancel": "Cancel the running evaluation",
    "act_reset_layout": "Put every dock back in its default place",
    "act_shortcuts": "List every action's keyboard shortcut",
    "act_about": "Version, methods and libraries",
}

PAPERS = (
    ("Procedural unit-cell graphs", "Makatura, Wang, Chen, Deng, Wojtan, Bickel & Matusik 2023",
     "Procedural Metamaterials: A Unified Procedural Graph for Metamaterial Design"),
    ("Virtual growth", "Liu, Sun & Daraio 2022",
     "Growth rules for irregular architected materials with programmable properties"),
    ("Phasor infill", "Tricard et al. 2020",
     "Freely orientable microstructures for designing deformable 3D prints"),
    ("Reaction-diffusion lattices", "Garnier, Schmidt & Rohmer 2022",
     "Growth of oriented orthotropic structures with reaction/diffusion"),
    ("Implicit multiscale media", "2024/25",
     "Procedural Multiscale Geometry Modeling using Implicit Functions"),
)

LIBRARIES = ("numpy", "scipy", "scikit-image", "trimesh", "libigl", "PySide6", "NodeGraphQt", "vtk",
             "pyvista", "moderngl", "dask")
# distributions a library may be installed as
_DISTRIBUTIONS = {"PySide6": ("PySide6", "PySide6-Essentials")}


def plain_text(action: QtGui.QAction) -> str:
    """An action's menu text without mnemonics or the trailing ellipsis."""
    return action.text().replace("&&", "\0").replace("&", "").replace("\0", "&").rstrip("…").rstrip(".")


def _keys(action: QtGui.QAction) -> str:
    return ", ".join(k.toString(QtGui.QKeySequence.SequenceFormat.NativeText) for k in action.shortcuts()
                     if not k.isEmpty())


def apply_action_tips(window: QtWidgets.QWidget) -> None:
    """Tooltip and status tip on every action of `window` that has none yet."""
    by_action = {}
    for name, tip in ACTION_TIPS.items():
        action = getattr(window, name, None)
        if isinstance(action, QtGui.QAction):
            by_action[id(action)] = tip
    for action in _window_actions(window):
        if action.isSeparator() or action.menu() is not None or action.statusTip():
            continue
        tip = by_action.get(id(action), plain_text(action))
        keys = _keys(action)
        action.setStatusTip(tip)
        action.setToolTip(f"{tip} ({keys})" if keys else tip)


def _window_actions(window: QtWidgets.QWidget) -> list[QtGui.QAction]:
    seen, out = set(), []
    for action in list(window.actions()) + window.findChildren(QtGui.QAction):
        if id(action) not in seen and action.text():
            seen.add(id(action))
            out.append(action)
    return out


def shortcut_rows(window: QtWidgets.QWidget) -> list[tuple[str, str]]:
    """(action, shortcuts) of every action of `window` with a shortcut, sorted by action."""
    rows = {}
    for action in _window_actions(window):
        keys = _keys(action)
        if keys:
            rows.setdefault((plain_text(action), keys), None)
    return sorted(rows, key=lambda r: (r[0].lower(), r[1]))


class ShortcutsDialog(QtWidgets.QDialog):
    """A read-only table of the window's shortcuts (non-modal)."""

    def __init__(self, window: QtWidgets.QWidget):
        super().__init__(window)
        self.setWindowTitle("Keyboard Shortcuts")
        self.table = QtWidgets.QTableWidget(0, 2, self)
        self.table.setHorizontalHeaderLabels(["Action", "Shortcut"])
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.horizontalHeader().setSectionResizeMode(0, QtWidgets.QHeaderView.ResizeMode.Stretch)
        self.table.horizontalHeader().setSectionResizeMode(1, QtWidgets.QHeaderView.ResizeMode.ResizeToContents)
        hint = QtWidgets.QLabel("In the node editor: Tab searches node types to add; "
                                "drag from a port to connect.")
        hint.setWordWrap(True)
        close = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.StandardButton.Close)
        close.rejected.connect(self.close)
        lay = QtWidgets.QVBoxLayout(self)
        lay.addWidget(self.table)
        lay.addWidget(hint)
        lay.addWidget(close)
        self.resize(460, 520)
        self.refresh(window)

    def refresh(self, window: QtWidgets.QWidget) -> None:
        rows = shortcut_rows(window)
        self.table.setRowCount(len(rows))
        for r, (name, keys) in enumerate(rows):
            self.table.setItem(r, 0, QtWidgets.QTableWidgetItem(name))
            self.table.setItem(r, 1, QtWidgets.QTableWidgetItem(keys))

    def rows(self) -> list[tuple[str, str]]:
        return [(self.table.item(r, 0).text(), self.table.item(r, 1).text())
                for r in range(self.table.rowCount())]


def _version(name: str) -> str | None:
    for dist in _DISTRIBUTIONS.get(name, (name,)):
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            continue
    return None


def about_html() -> str:
    """The About text: version, the five methods and their papers, key libraries with versions."""
    version = _version("mesoforge") or "development build"
    papers = "".join(f"<li><b>{method}</b>: {who}, <i>{title}</i></li>" for method, who, title in PAPERS)
    libs = []
    for name in LIBRARIES:
        v = _version(name)
        if v is not None:
            libs.append(f"{name} {v}")
    libs.append(f"Qt {QtCore.qVersion()}")
    libs.append(f"Python {platform.python_version()}")
    return (f"<h3>Mesoforge {version}</h3>"
            "<p>A workbench for architected materials: procedural node graphs evaluated by one "
            "incremental engine.</p>"
            f"<p>Methods:</p><ul>{papers}</ul>"
            f"<p>Built on: {', '.join(libs)}.</p>")


def build_help_menu(window: QtWidgets.QMainWindow, bar: QtWidgets.QMenuBar) -> QtWidgets.QMenu:
    """Help › Keyboard Shortcuts… / About Mesoforge…, then tips on every action."""
    menu = bar.addMenu("&Help")
    window.act_shortcuts = QtGui.QAction("&Keyboard Shortcuts…", window)
    window.act_shortcuts.setShortcut(QtGui.QKeySequence("Ctrl+/"))
    window.act_shortcuts.triggered.connect(lambda _c=False: show_shortcuts(window))
    window.addAction(window.act_shortcuts)
    window.act_about = QtGui.QAction("&About Mesoforge…", window)
    window.act_about.setMenuRole(QtGui.QAction.MenuRole.AboutRole)
    window.act_about.triggered.connect(lambda _c=False: show_about(window))
    menu.addAction(window.act_shortcuts)
    menu.addAction(window.act_about)
    apply_action_tips(window)
    return menu


def show_shortcuts(window) -> ShortcutsDialog:
    """Show (or raise) the window's shortcuts dialog, read afresh from its actions."""
    dialog = getattr(window, "shortcuts_dialog", None)
    if dialog is None:
        dialog = window.shortcuts_dialog = ShortcutsDialog(window)
    else:
        dialog.refresh(window)
    dialog.show()
    dialog.raise_()
    return dialog


def show_about(window) -> QtWidgets.QMessageBox:
    """The About box, non-modal (tests and the window keep running)."""
    box = getattr(window, "about_box", None)
    if box is None:
        box = window.about_box = QtWidgets.QMessageBox(window)
        box.setWindowTitle("About Mesoforge")
        box.setTextFormat(QtCore.Qt.TextFormat.RichText)
        box.setText(about_html())
        box.setStandardButtons(QtWidgets.QMessageBox.StandardButton.Close)
        box.setModal(False)
    box.show()
    box.raise_()
    return box
