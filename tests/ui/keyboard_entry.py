"""Typing into a number field as a user does (shared by the docks' tests)."""

from __future__ import annotations

from PySide6 import QtCore

Key = QtCore.Qt.Key


def type_into(qtbot, field, text: str) -> None:
    """Select the field's text, type ``text``, press Enter (a ToolNumber or NumberBox)."""
    edit = field.lineEdit()
    edit.selectAll()
    qtbot.keyClick(edit, Key.Key_Backspace)
    if text:
        qtbot.keyClicks(edit, text)
    qtbot.keyClick(edit, Key.Key_Return)
