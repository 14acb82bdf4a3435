"""What the picture canvases share: the paintEvent opening and the painting toggle."""

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


class PaintingToggle:
    """Painting mode of a canvas with strokes: a cross cursor while on;
    switching off drops the stroke in progress (``abort_stroke``)."""

    _painting = False

    def set_painting(self, on: bool) -> None:
        if not on:
            self.abort_stroke()
        self._painting = bool(on)
        self.setCursor(QtCore.Qt.CursorShape.CrossCursor if on else QtCore.Qt.CursorShape.ArrowCursor)
        self.update()

    @property
    def painting(self) -> bool:
        return self._painting
