"""Undo / redo keys that work from every widget of a window.

A focused line edit or spin box claims Ctrl+Z (and Ctrl+Shift+Z) for its own
text undo, so the window's Undo action never saw them, and Qt's Redo key on
Linux is Ctrl+Shift+Z only.  `UndoKeys` watches the application's key events:
in a text field of its window (or of one of the window's docks, floating or
not) it takes Ctrl+Z as the document's undo and Ctrl+Shift+Z / Ctrl+Y as its
redo.  Fields of other windows (dialogs) keep their own text undo.
"""

from __future__ import annotations

from typing import Callable

from PySide6 import QtCore, QtGui, QtWidgets

UNDO_KEYS = (QtGui.QKeySequence("Ctrl+Z"),)
REDO_KEYS = (QtGui.QKeySequence("Ctrl+Shift+Z"), QtGui.QKeySequence("Ctrl+Y"))
_TEXT_FIELDS = (QtWidgets.QLineEdit, QtWidgets.QAbstractSpinBox)
_Type = QtCore.QEvent.Type


def key_of(event: QtGui.QKeyEvent) -> QtGui.QKeySequence:
    """The key sequence of a key event (keypad flag dropped)."""
    mods = event.modifiers() & ~QtCore.Qt.KeyboardModifier.KeypadModifier
    return QtGui.QKeySequence(QtCore.QKeyCombination(mods, QtCore.Qt.Key(event.key())))


class UndoKeys(QtCore.QObject):
    """An application event filter (a child of `window`, gone with it) that runs
    `undo()` / `redo()` for the undo / redo keys pressed in `window`'s text fields."""

    def __init__(self, window: QtWidgets.QMainWindow, undo: Callable[[], None], redo: Callable[[], None]):
        super().__init__(window)
        self._window = window
        self._undo, self._redo = undo, redo
        QtWidgets.QApplication.instance().installEventFilter(self)

    def stop(self) -> None:
        """Stop filtering (the window is closing: no event of its half-destroyed widgets comes here)."""
        app = QtWidgets.QApplication.instance()
        if app is not None:
            app.removeEventFilter(self)

    def _owned(self, obj) -> bool:
        if not isinstance(obj, _TEXT_FIELDS):
            return False
        top = obj.window()
        if top is self._window:
            return True
        # a floating dock is its own window; its main window is the dock's parent
        return isinstance(top, QtWidgets.QDockWidget) and top.parentWidget() is self._window

    def _slot(self, event) -> Callable[[], None] | None:
        key = key_of(event)
        if any(key == k for k in UNDO_KEYS):
            return self._undo
        if any(key == k for k in REDO_KEYS):
            return self._redo
        return None

    def eventFilter(self, obj, event) -> bool:
        kind = event.type()
        if kind not in (_Type.ShortcutOverride, _Type.KeyPress) or not self._owned(obj):
            return False
        slot = self._slot(event)
        if slot is None:
            return False
        if kind == _Type.ShortcutOverride:
            event.accept()          # the key press comes here (not to the field's text undo, nor a shortcut)
            return True
        slot()
        return True
