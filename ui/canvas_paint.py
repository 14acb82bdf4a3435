"""The opening every picture canvas's paintEvent shares."""

from __future__ import annotations

from PySide6 import QtCore, QtGui


def begin_paint(widget, has_picture: bool, placeholder: str) -> QtGui.QPainter | None:
    """A painter on ``widget`` over its window colour; with nothing to show,
    draws ``placeholder`` centred, ends the painter and returns None."""
    p = QtGui.QPainter(widget)
    p.fillRect(widget.rect(), widget.palette().window())
    if has_picture:
        return p
    p.setPen(widget.palette().text().color())
    p.drawText(widget.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, placeholder)
    p.end()
    return None
