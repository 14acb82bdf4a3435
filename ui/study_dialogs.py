"""Small pieces of the Growth Study dock: its file dialogs, form helpers and tile-set list."""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtWidgets

from engine.growth import list_tilesets

from .tool_number import ToolNumber

DATABASE_FILTER = "Study database (*.csv *.parquet);;All files (*)"


def shipped_tilesets() -> list:
    """Tile set names from resources/tilesets, one per file (not its file-stem alias)."""
    seen, names = set(), []
    for name, path in list_tilesets().items():
        if path not in seen:
            seen.add(path)
            names.append(name)
    return names


def hint_groups_from_text(text: str) -> list:
    """One hint text per non-empty line; a line ``uniform`` is the uniform group (``""``)."""
    out = []
    for line in text.splitlines():
        line = line.strip()
        if line:
            out.append("" if line.lower() == "uniform" else line)
    return out


def open_path(parent) -> str | None:
    """A study database to open, or None."""
    path, _ = QtWidgets.QFileDialog.getOpenFileName(parent, "Open study database", "",
                                                    DATABASE_FILTER)
    return path or None


def save_path(parent) -> str | None:
    """Where to write a study database (``.csv`` added when there is no suffix), or None."""
    path, _ = QtWidgets.QFileDialog.getSaveFileName(parent, "Study database", "study.csv",
                                                    DATABASE_FILTER)
    if path and not Path(path).suffix:
        path += ".csv"
    return path or None


def confirm_replace(parent, path: Path) -> bool:
    """Whether to replace the existing database ``path`` (Run starts it afresh)."""
    buttons = QtWidgets.QMessageBox.StandardButton
    answer = QtWidgets.QMessageBox.question(
        parent, "Replace the database?",
        f"{path.name} already exists. Run starts it afresh and its rows are lost; "
        f"Resume continues it instead.\n\nReplace it?",
        buttons.Yes | buttons.No, buttons.No)
    return answer == buttons.Yes


def _number(param, **options) -> ToolNumber:
    """A study setting's field over its schema (`engine.batch.study_params`): the rule
    ``mesoforge study`` applies to the same flag, a refusal shown under the field."""
    return ToolNumber(param, **options)


def _row(*widgets) -> QtWidgets.QWidget:
    w = QtWidgets.QWidget()
    lay = QtWidgets.QHBoxLayout(w)
    lay.setContentsMargins(0, 0, 0, 0)
    for x in widgets:
        lay.addWidget(x)
    return w
