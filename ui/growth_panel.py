"""The "Virtual Growth" dock: a grown tiling as an image, its growth replayed,
its realised block probabilities and (when a Tiling Properties node follows
it) the in-plane stiffness.

The panel shows the tiling of the selected node, or of the node feeding the
selected node, or else of the last node in the graph that produced one.  The
replay regrows the tiling with ``record_steps=True`` (same tile set, shape,
hints, periodicity, availability and seed, so the same tiling) and reveals the
cells in the order growth decided them; a QTimer on the GUI thread drives it.
Everything is drawn with QPainter.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph.values import Stiffness, TilingValue
from engine.growth import DEFECT, UNASSIGNED, Tiling, grow_tiling, realised_probabilities, tiling_image

SOLID_RGB = (40, 44, 52)
VOID_RGB = (236, 236, 230)
UNASSIGNED_RGB = (160, 160, 160)
DEFECT_COLOUR = QtGui.QColor(220, 40, 40)
PIE_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#b07aa1", "#76b7b2", "#edc948",
               "#ff9da7", "#9c755f", "#bab0ac")
TICK_MS = 20
MAX_IMAGE_PX = 800  # longest side of the rendered tiling image, in pixels


def tiling_of(outputs: dict) -> TilingValue | None:
    for value in (outputs or {}).values():
        if isinstance(value, TilingValue):
            return value
    return None


def stiffness2d_of(outputs: dict) -> Stiffness | None:
    for value in (outputs or {}).values():
        if isinstance(value, Stiffness) and np.shape(value.C) == (3, 3):
            return value
    return None


def pixels_per_block(shape) -> int:
    return int(max(2, min(20, MAX_IMAGE_PX // max(1, max(shape)))))


def tiling_rgb(tiles: np.ndarray, tileset, tileset_name: str, periodic: bool, ppb: int) -> np.ndarray:
    """(ny*ppb, nx*ppb, 3) uint8: solid dark, void light, unassigned cells grey."""
    tiling = Tiling(np.array(tiles, dtype=np.int32), tileset_name, periodic)
    img = tiling_image(tiling, tileset, resolution=ppb, line_width=max(1.0, ppb / 5.0))
    rgb = np.where(img[..., None] > 0, np.array(SOLID_RGB, np.uint8), np.array(VOID_RGB, np.uint8))
    unassigned = np.asarray(tiles) == UNASSIGNED
    if unassigned.any():
        mask = np.repeat(np.repeat(unassigned, ppb, axis=0), ppb, axis=1)
        rgb[mask] = UNASSIGNED_RGB
    return np.ascontiguousarray(rgb.astype(np.uint8))


def requested_block_hints(hints, tileset) -> np.ndarray | None:
    """Requested block probabilities (normalised), from parsed hints or the set's weights."""
    n_blocks = tileset.n_blocks
    tile_block = np.asarray(tileset.tile_block)
    if hints is None:
        w = np.bincount(tile_block, weights=np.asarray(tileset.weights, float), minlength=n_blocks)
    else:
        w = np.zeros(n_blocks)
        names = list(tileset.block_names)
        tiles = list(tileset.tile_names)
        for key, value in dict(hints).items():
            if key in names:
                w[names.index(key)] += float(value)
            elif key in tiles:
                w[tile_block[tiles.index(key)]] += float(value)
            else:
                return None
    total = float(w.sum())
    return w / total if total > 0 else None


