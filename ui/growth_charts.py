"""Charts of the Virtual Growth dock: realised block probabilities as a pie,
E(theta) of a 2D stiffness as a polar curve. Drawn with QPainter."""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

PIE_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#b07aa1", "#76b7b2", "#edc948",
               "#ff9da7", "#9c755f", "#bab0ac")


class PieChart(QtWidgets.QWidget):
    """Realised block probabilities as a pie with a legend (and the requested hints)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.names: list[str] = []
        self.values = np.zeros(0)
        self.requested: np.ndarray | None = None
        self.setMinimumHeight(130)

    def set_data(self, names, values, requested=None) -> None:
        self.names = list(names)
        self.values = np.asarray(values, dtype=float)
        self.requested = None if requested is None else np.asarray(requested, dtype=float)
        self.update()

    def legend_lines(self) -> list[str]:
        lines = []
        for k, (name, v) in enumerate(zip(self.names, self.values)):
            text = f"{name}  {100 * v:.1f}%"
            if self.requested is not None and k < len(self.requested):
                text += f"  (hint {100 * self.requested[k]:.0f}%)"
            lines.append(text)
        return lines

    def paintEvent(self, _event) -> None:
        p = QtGui.QPainter(self)
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        if not self.names or self.values.sum() <= 0:
            p.setPen(self.palette().text().color())
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "no blocks placed")
            p.end()
            return
        d = min(self.height() - 10, self.width() // 2 - 10)
        pie = QtCore.QRectF(5, (self.height() - d) / 2, d, d)
        start = 90 * 16
        for k, v in enumerate(self.values):
            span = int(round(-v * 360 * 16))
            p.setBrush(QtGui.QColor(PIE_COLOURS[k % len(PIE_COLOURS)]))
            p.setPen(QtGui.QPen(QtGui.QColor("white"), 1))
            if span:
                p.drawPie(pie, start, span)
            start += span
        fm = p.fontMetrics()
        x = pie.right() + 14
        y = max(4, (self.height() - fm.height() * len(self.names)) / 2)
        for k, text in enumerate(self.legend_lines()):
            p.setBrush(QtGui.QColor(PIE_COLOURS[k % len(PIE_COLOURS)]))
            p.setPen(QtCore.Qt.PenStyle.NoPen)
            p.drawRect(QtCore.QRectF(x, y + 3, fm.height() - 6, fm.height() - 6))
            p.setPen(self.palette().text().color())
            p.drawText(QtCore.QPointF(x + fm.height(), y + fm.ascent()), text)
            y += fm.height()
        p.end()


class PolarPlot(QtWidgets.QWidget):
    """E(theta) of a 2D stiffness as a closed polar curve."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.theta = np.zeros(0)
        self.values = np.zeros(0)
        self.setMinimumSize(140, 140)

    def set_curve(self, theta, values) -> None:
        self.theta = np.asarray(theta, float)
        self.values = np.asarray(values, float)
        self.update()

    def paintEvent(self, _event) -> None:
        p = QtGui.QPainter(self)
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        c = QtCore.QPointF(self.width() / 2, self.height() / 2)
        radius = min(self.width(), self.height()) / 2 - 8
        vmax = float(np.max(self.values)) if self.values.size and np.all(np.isfinite(self.values)) else 0
        grid = QtGui.QPen(QtGui.QColor(150, 150, 150), 1, QtCore.Qt.PenStyle.DotLine)
        p.setPen(grid)
        for f in (0.5, 1.0):
            p.drawEllipse(c, radius * f, radius * f)
        p.drawLine(QtCore.QPointF(c.x() - radius, c.y()), QtCore.QPointF(c.x() + radius, c.y()))
        p.drawLine(QtCore.QPointF(c.x(), c.y() - radius), QtCore.QPointF(c.x(), c.y() + radius))
        if vmax > 0:
            s = radius / vmax
            pts = [QtCore.QPointF(c.x() + s * v * math.cos(t), c.y() - s * v * math.sin(t))
                   for t, v in zip(self.theta, self.values)]
            p.setPen(QtGui.QPen(QtGui.QColor("#4e79a7"), 2))
            p.setBrush(QtGui.QColor(78, 121, 167, 50))
            p.drawPolygon(QtGui.QPolygonF(pts))
            p.setPen(self.palette().text().color())
            p.drawText(QtCore.QPointF(2, self.height() - 3), f"max {vmax:.3g}")
        p.end()
