"""The picture of the Implicit Media dock: a traced frame, orbited by dragging, zoomed by the wheel.

The widget only draws and turns gestures into a view (azimuth, elevation, zoom); the
dock traces frames for it off the GUI thread.  A drag asks for quick frames (``moving``)
and, on release, a full one.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.nodes.sdf_preview import DEFAULT_ORBIT

DEGREES_PER_PIXEL = 0.4
ZOOM_PER_NOTCH = 1.15
ZOOM_RANGE = (0.2, 20.0)


class TraceView(QtWidgets.QWidget):
    """Shows an RGBA frame (letterboxed, aspect kept) and emits ``view_changed(moving)`` when a
    drag or a wheel notch moves the camera.

    azimuth, elevation : degrees (`engine.nodes.sdf_preview.orbit_direction`); zoom : >= 0.2.
    """

    view_changed = QtCore.Signal(bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(200, 160)
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Expanding, QtWidgets.QSizePolicy.Policy.Expanding)
        self.setToolTip("drag: orbit · wheel: zoom · double-click: reset the view")
        self.azimuth, self.elevation = DEFAULT_ORBIT
        self.zoom = 1.0
        self._image: QtGui.QImage | None = None
        self._pixels = None                      # keeps the QImage's buffer alive
        self._drag: QtCore.QPointF | None = None
        self.note = "select a node with an SDF output"
        self.frames_shown = 0

    # -- content -----------------------------------------------------------------------------
    def show_frame(self, rgba: np.ndarray) -> None:
        """Show an (h, w, 4) uint8 frame (row 0 at the top)."""
        pixels = np.ascontiguousarray(rgba, dtype=np.uint8)
        h, w = pixels.shape[:2]
        self._pixels = pixels
        self._image = QtGui.QImage(pixels.data, w, h, 4 * w, QtGui.QImage.Format.Format_RGBA8888)
        self.frames_shown += 1
        self.update()

    def clear(self, note: str) -> None:
        self._image, self._pixels, self.note = None, None, note
        self.update()

    def frame_size(self, scale: float = 1.0, cap: int = 512) -> tuple[int, int]:
        """(width, height) in pixels of a frame filling the widget, at most `cap` wide or high."""
        w, h = max(16, self.width()), max(16, self.height())
        s = min(1.0, cap / max(w, h)) * scale
        return max(16, int(w * s)), max(16, int(h * s))

    def reset_view(self) -> None:
        self.azimuth, self.elevation = DEFAULT_ORBIT
        self.zoom = 1.0
        self.view_changed.emit(False)

    # -- gestures ------------------------------------------------------------------------------
    def mousePressEvent(self, event: QtGui.QMouseEvent) -> None:
        if event.button() == QtCore.Qt.MouseButton.LeftButton:
            self._drag = event.position()

    def mouseMoveEvent(self, event: QtGui.QMouseEvent) -> None:
        if self._drag is None:
            return
        d = event.position() - self._drag
        self._drag = event.position()
        self.azimuth -= DEGREES_PER_PIXEL * d.x()
        self.elevation = max(-89.0, min(89.0, self.elevation + DEGREES_PER_PIXEL * d.y()))
        self.view_changed.emit(True)

    def mouseReleaseEvent(self, event: QtGui.QMouseEvent) -> None:
        if self._drag is not None:
            self._drag = None
            self.view_changed.emit(False)

    def mouseDoubleClickEvent(self, event: QtGui.QMouseEvent) -> None:
        self.reset_view()

    def wheelEvent(self, event: QtGui.QWheelEvent) -> None:
        notches = event.angleDelta().y() / 120.0
        if notches:
            self.zoom = float(np.clip(self.zoom * ZOOM_PER_NOTCH ** notches, *ZOOM_RANGE))
            self.view_changed.emit(False)

    # -- drawing -------------------------------------------------------------------------------
    def paintEvent(self, event: QtGui.QPaintEvent) -> None:
        p = QtGui.QPainter(self)
        p.fillRect(self.rect(), QtGui.QColor(40, 42, 46))
        if self._image is None:
            p.setPen(QtGui.QColor(150, 150, 150))
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter | QtCore.Qt.TextFlag.TextWordWrap,
                       self.note)
            return
        size = QtCore.QSizeF(self._image.size()).scaled(QtCore.QSizeF(self.size()),
                                                         QtCore.Qt.AspectRatioMode.KeepAspectRatio)
        target = QtCore.QRectF(QtCore.QPointF(0, 0), size)
        target.moveCenter(QtCore.QRectF(self.rect()).center())
        p.setRenderHint(QtGui.QPainter.RenderHint.SmoothPixmapTransform)
        p.drawImage(target, self._image)
