"""The questions the main window asks the user, behind one small interface.

Tests hand the window an object with the same methods that answers at once.
"""

from __future__ import annotations

import time
from pathlib import Path

from PySide6 import QtWidgets

from engine.autosave import RecoveryItem

PROJECT_FILTER = "Mesoforge project (*.json);;All files (*)"
MESH_FILTERS = {
    "STL mesh (*.stl)": ".stl", "Wavefront OBJ (*.obj)": ".obj", "PLY mesh (*.ply)": ".ply",
    "3MF (*.3mf)": ".3mf",
}


class Prompter:
    """Dialogs the window needs.  Tests pass a subclass that answers without showing anything."""

    def __init__(self, parent: QtWidgets.QWidget | None = None):
        self.parent = parent

    def ask_unsaved(self, name: str) -> str:
        """'save', 'discard' or 'cancel'."""
        box = QtWidgets.QMessageBox(self.parent)
        box.setIcon(QtWidgets.QMessageBox.Icon.Warning)
        box.setWindowTitle("Unsaved changes")
        box.setText(f"{name} has unsaved changes.")
        box.setInformativeText("Save them before continuing?")
        buttons = QtWidgets.QMessageBox.StandardButton
        box.setStandardButtons(buttons.Save | buttons.Discard | buttons.Cancel)
        box.setDefaultButton(buttons.Save)
        answer = box.exec()
        return {buttons.Save: "save", buttons.Discard: "discard"}.get(buttons(answer), "cancel")

    def error(self, title: str, text: str) -> None:
        QtWidgets.QMessageBox.critical(self.parent, title, text)

    def open_path(self, caption: str, directory: str = "", filters: str = PROJECT_FILTER) -> str | None:
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self.parent, caption, directory, filters)
        return path or None

    def save_path(self, caption: str, directory: str = "", filters: str = PROJECT_FILTER) -> str | None:
        path, selected = QtWidgets.QFileDialog.getSaveFileName(self.parent, caption, directory, filters)
        if path and not Path(path).suffix:
            path += MESH_FILTERS.get(selected, ".json")
        return path or None

    def ask_recover(self, items: list[RecoveryItem]) -> bool:
        """True to recover the newest autosave, False to discard them."""
        newest = items[0]
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(newest.saved_at))
        box = QtWidgets.QMessageBox(self.parent)
        box.setIcon(QtWidgets.QMessageBox.Icon.Question)
        box.setWindowTitle("Recover unsaved work?")
        box.setText(f"Mesoforge did not close cleanly. An autosave of {newest.display_name} from {when} "
                    "was found.")
        more = f" ({len(items) - 1} older autosave(s) will be discarded.)" if len(items) > 1 else ""
        box.setInformativeText("Recover it?" + more)
        recover = box.addButton("Recover", QtWidgets.QMessageBox.ButtonRole.AcceptRole)
        box.addButton("Discard", QtWidgets.QMessageBox.ButtonRole.DestructiveRole)
        box.setDefaultButton(recover)
        box.exec()
        return box.clickedButton() is recover