class TilingView(QtWidgets.QWidget):
    """A tiling image scaled to fit (nearest neighbour) with defect cells marked red."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.image: QtGui.QImage | None = None
        self.grid_shape: tuple = ()
        self.defects = np.zeros((0, 2), dtype=int)  # (row, col) of defect cells
        self.setMinimumSize(200, 200)
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Expanding, QtWidgets.QSizePolicy.Policy.Expanding)

    def set_grid(self, rgb: np.ndarray | None, tiles: np.ndarray | None) -> None:
        if rgb is None:
            self.image, self.grid_shape, self.defects = None, (), np.zeros((0, 2), dtype=int)
        else:
            h, w, _ = rgb.shape
            self._rgb = rgb  # the QImage borrows this buffer
            self.image = QtGui.QImage(rgb.data, w, h, 3 * w, QtGui.QImage.Format.Format_RGB888).copy()
            self.grid_shape = tuple(tiles.shape)
            self.defects = np.argwhere(np.asarray(tiles) == DEFECT)
        self.update()

    def target_rect(self) -> QtCore.QRectF:
        if self.image is None:
            return QtCore.QRectF()
        iw, ih = self.image.width(), self.image.height()
        s = min((self.width() - 8) / iw, (self.height() - 8) / ih)
        s = max(s, 1e-3)
        w, h = iw * s, ih * s
        return QtCore.QRectF((self.width() - w) / 2, (self.height() - h) / 2, w, h)

    def paintEvent(self, _event) -> None:
        p = QtGui.QPainter(self)
        p.fillRect(self.rect(), self.palette().window())
        if self.image is None:
            p.setPen(self.palette().text().color())
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "no tiling")
            p.end()
            return
        p.setRenderHint(QtGui.QPainter.RenderHint.SmoothPixmapTransform, False)
        r = self.target_rect()
        p.drawImage(r, self.image)  # nearest neighbour: smooth transform is off
        ny, nx = self.grid_shape
        cw, ch = r.width() / nx, r.height() / ny
        pen = QtGui.QPen(DEFECT_COLOUR, max(1.5, min(cw, ch) / 10))
        p.setPen(pen)
        p.setBrush(QtGui.QColor(220, 40, 40, 60))
        inset = 0.12
        for row, col in self.defects:
            p.drawRect(QtCore.QRectF(r.left() + (col + inset) * cw, r.top() + (row + inset) * ch,
                                     (1 - 2 * inset) * cw, (1 - 2 * inset) * ch))
        p.end()


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


class GrowthPanel(QtWidgets.QWidget):
    """Dock content: tiling image, growth replay, block probabilities, 2D stiffness."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.doc = None
        self.node_id: str | None = None
        self.value: TilingValue | None = None
        self.stiffness: Stiffness | None = None
        self.stiffness_id: str | None = None
        self.ppb = 20
        self.image_shape: tuple = ()  # (height, width) in pixels of the shown image
        self.shown_tiles: np.ndarray | None = None
        self.requested: np.ndarray | None = None
        # replay state
        self.replay: Tiling | None = None
        self.replay_error = ""
        self.anim_grid: np.ndarray | None = None
        self.anim_pos = 0
        self._carry = 0.0

        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel("select a Grow node (or evaluate a graph with one)")
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)
        self.view = TilingView()
        lay.addWidget(self.view, 3)

        row = QtWidgets.QHBoxLayout()
        self.play_button = QtWidgets.QPushButton("Play")
        self.play_button.setCheckable(True)
        self.play_button.toggled.connect(self._on_play_toggled)
        self.speed = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.speed.setRange(1, 2000)
        self.speed.setValue(60)
        self.speed_label = QtWidgets.QLabel()
        self.speed.valueChanged.connect(self._on_speed)
        self._on_speed(self.speed.value())
        row.addWidget(self.play_button)
        row.addWidget(self.speed, 1)
        row.addWidget(self.speed_label)
        lay.addLayout(row)
        self.anim_label = QtWidgets.QLabel("")
        lay.addWidget(self.anim_label)

        lay.addWidget(QtWidgets.QLabel("<b>Realised block probabilities</b>"))
        self.pie = PieChart()
        lay.addWidget(self.pie, 1)

        self.stiffness_box = QtWidgets.QGroupBox("In-plane stiffness")
        sl = QtWidgets.QHBoxLayout(self.stiffness_box)
        self.stiffness_label = QtWidgets.QLabel()
        self.stiffness_label.setWordWrap(True)
        self.polar = PolarPlot()
        sl.addWidget(self.stiffness_label, 1)
        sl.addWidget(self.polar)
        self.stiffness_box.hide()
        lay.addWidget(self.stiffness_box, 1)

        self.timer = QtCore.QTimer(self)
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(self._tick)
        self._set_controls_enabled(False)

    # -- context ------------------------------------------------------------------------------
    def set_context(self, doc, outputs: dict, selected: str | None) -> None:
        """Pick the tiling to show from the latest evaluation outputs and the selection."""
        self.doc = doc
        outputs = {k: v for k, v in (outputs or {}).items() if doc is None or k in doc.nodes}
        node_id = self._pick_node(doc, outputs, selected)
        value = tiling_of(outputs[node_id]) if node_id else None
        stiffness_id, stiffness = self._pick_stiffness(doc, outputs, node_id)
        if value is self.value and node_id == self.node_id and stiffness is self.stiffness:
            return  # nothing changed: keep a running replay going
        self.node_id, self.value = node_id, value
        self.stiffness_id, self.stiffness = stiffness_id, stiffness
        self._show_tiling()
        self._show_stiffness()

    @staticmethod
    def _pick_node(doc, outputs, selected):
        if selected in outputs and tiling_of(outputs[selected]) is not None:
            return selected
        if doc is not None and selected in getattr(doc, "nodes", {}):
            for edge in doc.inputs_of(selected):
                if edge.src in outputs and tiling_of(outputs[edge.src]) is not None:
                    return edge.src
        try:
            order = doc.topological_order() if doc is not None else list(outputs)
        except Exception:
            order = list(outputs)
        for nid in reversed(order):
            if nid in outputs and tiling_of(outputs[nid]) is not None:
                return nid
        return None

    @staticmethod
    def _pick_stiffness(doc, outputs, node_id):
        if doc is None or node_id is None:
            return None, None
        for edge in doc.outputs_of(node_id):
            node = doc.nodes.get(edge.dst)
            if node is not None and node.type_name == "TilingProperties" and edge.dst in outputs:
                st = stiffness2d_of(outputs[edge.dst])
                if st is not None:
                    return edge.dst, st
        return None, None

    # -- tiling ---------------------------------------------------------------------------------
    def _show_tiling(self) -> None:
        self.pause()
        self.replay, self.replay_error, self.anim_grid, self.anim_pos = None, "", None, 0
        tv = self.value
        if tv is None:
            self.caption.setText("select a Grow node (or evaluate a graph with one)")
            self._set_image(None)
            self.pie.set_data([], [])
            self.anim_label.setText("")
            self._set_controls_enabled(False)
            return
        t = tv.tiling
        dims = " × ".join(str(s) for s in t.shape[::-1])
        self.caption.setText(f"<b>{self.node_id}</b>: {dims} blocks ({tv.tileset.name}), "
                             f"periodic: {'yes' if t.periodic else 'no'}, "
                             f"defects: {t.n_defects}, seed: {t.seed}")
        self.ppb = pixels_per_block(t.shape)
        if tv.ndim == 2:
            self._set_image(np.asarray(t.tiles))
            self._set_controls_enabled(True)
        else:
            self._set_image(None)
            self._set_controls_enabled(False)
        self.anim_label.setText("" if tv.ndim == 2 else "3D tiling: the image and replay are 2D only")
        hints, _ = self._node_hints()
        self.requested = requested_block_hints(hints, tv.tileset) if hints is not False else None
        self.pie.set_data(tv.tileset.block_names, realised_probabilities(t, tv.tileset), self.requested)

    def _set_image(self, tiles: np.ndarray | None) -> None:
        if tiles is None:
            self.shown_tiles, self.image_shape = None, ()
            self.view.set_grid(None, None)
            return
        tv = self.value
        rgb = tiling_rgb(tiles, tv.tileset, tv.tiling.tileset_name, tv.tiling.periodic, self.ppb)
        self.shown_tiles = np.array(tiles)
        self.image_shape = rgb.shape[:2]
        self.view.set_grid(rgb, self.shown_tiles)

    def _node_hints(self):
        """(parsed hints or None, availability or None); hints False if unknown / unparsable."""
        node = self.doc.nodes.get(self.node_id) if self.doc is not None and self.node_id else None
        if node is None or node.type_name != "Grow":
            return False, None
        try:
            from engine.batch.hints_text import parse_hints
            hints = parse_hints(node.params.get("hints", ""), self.value.tileset)
        except ValueError:
            return False, None
        return hints, (node.params.get("availability") or None)

    def _show_stiffness(self) -> None:
        st = self.stiffness
        if st is None:
            self.stiffness_box.hide()
            return
        c = st.constants
        e_avg, nu_avg = c.get("E_avg", float("nan")), c.get("nu_avg", float("nan"))
        self.stiffness_label.setText(f"<b>{self.stiffness_id}</b><br>E_avg / E_s = {e_avg / st.E:.4g}"
                                     f"<br>nu_avg = {nu_avg:.4g}<br>density = {st.density:.3f}")
        try:
            from engine.physics.material_sphere import material_polar
            theta, e = material_polar(st.C, n=180)
            self.polar.set_curve(theta, e)
        except Exception:  # a singular C has no polar curve
            self.polar.set_curve([], [])
        self.stiffness_box.show()

    # -- replay -----------------------------------------------------------------------------------
    def _set_controls_enabled(self, on: bool) -> None:
        self.play_button.setEnabled(on)
        self.speed.setEnabled(on)

    def _on_speed(self, value: int) -> None:
        self.speed_label.setText(f"{value} steps/s")

    def prepare_replay(self) -> bool:
        """Regrow the shown tiling with its steps recorded; False (with a note) if impossible."""
        if self.replay is not None:
            return True
        tv = self.value
        if tv is None or tv.ndim != 2:
            return False
        t = tv.tiling
        hints, availability = self._node_hints()
        if hints is False or t.seed is None:
            self.replay_error = "cannot replay: the growth parameters are not known"
            self.anim_label.setText(self.replay_error)
            return False
        try:
            replay = grow_tiling(tv.tileset, t.shape, hints=hints, periodic=t.periodic,
                                 availability=availability, rng=t.seed, record_steps=True)
        except Exception as exc:
            self.replay_error = f"cannot replay: {exc}"
            self.anim_label.setText(self.replay_error)
            return False
        if not np.array_equal(replay.tiles, t.tiles):
            self.replay_error = ("the shown tiling was not grown in one pass from the node's current "
                                 "parameters (painted regions, local regrowth or an edit): the replay "
                                 "shows a fresh growth")
            self.anim_label.setText(self.replay_error)
        self.replay = replay
        self.anim_grid = np.full(t.shape, UNASSIGNED, dtype=np.int32)
        self.anim_pos = 0
        return True

    @property
    def n_steps(self) -> int:
        return 0 if self.replay is None else len(self.replay.steps)

    def assigned_count(self) -> int:
        """Cells shown as decided (tile or defect) in the current image."""
        if self.shown_tiles is None:
            return 0
        return int(np.count_nonzero(self.shown_tiles != UNASSIGNED))

    def restart(self) -> None:
        if self.prepare_replay():
            self.anim_grid[...] = UNASSIGNED
            self.anim_pos = 0
            self._set_image(self.anim_grid)
            self._update_anim_label()

    def step(self, n: int = 1) -> int:
        """Reveal the next `n` growth events; returns the number of assigned cells shown."""
        if not self.prepare_replay():
            return self.assigned_count()
        steps = self.replay.steps
        end = min(len(steps), self.anim_pos + max(0, int(n)))
        if end > self.anim_pos:
            chunk = steps[self.anim_pos:end]
            flat = self.anim_grid.reshape(-1)
            flat[chunk[:, 0]] = chunk[:, 1]  # later events win, as in the growth
            self.anim_pos = end
            if self.anim_pos == len(steps):
                self.anim_grid[...] = self.replay.tiles  # exactly the grown tiling
            self._set_image(self.anim_grid)
        self._update_anim_label()
        return self.assigned_count()

    def _update_anim_label(self) -> None:
        self.anim_label.setText(f"growth step {self.anim_pos} / {self.n_steps}, "
                                f"{self.assigned_count()} cells assigned")

    @property
    def playing(self) -> bool:
        return self.timer.isActive()

    def play(self) -> None:
        if not self.prepare_replay():
            self.play_button.setChecked(False)
            return
        if self.anim_pos == 0 or self.anim_pos >= self.n_steps:
            self.restart()  # start from the empty (grey) grid
        self._carry = 0.0
        self.timer.start()
        if not self.play_button.isChecked():
            self.play_button.setChecked(True)
        self.play_button.setText("Pause")

    def pause(self) -> None:
        self.timer.stop()
        if self.play_button.isChecked():
            self.play_button.setChecked(False)
        self.play_button.setText("Play")

    def _on_play_toggled(self, on: bool) -> None:
        if on and not self.playing:
            self.play()
        elif not on and self.playing:
            self.pause()

    def _tick(self) -> None:
        self._carry += self.speed.value() * TICK_MS / 1000.0
        n = int(self._carry)
        self._carry -= n
        if n:
            self.step(n)
        if self.anim_pos >= self.n_steps:
            self.pause()
