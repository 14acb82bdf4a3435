"""The "Reaction/Diffusion" dock: view the growth inputs and structures, grow live, brush, compare.

The dock follows one TopOpt -> RDFields -> RDGrow -> RDCompile chain: the
selected node's (walking up and down its edges), else the previous one,
else the only one in the graph. From the latest evaluation outputs it shows,
on a 2D grid or one slice of a 3D grid (axis and a scrub slider):

* rho, the infill map Gamma, the principal directions of the tensor field
  as line glyphs (or streamlines) over rho, coloured by ``|sigma_1|``;
* each direction's structure ``s_i`` and the combined result (RDCompile's
  density, else the union ``max_i s_i``);
* a before / after comparison: the data as it was before the last brush
  stroke (or before the edits last changed), instead of or beside now.

"Grow live" runs the engine growth with the RDGrow node's parameters in a
worker (`ui.rd_worker`), drawing every N steps with the step count and
``G^t``; Pause / Resume continue exactly, Cancel keeps the last complete
step. The live run never changes the document; "Apply" asks the window to
evaluate the document the normal way (signal ``evaluate_requested``).

A left drag on the picture is one brush stroke (Escape abandons it): erase
or draw appends ONE edit ``{mode, centres, radius}`` in growth-grid cells
to the RDGrow node's ``edits``, mark solid ONE stroke of stamps
``{centre, radius, value}`` in field cells to the RDFields node's
``gamma_c``, each as one ``SetParam`` on the undo stack.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.graph import SetParam
from engine.graph.values import Field, RDFieldsValue, RDStructuresValue
from engine.rd.preview import (PLANE_AXES, glyph_segments, grid_slice, principal_glyphs,
                               principal_streamlines, rescale_index, slice_point, slice_shape,
                               stroke_centres)

from .phasor_canvas import apply_lut, colour_lut
from .rd_canvas import COMPARE_MODES, BrushBox, RDCanvas, SliceRow
from .rd_worker import LiveGrowthBox

CHAIN = ("TopOpt", "RDFields", "RDGrow", "RDCompile")
COMPARE_TEXT = {"now": "Now", "before": "Before last edit", "split": "Split: before | now"}
GLYPHS = 18              # glyphs / streamline seeds along the longer side
MIN_STEP_PX = 2.0        # a drag records a point after moving this many screen pixels
MAX_MARKS = 600          # stamps outlined on the picture at most
NO_CHAIN = "select an RD node (TopOpt, RDFields, RDGrow or RDCompile) or evaluate a graph with one"
ORDINAL = ("1st", "2nd", "3rd")


# -- picking the chain ------------------------------------------------------------------------
def _type_of(doc, node_id):
    node = doc.nodes.get(node_id) if doc is not None and node_id else None
    return None if node is None else node.type_name


def pick_rd_chain(doc, selected, previous=None) -> dict:
    """``{type name: node id or None}`` for the TopOpt / RDFields / RDGrow / RDCompile chain
    of the selected node, else of ``previous``, else of the only such node."""
    chain = dict.fromkeys(CHAIN)
    if doc is None:
        return chain
    start = next((n for n in (selected, previous) if _type_of(doc, n) in CHAIN), None)
    if start is None:
        for kind in ("RDGrow", "RDFields", "RDCompile", "TopOpt"):
            found = [n for n, node in doc.nodes.items() if node.type_name == kind]
            if len(found) == 1:
                start = found[0]
                break
    if start is None:
        return chain
    k = CHAIN.index(_type_of(doc, start))
    chain[CHAIN[k]] = start
    for i in range(k, 0, -1):        # upstream
        here = chain[CHAIN[i]]
        up = [e.src for e in doc.inputs_of(here)] if here else []
        chain[CHAIN[i - 1]] = next((n for n in up if _type_of(doc, n) == CHAIN[i - 1]), None)
    for i in range(k, len(CHAIN) - 1):   # downstream, first in document order
        here = chain[CHAIN[i]]
        down = [e.dst for e in doc.outputs_of(here)] if here else []
        chain[CHAIN[i + 1]] = next((n for n in doc.nodes if n in down and _type_of(doc, n) == CHAIN[i + 1]),
                                   None)
    return chain


def _fields_of_design(design):
    """A TopOpt design shown as RD fields (no infill map yet) while no RDFields follows it."""
    rho = np.asarray(design.rho)
    principal = getattr(design, "principal", None)
    return RDFieldsValue(rho, design.rotation, np.zeros_like(rho), design.lo, design.hi,
                         magnitude=None if principal is None else np.abs(principal))


def _value(outputs, node_id, kind):
    for value in (outputs.get(node_id) or {}).values() if node_id else ():
        if isinstance(value, kind):
            return value
    return None


class RDPanel(QtWidgets.QWidget):
    """Dock content: RD fields and structures on a paintable slice, live growth, before / after.

    Parameters
    ----------
    doc : GraphDocument; undo : UndoStack over it (strokes are pushed there)

    Signals
    -------
    evaluate_requested() : "Apply" after a live growth: evaluate the document now
    """

    evaluate_requested = QtCore.Signal()

    def __init__(self, doc, undo, parent=None):
        super().__init__(parent)
        self.doc, self.undo = doc, undo
        self.chain = dict.fromkeys(CHAIN)
        self.design = None
        self.fields: RDFieldsValue | None = None
        self.structures: RDStructuresValue | None = None
        self.compiled: Field | None = None
        self.live = None                # LiveFrame shown instead of the structures
        self.before: dict | None = None  # the data before the last edit
        self.shown_values: np.ndarray | None = None   # the slice drawn now, [v, u]
        self.shown_source = ""          # "fields" or "growth": the grid it comes from
        self.shown_index: int | None = None           # layer of that grid (3D)
        self.glyphs = None              # GlyphSet drawn now (tensor views), in field cells
        self._magnitude_cache = (None, None)
        self._stroke: list | None = None
        self._outputs_key = None
        self._shown_painted = (None, None)

        self._build()
        if doc is not None:
            doc.subscribe(self._on_doc_event)
        self._on_brush_changed()
        self._sync_source()
        self._update_live_buttons()

    # -- widgets ------------------------------------------------------------------------------
    def _build(self) -> None:
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel(NO_CHAIN)
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Preset"))
        self.preset_box = QtWidgets.QComboBox()
        self.preset_box.setToolTip("the TopOpt node's problem (the paper's presets)")
        self.preset_box.activated.connect(self._on_preset)
        row.addWidget(self.preset_box, 1)
        self.import_button = QtWidgets.QPushButton("Import fields…")
        self.import_button.setToolTip("read rho, sigma or R (and Gamma) from an .npz or .vti file "
                                      "into the RDFields node")
        self.import_button.clicked.connect(lambda: self.import_fields())
        row.addWidget(self.import_button)
        lay.addLayout(row)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Show"))
        self.view_box = QtWidgets.QComboBox()
        self.view_box.currentIndexChanged.connect(lambda _i: self.redraw())
        row.addWidget(self.view_box, 1)
        self.style_box = QtWidgets.QComboBox()
        self.style_box.addItem("glyphs", "glyphs")
        self.style_box.addItem("streamlines", "streamlines")
        self.style_box.setToolTip("how the principal directions are drawn")
        self.style_box.currentIndexChanged.connect(lambda _i: self.redraw())
        row.addWidget(self.style_box)
        lay.addLayout(row)
        self._fill_views(2)

        self.slice_row = SliceRow()
        self.slice_row.changed.connect(self.redraw)
        self.axis_box, self.index_slider = self.slice_row.axis_box, self.slice_row.slider
        lay.addWidget(self.slice_row)

        self.canvas = RDCanvas()
        self.canvas.strokeBegan.connect(self._on_stroke_began)
        self.canvas.strokeMoved.connect(self._on_stroke_moved)
        self.canvas.strokeEnded.connect(self._on_stroke_ended)
        self.canvas.strokeAborted.connect(self._on_stroke_aborted)
        lay.addWidget(self.canvas, 3)
        self.note = QtWidgets.QLabel("")
        self.note.setWordWrap(True)
        lay.addWidget(self.note)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Compare"))
        self.compare_box = QtWidgets.QComboBox()
        for key in COMPARE_MODES:
            self.compare_box.addItem(COMPARE_TEXT[key], key)
        self.compare_box.currentIndexChanged.connect(self._on_compare_changed)
        row.addWidget(self.compare_box, 1)
        self.split_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.split_slider.setRange(0, 100)
        self.split_slider.setValue(50)
        self.split_slider.valueChanged.connect(self._on_compare_changed)
        row.addWidget(self.split_slider, 1)
        lay.addLayout(row)

        self.live_box = LiveGrowthBox(self)
        self.live_box.job_factory = self._live_job
        self.live_box.frame.connect(self._on_live_frame)
        self.live_box.apply_requested.connect(self._on_apply)
        self.live_box.message.connect(lambda text: self.message.setText(text))
        self.worker = self.live_box.worker
        # the controls under their usual names
        self.every_spin, self.pause_button = self.live_box.every_spin, self.live_box.pause_button
        self.apply_button, self.live_label = self.live_box.apply_button, self.live_box.label
        lay.addWidget(self.live_box)
        self.brush = BrushBox()
        self.brush.changed.connect(self._on_brush_changed)
        self.mode_box, self.radius_spin, self.value_spin = (self.brush.mode_box, self.brush.radius_spin,
                                                             self.brush.value_spin)
        lay.addWidget(self.brush)
        self.message = QtWidgets.QLabel("")
        self.message.setWordWrap(True)
        lay.addWidget(self.message)

    def _fill_views(self, d: int) -> None:
        keys = ["rho", "gamma"] + [f"tensor{i}" for i in range(d)] + [f"s{i}" for i in range(d)] + ["combined"]
        if [self.view_box.itemData(i) for i in range(self.view_box.count())] == keys:
            return
        current = self.view_box.currentData()
        self.view_box.blockSignals(True)
        self.view_box.clear()
        for key in keys:
            self.view_box.addItem(self._view_text(key), key)
        self.view_box.setCurrentIndex(keys.index(current) if current in keys else 0)
        self.view_box.blockSignals(False)

    @staticmethod
    def _view_text(key: str) -> str:
        fixed = {"rho": "Infill space rho", "gamma": "Infill map Gamma", "combined": "Combined result"}
        if key in fixed:
            return fixed[key]
        i = int(key[-1])
        return (f"Tensor field: {ORDINAL[i]} principal direction" if key.startswith("tensor")
                else f"Structure s_{i + 1} (⟂ {ORDINAL[i]} direction)")

    # -- context ------------------------------------------------------------------------------
    def set_context(self, doc, outputs: dict, selected: str | None) -> None:
        """Pick the chain to show from the latest evaluation ``outputs`` (node id -> {port: value})
        and the selection."""
        if doc is not None and doc is not self.doc:
            if self.doc is not None:
                self.doc.unsubscribe(self._on_doc_event)
            self.doc = doc
            doc.subscribe(self._on_doc_event)
            self.before = None
        outputs = outputs or {}
        chain = pick_rd_chain(self.doc, selected, self.chain["RDGrow"] or self.chain["RDFields"])
        design = _value(outputs, chain["TopOpt"], object) if chain["TopOpt"] else None
        fields = _value(outputs, chain["RDFields"], RDFieldsValue)
        structures = _value(outputs, chain["RDGrow"], RDStructuresValue)
        compiled = _value(outputs, chain["RDCompile"], Field)
        key = (tuple(chain.values()), id(design), id(fields), id(structures), id(compiled))
        if key == self._outputs_key:
            return
        self._outputs_key = key
        if fields is None and design is not None:
            fields = _fields_of_design(design)
        painted = self._painted(chain)
        if chain["RDGrow"] != self.chain["RDGrow"] or chain["RDFields"] != self.chain["RDFields"]:
            self.live_box.shutdown()
            self.live = None
            self.before = None
        else:
            if structures is not None and structures is not self.structures:
                if self.worker.status not in ("running", "paused"):
                    self.live = None      # the node's own result is the truth again
                if structures.regrown:
                    self.message.setText(f"regrown locally around the new edit(s); "
                                         f"{len(structures.edits)} edit(s) applied")
            if painted != self._shown_painted and (self.fields is not None or self.structures is not None):
                self.before = self._data()    # the brush data changed: what was shown is "before"
        self._shown_painted = painted
        if self.canvas.in_stroke:
            self.canvas.abort_stroke()
        self.chain = chain
        self.design, self.fields, self.structures, self.compiled = design, fields, structures, compiled
        d = self._ndim()
        self._fill_views(d or 2)
        self.slice_row.set_grid(self.view_grid())
        self._update_caption()
        self._sync_source()
        self.redraw()
        self._update_live_buttons()

    def _sync_source(self) -> None:
        """The preset box shows the TopOpt node's preset; import needs an RDFields node."""
        from engine.graph.node import node_type

        topopt = self._node("TopOpt")
        self.preset_box.blockSignals(True)
        if self.preset_box.count() == 0 and topopt is not None:
            for name in node_type("TopOpt").param("preset").choices:
                self.preset_box.addItem(name, name)
        if topopt is not None:
            self.preset_box.setCurrentIndex(max(0, self.preset_box.findData(topopt.params.get("preset"))))
        self.preset_box.blockSignals(False)
        self.preset_box.setEnabled(topopt is not None)
        self.import_button.setEnabled(self._node("RDFields") is not None and self.undo is not None)

    def _on_preset(self, _index: int) -> None:
        topopt, name = self._node("TopOpt"), self.preset_box.currentData()
        if topopt is not None and self.undo is not None and topopt.params.get("preset") != name:
            self._push(topopt.id, "preset", name)

    def import_fields(self, path: str | None = None) -> bool:
        """Point the RDFields node at a field file (asks for one without ``path``): one SetParam."""
        fnode = self._node("RDFields")
        if fnode is None or self.undo is None:
            self.message.setText("importing needs an RDFields node in the chain")
            return False
        if path is None:
            path, _ = QtWidgets.QFileDialog.getOpenFileName(self, "Import RD fields", "",
                                                            "Field files (*.npz *.vti)")
            if not path:
                return False
        if not self._push(fnode.id, "path", str(path)):
            return False
        if self.doc.inputs_of(fnode.id):
            self.message.setText("the connected design is used while one is connected; "
                                 "disconnect it to grow on the imported fields")
        return True

    def _push(self, node_id: str, name: str, value) -> bool:
        try:
            self.undo.push(SetParam(node_id, name, value))
        except Exception as exc:   # refused by the document: nothing changed
            self.message.setText(f"<span style='color:#c0392b'>not changed: {exc}</span>")
            return False
        return True

    def _painted(self, chain) -> tuple:
        """The brush data of ``chain`` in the document now: (RDGrow edits, RDFields gamma_c)."""
        nodes = self.doc.nodes if self.doc is not None else {}
        grow, fnode = nodes.get(chain["RDGrow"] or ""), nodes.get(chain["RDFields"] or "")
        return (repr(grow.params.get("edits")) if grow is not None else None,
                repr(fnode.params.get("gamma_c")) if fnode is not None else None)

    def _data(self) -> dict:
        return {"fields": self.fields, "structures": self.structures, "compiled": self.compiled,
                "live": self.live}

    def _ndim(self) -> int | None:
        shown = self.fields if self.fields is not None else self.structures
        return None if shown is None else shown.ndim

    def _node(self, kind):
        nid = self.chain.get(kind)
        return self.doc.nodes.get(nid) if self.doc is not None and nid else None

    def _update_caption(self) -> None:
        ids = [f"<b>{self.chain[k]}</b>" for k in CHAIN if self.chain[k]]
        if not ids:
            self.caption.setText(NO_CHAIN)
            return
        parts = [" → ".join(ids)]
        if self.fields is not None:
            parts.append("fields " + " × ".join(str(n) for n in self.fields.grid_shape[::-1]))
        grid = self.growth_grid()
        if grid is not None:
            parts.append("growth " + " × ".join(str(n) for n in grid[::-1]))
        if self.fields is None and self.structures is None:
            parts.append("not evaluated yet")
        grow, fnode = self._node("RDGrow"), self._node("RDFields")
        if grow is not None:
            parts.append(f"{len(grow.params.get('edits', []))} edit(s)")
        if fnode is not None:
            parts.append(f"{len(fnode.params.get('gamma_c', []))} solid stroke(s)")
        self.caption.setText(", ".join(parts))

    def _on_doc_event(self, event: str, payload) -> None:
        try:
            if event == "param_changed" and payload[0] in self.chain.values():
                self._update_caption()
                self._sync_source()
                if payload == (self.chain["RDGrow"], "resolution"):   # the view grid changed
                    self.slice_row.set_grid(self.view_grid())
                    self.redraw()
                else:
                    self._update_marks()
            elif event in ("node_removed", "reset") and any(
                    n is not None and n not in self.doc.nodes for n in self.chain.values()):
                self.live_box.shutdown()
                self._outputs_key = None
                self.set_context(self.doc, {}, None)
        except RuntimeError:   # the widget is gone; the document lives on
            pass

    # -- grids --------------------------------------------------------------------------------
    def growth_grid(self) -> tuple | None:
        """Shape ([y, x] / [z, y, x]) of the RDGrow node's growth grid, from its current
        parameters and the evaluated fields (else the evaluated structures)."""
        grow = self._node("RDGrow")
        if grow is not None and self.fields is not None:
            from engine.nodes.rd import growth_shape
            try:
                return tuple(growth_shape(grow.params.get("resolution", []), self.fields))
            except Exception:
                pass
        if self.structures is not None:
            return tuple(self.structures.fields.grid_shape)
        return None

    def view_grid(self) -> tuple | None:
        """The grid the picture's cell coordinates refer to: the growth grid, else the fields'."""
        grid = self.growth_grid()
        if grid is None and self.fields is not None:
            grid = tuple(self.fields.grid_shape)
        return grid

    @property
    def axis(self) -> str:
        return self.slice_row.axis

    @property
    def index(self) -> int | None:
        """Layer of the view grid along the slice axis (None in 2D)."""
        return self.slice_row.index

    def set_slice(self, axis: str, index: int | None = None) -> None:
        """Show the slice normal to ``axis`` at layer ``index`` of the view grid."""
        self.slice_row.set_slice(axis, index)

    def set_view(self, key: str) -> None:
        keys = [self.view_box.itemData(i) for i in range(self.view_box.count())]
        self.view_box.setCurrentIndex(keys.index(key))

    @property
    def view(self) -> str:
        return self.view_box.currentData() or "rho"

    def _layer(self, source_shape) -> int | None:
        """The layer of a grid of ``source_shape`` under the current slice of the view grid."""
        if len(source_shape) != 3:
            return None
        g = {"z": 0, "y": 1, "x": 2}[self.axis]
        return rescale_index(self.index, self.view_grid()[g], source_shape[g])

    def _to_view(self, source_shape) -> np.ndarray:
        """(2,) factors from a source grid's slice cells to the view grid's slice cells."""
        n_v, n_u = slice_shape(source_shape, self.axis)
        m_v, m_u = slice_shape(self.view_grid(), self.axis)
        return np.array([m_u / n_u, m_v / n_v])

    # -- pictures -----------------------------------------------------------------------------
    def _iso(self) -> float:
        grow = self._node("RDGrow")
        if grow is not None:
            return float(grow.params.get("iso", 0.5))
        return float(self.structures.iso) if self.structures is not None else 0.5

    def _magnitude_range(self, fields) -> tuple | None:
        if fields is None or fields.magnitude is None:
            return None
        key, rng = self._magnitude_cache
        if key is not fields:
            m = np.asarray(fields.magnitude[..., 0])
            rng = (float(m.min()), float(m.max()) if m.max() > m.min() else float(m.min()) + 1.0)
            self._magnitude_cache = (fields, rng)
        return rng

    def _structure_source(self, data):
        """(s (n,) + grid, directions) to show: the live growth, else the node's output."""
        live = data.get("live")
        if live is not None:
            return live.s, tuple(live.directions)
        st = data.get("structures")
        return (None, ()) if st is None else (st.s, tuple(st.directions))

    def picture(self, data: dict, key: str) -> dict | None:
        """What view ``key`` shows of ``data`` on the current slice:
        ``{values, source, index, rgb, scale, segments, colours, lines, glyphs, note}``; None
        when there is nothing to show."""
        fields = data.get("fields")
        out = {"segments": None, "colours": None, "lines": [], "glyphs": None, "note": "", "scale": None}
        if key in ("rho", "gamma") or key.startswith("tensor"):
            if fields is None:
                return None
            index = self._layer(fields.grid_shape)
            axis = self.axis
            rho = np.asarray(grid_slice(fields.rho, axis, index or 0))
            out.update(source="fields", index=index)
            if key == "gamma":
                out["values"] = np.asarray(grid_slice(fields.gamma, axis, index or 0))
                out["scale"] = (colour_lut("magma"), 0.0, 1.0, "Gamma")
                out["rgb"] = apply_lut(out["values"], 0.0, 1.0, out["scale"][0])
            elif key == "rho":
                out["values"] = rho
                out["scale"] = (colour_lut("Greys"), 0.0, 1.0, "rho")
                out["rgb"] = apply_lut(rho, 0.0, 1.0, out["scale"][0])
            else:
                out["values"] = rho
                out["rgb"] = apply_lut(rho, 0.0, 3.5, colour_lut("Greys"))   # a light background
                self._tensor_overlay(fields, int(key[-1]), index, out)
            return out
        s, dirs = self._structure_source(data)
        if key == "combined":
            compiled = data.get("compiled")
            if compiled is not None and data.get("live") is None:
                grid = tuple(compiled.grid_shape)
                index = self._layer(grid)
                values = np.asarray(grid_slice(compiled.values, self.axis, index or 0, ndim=len(grid)))
                out["note"] = "RDCompile density"
            elif s is not None:
                index = self._layer(s.shape[1:])
                values = np.asarray(grid_slice(np.max(s, axis=0), self.axis, index or 0))
                out["note"] = "union max_i s_i (RDCompile's result once evaluated)" if data.get("live") is None \
                    else "live: union max_i s_i"
            else:
                return None
        else:
            i = int(key[-1])
            if s is None:
                return None
            if i not in dirs:
                out["note"] = f"the {ORDINAL[i]} direction is not grown (RDGrow directions)"
                return None
            index = self._layer(s.shape[1:])
            values = np.asarray(grid_slice(s[dirs.index(i)], self.axis, index or 0))
            out["note"] = "live growth" if data.get("live") is not None else ""
        out.update(source="growth", index=index, values=values)
        out["scale"] = (colour_lut("Greys"), 0.0, 1.0, "s")
        out["rgb"] = apply_lut(values, 0.0, 1.0, out["scale"][0])
        return out

    def _tensor_overlay(self, fields, direction: int, index, out: dict) -> None:
        axis = self.axis
        mask = np.asarray(fields.rho) >= self._iso()
        magnitude = None if fields.magnitude is None else fields.magnitude[..., 0]
        factors = self._to_view(fields.grid_shape)
        if self.style_box.currentData() == "streamlines":
            lines = principal_streamlines(fields.rotation, direction=direction, mask=mask, axis=axis,
                                          index=index or 0, count=GLYPHS)
            out["lines"] = [line * factors for line in lines]
            return
        g = principal_glyphs(fields.rotation, direction=direction, magnitude=magnitude, mask=mask, axis=axis,
                             index=index or 0, count=GLYPHS)
        out["glyphs"] = g
        n_v, n_u = slice_shape(fields.grid_shape, axis)
        spacing = max(n_v, n_u) / GLYPHS * float(factors.mean())
        out["segments"] = glyph_segments(g.centres * factors, g.vectors * factors / factors.mean(),
                                         0.8 * spacing)
        rng = self._magnitude_range(fields)
        if rng is not None:
            lut = colour_lut("viridis")
            out["colours"] = apply_lut(g.values, *rng, lut)
            out["scale"] = (lut, rng[0], rng[1], "|sigma_1|")

    def redraw(self) -> None:
        """Draw the current view, slice and comparison from the data held."""
        if self.canvas.in_stroke:
            self.canvas.abort_stroke()      # a stroke lives on one picture; aborting redraws
            return
        grid = self.view_grid()
        self.style_box.setEnabled(self.view.startswith("tensor"))
        pic = None if grid is None else self.picture(self._data(), self.view)
        if pic is None:
            self.shown_values, self.shown_source, self.shown_index = None, "", None
            self.canvas.set_image(None)
            self.canvas.set_segments(None)
            self.canvas.set_polylines([])
            self.canvas.set_before(None)
            self.canvas.set_scale(None)
            self.canvas.set_painting(False)
            self.canvas.placeholder = NO_CHAIN if grid is None else "nothing to show here yet: evaluate the graph"
            self.canvas.update()
            return
        n_v, n_u = slice_shape(grid, self.axis)
        u, v = PLANE_AXES[self.axis]
        self.canvas.axis_names = ("xyz"[u], "xyz"[v])
        self.canvas.set_grid_extent(n_u, n_v)
        self.shown_values, self.shown_source, self.shown_index = pic["values"], pic["source"], pic["index"]
        self.canvas.set_image(pic["rgb"])
        if pic["scale"] is not None:
            self.canvas.set_scale(*pic["scale"])
        else:
            self.canvas.set_scale(None)
        self.canvas.set_segments(pic["segments"], pic["colours"])
        self.canvas.set_polylines(pic["lines"])
        self.glyphs = pic["glyphs"]
        self._set_note(pic["note"])
        self._draw_before()
        self._update_marks()
        reason = self.paint_block_reason()
        self.canvas.set_painting(reason is None)
        self.canvas.setToolTip(reason or "")

    def _draw_before(self) -> None:
        mode = self.compare_box.currentData()
        before = None
        if self.before is not None and mode != "now":
            pic = self.picture(self.before, self.view)
            if pic is not None and pic["rgb"].shape == self.canvas.rgb.shape:
                before = pic["rgb"]
        self.canvas.set_before(before)
        self.canvas.set_compare(mode, self.split_slider.value() / 100.0)
        if mode != "now" and before is None:
            self._set_note("nothing to compare yet: the view before the last edit is kept from the next stroke on")

    def _on_compare_changed(self, *_args) -> None:
        self._draw_before()

    def _set_note(self, text: str) -> None:
        self.note.setText(text)

    # -- brush ----------------------------------------------------------------------------------
    @property
    def brush_mode(self) -> str:
        return self.brush.mode

    def _brush_target(self) -> tuple:
        """(node kind, parameter) a stroke of the current mode appends to."""
        return ("RDFields", "gamma_c") if self.brush_mode == "solid" else ("RDGrow", "edits")

    def _cells_per_view(self) -> np.ndarray:
        """(d,) factors from view-grid cells to the brush target's cells, (x, y[, z]) order."""
        grid = np.array(self.view_grid()[::-1], float)
        if self.brush_mode != "solid":
            return np.ones_like(grid)
        return np.array(self.fields.grid_shape[::-1], float) / grid

    def brush_error(self) -> str | None:
        """The node's refusal of the current brush settings (as an item it would store), or None."""
        from engine.graph.errors import ParamError
        from engine.graph.node import node_type

        kind, name = self._brush_target()
        r = self.radius_spin.value()
        d = len(self.view_grid() or (0, 0))
        if self.brush_mode == "solid":
            item = [[{"centre": [0.5] * d, "radius": r, "value": self.value_spin.value()}]]
        else:
            item = [{"mode": self.brush_mode, "centre": [0.5] * d, "radius": r}]
        try:
            node_type(kind).param(name).coerce(item)
        except (ParamError, ValueError) as exc:
            return str(exc)
        return None

    def paint_block_reason(self) -> str | None:
        """Why painting is off now, or None when it is on."""
        kind, _ = self._brush_target()
        if self.undo is None:
            return "painting is off: the dock has no undo history to record strokes"
        if self._node(kind) is None:
            return f"no {kind} node in this chain to paint on"
        if self.view_grid() is None or self.fields is None:
            return "painting needs evaluated RD fields: evaluate the graph"
        return None

    def _on_brush_changed(self) -> None:
        self.canvas.brush_mode = self.brush_mode
        r = self.radius_spin.value()
        if self.brush_mode == "solid" and self.fields is not None and self.view_grid() is not None:
            r = r / float(self._cells_per_view()[0])
        self.canvas.brush_radius = max(r, 0.0)
        error = self.brush_error() if self.view_grid() is not None else None
        self.message.setText("" if error is None else f"<span style='color:#c0392b'>{error}</span>")
        if self.view_grid() is not None:
            reason = self.paint_block_reason()
            self.canvas.set_painting(reason is None)
            self.canvas.setToolTip(reason or "")
        self._update_marks()

    def _view_point(self, u: float, v: float) -> np.ndarray:
        """(x, y[, z]) in view-grid cells of the in-plane point (u, v) of the current slice."""
        return slice_point(u, v, self.axis, self.index)

    def _on_stroke_began(self, u: float, v: float) -> None:
        error = self.brush_error() or self.paint_block_reason()
        if error is not None:
            self.message.setText(f"<span style='color:#c0392b'>not painted: {error}</span>")
            self._stroke = None
            self.canvas.abort_stroke()
            return
        self._stroke = [(u, v)]
        self.canvas.set_trail(np.array(self._stroke))

    def _on_stroke_moved(self, u: float, v: float) -> None:
        if self._stroke is None:
            return
        lu, lv = self._stroke[-1]
        if np.hypot(u - lu, v - lv) * self.canvas._px_per_mm() < MIN_STEP_PX:
            return
        self._stroke.append((u, v))
        self.canvas.set_trail(stroke_centres(self._stroke, max(self.canvas.brush_radius, 1e-3)))

    def _on_stroke_aborted(self) -> None:
        self._stroke = None
        self.canvas.set_trail(None)
        self.redraw()

    def _on_stroke_ended(self, u: float, v: float) -> None:
        points, self._stroke = self._stroke, None
        self.canvas.set_trail(None)
        if points is None:
            return
        if (u, v) != points[-1]:
            points.append((u, v))
        kind, name = self._brush_target()
        node = self._node(kind)
        r = float(self.radius_spin.value())
        cells = np.array([self._view_point(pu, pv) for pu, pv in points]) * self._cells_per_view()
        centres = np.round(stroke_centres(cells, r), 4).tolist()
        old = list(node.params.get(name, []))
        if self.brush_mode == "solid":
            value = old + [[{"centre": c, "radius": r, "value": float(self.value_spin.value())} for c in centres]]
        else:
            value = old + [{"mode": self.brush_mode, "centres": centres, "radius": r}]
        before = self._data()
        if not self._push(node.id, name, value):
            self.redraw()
            return
        self.before = before
        what = "solid region marked" if self.brush_mode == "solid" else f"{self.brush_mode} stroke added"
        self.message.setText(f"{what} ({len(centres)} stamps); evaluate to regrow")
        self.redraw()

    def _update_marks(self) -> None:
        """Outline the stamps in the document (view-grid cells) where they cross the slice."""
        grid = self.view_grid()
        if grid is None or self.fields is None:
            self.canvas.set_marks([])
            return
        grow, fnode = self._node("RDGrow"), self._node("RDFields")
        to_view = np.array(grid[::-1], float) / np.array(self.fields.grid_shape[::-1], float)
        items = []
        for e in grow.params.get("edits", []) if grow is not None else ():
            items += [(p, float(e["radius"]), e["mode"]) for p in ([e["centre"]] if "centre" in e else e["centres"])]
        for stroke in fnode.params.get("gamma_c", []) if fnode is not None else ():
            items += [(np.asarray(st["centre"]) * to_view, float(st["radius"]) * to_view[0], "solid")
                      for st in stroke if len(st["centre"]) == len(grid)]
        self.canvas.set_stamps(items[-MAX_MARKS:], self.axis, self.index)

    # -- live growth ------------------------------------------------------------------------------
    def _live_job(self, every: int):
        """The growth the RDGrow node would run now (`ui.rd_worker.live_growth`), or None."""
        from engine.graph.node import node_seed

        from .rd_worker import live_growth

        grow = self._node("RDGrow")
        if grow is None or self.fields is None:
            return None
        try:
            job = live_growth(self.fields, dict(grow.params), seed=node_seed(self.doc.seed, grow.id), every=every)
        except Exception as exc:    # the node's refusal (NodeInputError, GrowthInputError)
            raise ValueError(str(exc)) from None
        if grow.params.get("edits"):
            self.message.setText("growing from the seeds; the brush edits are applied by the node's "
                                 "local regrowth (Apply)")
        return job

    def start_live(self) -> bool:
        """Grow the RDGrow node's structures live from its seeds; False (with a message) if impossible."""
        return self.live_box.start()

    def pause_live(self) -> None:
        self.live_box.pause()

    def resume_live(self) -> bool:
        return self.live_box.resume()

    def cancel_live(self) -> None:
        self.live_box.cancel()

    def _on_apply(self) -> None:
        """The node's evaluation is the truth: drop the live picture, ask for an evaluation."""
        self.live = None
        self.redraw()
        self.message.setText("evaluating the document: the RDGrow node's result replaces the live view")
        self.evaluate_requested.emit()

    def _on_live_frame(self, frame) -> None:
        self.live = frame
        if self.view.startswith("s") or self.view == "combined":
            self.redraw()

    def _update_live_buttons(self) -> None:
        self.live_box.update_buttons(self._node("RDGrow") is not None and self.fields is not None)

    def shutdown(self) -> None:
        """Stop the growth thread and stop following the document (the window is closing)."""
        if self.doc is not None:
            self.doc.unsubscribe(self._on_doc_event)
        self.live_box.shutdown()
