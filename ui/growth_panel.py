"""The "Virtual Growth" dock: a grown tiling as an image, its growth replayed,
hint regions painted on it, its realised block probabilities and (when a
Tiling Properties node follows it) the in-plane stiffness.

The panel shows the tiling of the selected node, or of the node feeding the
selected node, or else of the last node in the graph that produced one. A 3D
tiling is shown one layer at a time (axis and layer chosen below the
picture), each block's beams projected onto the layer plane
(``engine.growth.layers``).

The replay reveals the cells in the order growth decided them, from the grid
as it was before the growth: the ``steps`` / ``start_tiles`` the Grow node
recorded on its output when present (so a local regrowth replays as one),
else the tiling's own ``steps`` (start: the tiling with those cells
cleared), else a regrowth with ``record_steps=True`` from the node's
parameters (same tiling for a growth in one pass). A QTimer on the GUI
thread drives it; defects show red as they form.

Painting (2D Grow nodes, with an undo stack): each stroke on the picture
becomes one ``SetParam(node, "regions", text)``, clear all one more, and the
hints per label one ``SetParam(node, "region_hints", text)``; the panel
follows the document's events, so undo / redo show at once.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.graph import SetParam
from engine.graph.values import Stiffness, TilingValue
from engine.growth import UNASSIGNED, Tiling, grow_tiling, realised_probabilities, tiling_image
from engine.growth.layers import LAYER_AXES, layer_image, tiling_layer
from engine.growth.regions import format_region_map, parse_region_map

from .growth_charts import PieChart, PolarPlot
from .region_canvas import RegionCanvas
from .region_tools import RegionTools

SOLID_RGB = (40, 44, 52)
VOID_RGB = (236, 236, 230)
UNASSIGNED_RGB = (160, 160, 160)
ARM_UP_RGB = (31, 119, 180)
ARM_DOWN_RGB = (230, 140, 30)
# layer image codes (engine.growth.layers: VOID, BEAM, ARM_UP, ARM_DOWN, NOT_GROWN) -> colour
LAYER_RGB = np.array([VOID_RGB, SOLID_RGB, ARM_UP_RGB, ARM_DOWN_RGB, UNASSIGNED_RGB], np.uint8)
TICK_MS = 20
MAX_IMAGE_PX = 800  # longest side of the rendered tiling image, in pixels
AXIS_TEXT = {"z": "z (x-y layers)", "y": "y (x-z layers)", "x": "x (y-z layers)"}
NO_TILING = "select a Grow node (or evaluate a graph with one)"


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


def layer_rgb(tiles: np.ndarray, tileset, axis: str, index: int, ppb: int) -> np.ndarray:
    """(rows*ppb, cols*ppb, 3) uint8 picture of one layer of a 3D grid."""
    codes = layer_image(tiles, tileset, axis, index, resolution=ppb, line_width=max(1.0, ppb / 5.0))
    return np.ascontiguousarray(LAYER_RGB[codes])


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


def recorded_history(tv: TilingValue):
    """(start grid, steps (n, 2), final grid) recorded with the tiling, or None.

    ``tv.steps`` / ``tv.start_tiles`` (set by the Grow node) first, then the
    tiling's own ``steps``; without a start grid the cells named in the steps
    are cleared from the final grid (growth decides each cell once).
    """
    final = np.asarray(tv.tiling.tiles)
    steps = getattr(tv, "steps", None)
    if steps is None:
        steps = getattr(tv.tiling, "steps", None)
    if steps is None:
        return None
    steps = np.asarray(steps)
    if steps.ndim != 2 or steps.shape[1] != 2 or not np.issubdtype(steps.dtype, np.integer) \
            or (steps.size and (steps[:, 0].min() < 0 or steps[:, 0].max() >= final.size)):
        return None
    start = getattr(tv, "start_tiles", None)
    if start is None or np.shape(start) != final.shape:
        start = final.copy()
        start.reshape(-1)[steps[:, 0]] = UNASSIGNED
    return np.array(start, dtype=np.int32), steps.astype(np.int64), final


class GrowthPanel(QtWidgets.QWidget):
    """Dock content: tiling picture with painted regions, growth replay, 3D layers,
    block probabilities, 2D stiffness.

    Parameters
    ----------
    parent : QWidget, optional
    undo : engine.graph.UndoStack, optional
        Where paint strokes and region hints go; without it painting is off
        (see `set_undo`).
    """

    def __init__(self, parent=None, *, undo=None):
        super().__init__(parent)
        self.doc = None
        self.undo = None
        self._watched = None
        self.node_id: str | None = None
        self.value: TilingValue | None = None
        self.stiffness: Stiffness | None = None
        self.stiffness_id: str | None = None
        self.ppb = 20
        self.image_shape: tuple = ()  # (height, width) in pixels of the shown image
        self.shown_tiles: np.ndarray | None = None  # the whole grid shown (a layer of it in 3D)
        self.requested: np.ndarray | None = None
        self.replay_note = ""
        self._reset_replay()
        self._carry = 0.0

        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel(NO_TILING)
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)
        self.view = RegionCanvas()
        self.view.strokeFinished.connect(self._on_stroke)
        lay.addWidget(self.view, 3)
        lay.addWidget(self._build_layer_row())

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
        self.anim_label.setWordWrap(True)
        lay.addWidget(self.anim_label)

        self.region_tools = RegionTools()
        self.region_tools.labelChosen.connect(self._on_label_chosen)
        self.region_tools.radiusChanged.connect(self._on_radius)
        self.region_tools.overlayToggled.connect(self.view.set_overlay_visible)
        self.region_tools.clearRequested.connect(self.clear_regions)
        self.region_tools.hintsApplied.connect(self._on_hints_applied)
        self.view.paint_label = self.region_tools.paint_label
        self.view.brush_radius = self.region_tools.radius.value()
        lay.addWidget(self.region_tools)

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
        self.set_undo(undo)

    def _build_layer_row(self) -> QtWidgets.QWidget:
        self.layer_row = QtWidgets.QWidget()
        h = QtWidgets.QHBoxLayout(self.layer_row)
        h.setContentsMargins(0, 0, 0, 0)
        h.addWidget(QtWidgets.QLabel("Layers along"))
        self.layer_axis = QtWidgets.QComboBox()
        for axis in LAYER_AXES:
            self.layer_axis.addItem(AXIS_TEXT[axis], axis)
        self.layer_axis.currentIndexChanged.connect(self._on_layer_axis)
        h.addWidget(self.layer_axis)
        self.layer_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.layer_slider.setRange(0, 0)
        self.layer_slider.valueChanged.connect(self._on_layer)
        h.addWidget(self.layer_slider, 1)
        self.layer_label = QtWidgets.QLabel("")
        h.addWidget(self.layer_label)
        key = QtWidgets.QLabel(f"<span style='color:rgb{ARM_UP_RGB}'>&#9679;</span> up "
                               f"<span style='color:rgb{ARM_DOWN_RGB}'>&#9679;</span> down")
        h.addWidget(key)
        self.layer_row.setToolTip("a 3D tiling is shown layer by layer: beams in the layer plane as "
                                  "lines, beams to the next layer as small blue discs, to the "
                                  "previous layer as larger orange discs")
        self.layer_row.hide()
        return self.layer_row

    # -- document and undo --------------------------------------------------------------------
    def set_undo(self, undo) -> None:
        """Where paint strokes go (an UndoStack over the shown document); None turns painting off."""
        self.undo = undo
        if undo is not None:
            self._watch(undo.doc)
        self._refresh_regions()

    def _watch(self, doc) -> None:
        """Follow `doc`'s events (parameter edits, undo) to keep the painted map current."""
        if doc is self._watched:
            return
        if self._watched is not None:
            self._watched.unsubscribe(self._on_doc_event)
        self._watched = doc
        if doc is not None:
            doc.subscribe(self._on_doc_event)

    def detach(self) -> None:
        """Stop following the document and stop the replay (the window is closing)."""
        self.pause()
        self._watch(None)

    def _on_doc_event(self, event: str, payload) -> None:
        try:
            if event == "param_changed":
                node_id, name = payload
                if node_id == self.node_id and name in ("regions", "region_hints", "hints", "size"):
                    self._refresh_regions()
            elif event in ("node_removed", "reset"):
                self._refresh_regions()
        except RuntimeError:   # the widget is gone; the document lives on
            pass

    def _grow_node(self):
        doc = self.doc if self.doc is not None else self._watched
        node = doc.nodes.get(self.node_id) if doc is not None and self.node_id else None
        return node if node is not None and node.type_name == "Grow" else None

    def paint_block_reason(self) -> str | None:
        """Why painting is off now, or None when it is on."""
        node = self._grow_node()
        if self.value is None:
            return "painting needs a tiling: evaluate a graph with a Grow node"
        if node is None:
            return "hint regions are painted on the tiling of a Grow node"
        if self.value.ndim != 2:
            return "painted regions are for 2D grids; this tiling is 3D"
        if self.undo is None:
            return "painting is off: the panel has no undo history to record strokes"
        if self.doc is not None and self.undo.doc is not self.doc:
            return "painting is off: the undo history belongs to another document"
        size = tuple(int(s) for s in node.params.get("size", ()))[::-1]
        if size != tuple(self.value.tiling.shape):
            return "the grid size changed since the last evaluation: evaluate to paint"
        return None

    def _refresh_regions(self) -> None:
        reason = self.paint_block_reason()
        node = self._grow_node()
        labels, problem = None, ""
        if node is not None and self.value is not None and self.value.ndim == 2:
            try:
                labels = parse_region_map(node.params.get("regions", ""), self.value.tiling.shape)
            except ValueError as exc:
                problem = f"the regions text does not fit this grid ({exc}); a stroke replaces it"
        self.view.set_labels(labels)
        self.view.set_painting(reason is None)
        self.view.setToolTip(reason or "")
        self.region_tools.set_available(reason)
        if node is not None and self.value is not None and self.value.ndim == 2:
            self.region_tools.set_state(labels, node.params.get("region_hints", ""),
                                        node.params.get("hints", ""), self.value.tileset)
        else:
            self.region_tools.set_state(None, "", "", None)
        if problem:
            self.region_tools.show_message(problem, error=True)

    def _push_param(self, name: str, value: str) -> bool:
        try:
            self.undo.push(SetParam(self.node_id, name, value))
        except Exception as exc:   # refused by the document: nothing changed
            self.region_tools.show_message(f"not applied: {exc}", error=True)
            self._refresh_regions()
            return False
        return True

    def _on_stroke(self, labels: np.ndarray) -> None:
        if self.paint_block_reason() is not None:
            self._refresh_regions()
            return
        self._push_param("regions", format_region_map(labels) if np.any(labels) else "")

    def clear_regions(self) -> None:
        """Remove every painted region: one undo step (nothing if nothing is painted)."""
        node = self._grow_node()
        if node is None or self.paint_block_reason() is not None:
            return
        if not node.params.get("regions", "").strip():
            self.region_tools.show_message("nothing is painted")
            return
        self._push_param("regions", "")

    def _on_hints_applied(self, text: str) -> None:
        if self._grow_node() is not None and self.paint_block_reason() is None:
            if self._push_param("region_hints", text):
                self.region_tools.show_message("hints applied")

    def _on_label_chosen(self, label: int) -> None:
        self.view.paint_label = int(label)

    def _on_radius(self, radius: float) -> None:
        self.view.brush_radius = float(radius)

    # -- context ------------------------------------------------------------------------------
    def set_context(self, doc, outputs: dict, selected: str | None) -> None:
        """Pick the tiling to show from the latest evaluation outputs and the selection."""
        self.doc = doc
        self._watch(doc if doc is not None else getattr(self.undo, "doc", None))
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
        self._refresh_regions()

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
        self._reset_replay()
        tv = self.value
        if tv is None:
            self.caption.setText(NO_TILING)
            self.layer_row.hide()
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
        self.layer_row.setVisible(tv.ndim == 3)
        if tv.ndim == 3:
            self._fit_layer_slider()
        self._set_image(np.asarray(t.tiles))
        self._set_controls_enabled(True)
        self.anim_label.setText("")
        self.requested = self._requested_blocks()
        self.pie.set_data(tv.tileset.block_names, realised_probabilities(t, tv.tileset), self.requested)

    @property
    def axis(self) -> str:
        return self.layer_axis.currentData() or "z"

    @property
    def layer(self) -> int:
        return int(self.layer_slider.value())

    def set_layer(self, axis: str, index: int) -> None:
        """Show layer `index` along `axis` ("z", "y" or "x") of a 3D tiling."""
        self.layer_axis.setCurrentIndex(list(LAYER_AXES).index(axis))
        self.layer_slider.setValue(int(index))

    def _fit_layer_slider(self) -> None:
        n = self.value.tiling.shape[LAYER_AXES[self.axis][0]]
        self.layer_slider.blockSignals(True)
        self.layer_slider.setRange(0, n - 1)
        self.layer_slider.setValue(min(self.layer_slider.value(), n - 1))
        self.layer_slider.blockSignals(False)
        self.layer_label.setText(f"{self.axis} = {self.layer} / {n - 1}")

    def _on_layer_axis(self, _index: int) -> None:
        if self.value is not None and self.value.ndim == 3:
            self._fit_layer_slider()
            self._set_image(self.shown_tiles)

    def _on_layer(self, _value: int) -> None:
        if self.value is not None and self.value.ndim == 3:
            self._fit_layer_slider()
            self._set_image(self.shown_tiles)

    def _set_image(self, tiles: np.ndarray | None) -> None:
        """Show the whole grid `tiles` (one layer of it in 3D); None clears."""
        if tiles is None:
            self.shown_tiles, self.image_shape = None, ()
            self.view.set_grid(None, None)
            return
        tv = self.value
        self.shown_tiles = np.array(tiles)
        if self.shown_tiles.ndim == 2:
            rgb = tiling_rgb(tiles, tv.tileset, tv.tiling.tileset_name, tv.tiling.periodic, self.ppb)
            cells = self.shown_tiles
        else:
            rgb = layer_rgb(self.shown_tiles, tv.tileset, self.axis, self.layer, self.ppb)
            cells = tiling_layer(self.shown_tiles, self.axis, self.layer)
        self.image_shape = rgb.shape[:2]
        self.view.set_grid(rgb, cells)

    def _node_hints(self):
        """(parsed hints or None, availability or None); hints False if unknown / unparsable."""
        node = self._grow_node()
        if node is None:
            return False, None
        try:
            from engine.batch.hints_text import parse_hints
            hints = parse_hints(node.params.get("hints", ""), self.value.tileset)
        except ValueError:
            return False, None
        return hints, (node.params.get("availability") or None)

    def _requested_blocks(self) -> np.ndarray | None:
        """Block probabilities the node asks for, averaged over the painted cells' hints."""
        hints, _ = self._node_hints()
        if hints is False:
            return None
        ts = self.value.tileset
        regions = self._grow_node().params.get("regions", "")
        if self.value.ndim != 2 or not regions.strip():
            return requested_block_hints(hints, ts)
        from engine.batch.hints_text import parse_hints
        from engine.growth.regions import parse_region_hints
        try:
            counts = np.bincount(parse_region_map(regions, self.value.tiling.shape).ravel())
            per_label = parse_region_hints(self._grow_node().params.get("region_hints", ""),
                                           lambda text: parse_hints(text, ts))
        except ValueError:
            return None
        total = np.zeros(ts.n_blocks)
        for label in np.flatnonzero(counts):
            share = requested_block_hints(per_label.get(int(label), hints), ts)
            if share is None:
                return None
            total += counts[label] * share
        return total / total.sum()

    def _growth_hints(self):
        """Hints the Grow node passes to growth: its base hints or the painted field; False if unknown."""
        hints, _ = self._node_hints()
        node = self._grow_node()
        if hints is False or self.value.ndim != 2 or not node.params.get("regions", "").strip():
            return hints
        from engine.batch.hints_text import parse_hints
        from engine.growth.regions import parse_region_hints, region_hint_field
        ts, shape = self.value.tileset, self.value.tiling.shape
        try:
            labels = parse_region_map(node.params["regions"], shape)
            per_label = parse_region_hints(node.params.get("region_hints", ""),
                                           lambda text: parse_hints(text, ts))
        except ValueError:
            return False
        return region_hint_field(ts, shape, labels, hints, per_label)

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
    def _reset_replay(self) -> None:
        self.replay_start: np.ndarray | None = None
        self.replay_steps: np.ndarray | None = None
        self.replay_final: np.ndarray | None = None
        self.replay_error = ""
        self.replay_note = ""
        self.anim_grid: np.ndarray | None = None
        self.anim_pos = 0

    def _set_controls_enabled(self, on: bool) -> None:
        self.play_button.setEnabled(on)
        self.speed.setEnabled(on)

    def _on_speed(self, value: int) -> None:
        self.speed_label.setText(f"{value} steps/s")

    def prepare_replay(self) -> bool:
        """Find (or rebuild) the shown tiling's growth history; False (with a note) if impossible."""
        if self.replay_steps is not None:
            return True
        tv = self.value
        if tv is None:
            return False
        history = recorded_history(tv)
        if history is None:
            history = self._regrown_history()
            if history is None:
                return False
        else:
            cleared = int(np.count_nonzero(history[0] == UNASSIGNED))
            self.replay_note = ("recorded growth" if cleared == tv.tiling.tiles.size
                                else f"recorded local regrowth of {cleared} cells")
        self.replay_start, self.replay_steps, self.replay_final = history
        self.anim_grid = self.replay_start.copy()
        self.anim_pos = 0
        return True

    def _regrown_history(self):
        """Grow the tiling again from the node's parameters with its steps recorded."""
        tv = self.value
        t = tv.tiling
        _, availability = self._node_hints()
        hints = self._growth_hints()
        if hints is False or t.seed is None:
            self.replay_error = "cannot replay: the growth parameters are not known"
            self.anim_label.setText(self.replay_error)
            return None
        try:
            replay = grow_tiling(tv.tileset, t.shape, hints=hints, periodic=t.periodic,
                                 availability=availability, rng=t.seed, record_steps=True)
        except Exception as exc:
            self.replay_error = f"cannot replay: {exc}"
            self.anim_label.setText(self.replay_error)
            return None
        if not np.array_equal(replay.tiles, t.tiles):
            self.replay_note = ("the shown tiling was not grown in one pass from the node's current "
                                "parameters (local regrowth or an edit) and carries no record: "
                                "the replay shows a fresh growth")
        start = np.full(t.shape, UNASSIGNED, dtype=np.int32)
        return start, np.asarray(replay.steps, dtype=np.int64), np.asarray(replay.tiles)

    @property
    def n_steps(self) -> int:
        return 0 if self.replay_steps is None else len(self.replay_steps)

    def assigned_count(self) -> int:
        """Cells shown as decided (tile or defect) in the whole shown grid."""
        if self.shown_tiles is None:
            return 0
        return int(np.count_nonzero(self.shown_tiles != UNASSIGNED))

    def restart(self) -> None:
        if self.prepare_replay():
            self.anim_grid[...] = self.replay_start
            self.anim_pos = 0
            self._set_image(self.anim_grid)
            self._update_anim_label()

    def step(self, n: int = 1) -> int:
        """Reveal the next `n` growth events; returns the number of assigned cells shown."""
        if not self.prepare_replay():
            return self.assigned_count()
        steps = self.replay_steps
        end = min(len(steps), self.anim_pos + max(0, int(n)))
        if end > self.anim_pos:
            chunk = steps[self.anim_pos:end]
            flat = self.anim_grid.reshape(-1)
            flat[chunk[:, 0]] = chunk[:, 1]  # later events win, as in the growth
            self.anim_pos = end
            if self.anim_pos == len(steps):
                self.anim_grid[...] = self.replay_final  # exactly the grown tiling
            self._set_image(self.anim_grid)
        self._update_anim_label()
        return self.assigned_count()

    def _update_anim_label(self) -> None:
        text = (f"growth step {self.anim_pos} / {self.n_steps}, "
                f"{self.assigned_count()} cells assigned")
        if self.replay_note:
            text += f" ({self.replay_note})"
        self.anim_label.setText(text)

    @property
    def playing(self) -> bool:
        return self.timer.isActive()

    def play(self) -> None:
        if not self.prepare_replay():
            self.play_button.setChecked(False)
            return
        if self.anim_pos == 0 or self.anim_pos >= self.n_steps:
            self.restart()  # start from the grid before the growth
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
