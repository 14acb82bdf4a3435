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

"Grow live" runs the RDGrow node's own growth session
(`engine.nodes.rd_session.RDGrowthSession`) on a task runner
(`ui.rd_worker`), drawing every N steps with the step count and ``G^t``;
Pause / Resume continue exactly, Cancel keeps the last complete step.
The live run never changes the document; "Apply" asks the window to
evaluate it (signal ``evaluate_requested``), first handing a growth run to
the end with the node's current parameters, seed and input to the window's
evaluator as the node's result (`LiveGrowthBox.adopt`, `Evaluator.adopt`):
RDGrow is then "cached" and only RDCompile evaluates.

A left drag on the picture is one brush stroke (Escape abandons it): erase
or draw appends ONE edit ``{mode, centres, radius}`` in growth-grid cells
to the RDGrow node's ``edits``, mark solid ONE stroke of stamps
``{centre, radius, value}`` in field cells to the RDFields node's
``gamma_c``, each as one ``SetParam`` on the undo stack (`ui.rd_brush_tool`).

This module wires the pieces: the control rows (`ui.rd_view_controls`), the
pictures (`ui.rd_pictures`), the brush (`ui.rd_brush_tool`), the live
growth box (`ui.rd_live_box`) and the canvas (`ui.rd_canvas`).
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.graph import SetParam
from engine.graph.query import chain_around
from engine.geometry.values import Field
from engine.rd.values import RDFieldsValue, RDStructuresValue
from engine.rd.preview import PLANE_AXES, slice_shape

from .rd_brush_tool import RDBrushTool
from .rd_chain import CHAIN, NO_CHAIN, caption_text, chain_outputs, fields_of_design, painted
from .rd_canvas import BrushBox, RDCanvas, SliceRow
from .rd_live_box import LiveGrowthBox
from .rd_pictures import RDPictures
from .rd_view_controls import CompareRow, SourceRow, ViewRow


def pick_rd_chain(doc, selected, previous=None) -> dict:
    """``{type name: node id or None}`` of the RD chain around ``selected`` (`chain_around`'s rule)."""
    return chain_around(doc, selected, CHAIN, previous=previous)


class RDPanel(QtWidgets.QWidget):
    """Dock content: RD fields and structures on a paintable slice, live growth, before / after.

    Parameters
    ----------
    doc : GraphDocument; undo : UndoStack over it (strokes are pushed there)
    parent : the main window (it sets ``live_box.adopt_result`` to its ``adopt_result``, `ui.window_evaluation`)

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
        self._outputs_key = None
        self._shown_painted = (None, None)
        self.pictures = RDPictures(self)

        self._build()
        if doc is not None:
            doc.subscribe(self._on_doc_event)
        self.brush_tool.on_brush_changed()
        self._sync_source()
        self._update_live_buttons()

    # -- widgets ------------------------------------------------------------------------------
    def _build(self) -> None:
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel(NO_CHAIN)
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)

        self.source_row = SourceRow()
        self.source_row.preset_chosen.connect(self._on_preset)
        self.source_row.import_clicked.connect(lambda: self.import_fields())
        self.preset_box, self.import_button = self.source_row.preset_box, self.source_row.import_button
        lay.addWidget(self.source_row)

        self.view_row = ViewRow()
        self.view_row.changed.connect(self.redraw)
        self.view_box, self.style_box = self.view_row.view_box, self.view_row.style_box
        lay.addWidget(self.view_row)

        self.slice_row = SliceRow()
        self.slice_row.changed.connect(self.redraw)
        self.axis_box, self.index_slider = self.slice_row.axis_box, self.slice_row.slider
        lay.addWidget(self.slice_row)

        self.canvas = RDCanvas()
        lay.addWidget(self.canvas, 3)
        self.note = QtWidgets.QLabel("")
        self.note.setWordWrap(True)
        lay.addWidget(self.note)

        self.compare_row = CompareRow()
        self.compare_row.changed.connect(self._draw_before)
        self.compare_box, self.split_slider = self.compare_row.compare_box, self.compare_row.split_slider
        lay.addWidget(self.compare_row)

        self.live_box = LiveGrowthBox(self)
        self.live_box.session_factory = self._live_session
        self.live_box.frame.connect(self._on_live_frame)
        self.live_box.apply_requested.connect(self._on_apply)
        self.live_box.message.connect(lambda text: self.message.setText(text))
        self.worker = self.live_box.worker
        # the controls under their usual names
        self.every_spin, self.pause_button = self.live_box.every_spin, self.live_box.pause_button
        self.apply_button, self.live_label = self.live_box.apply_button, self.live_box.label
        lay.addWidget(self.live_box)
        self.brush = BrushBox()
        self.mode_box, self.radius_spin, self.value_spin = (self.brush.mode_box, self.brush.radius_spin,
                                                             self.brush.value_spin)
        lay.addWidget(self.brush)
        self.message = QtWidgets.QLabel("")
        self.message.setWordWrap(True)
        lay.addWidget(self.message)
        self.brush_tool = RDBrushTool(self)

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
        design, fields, structures, compiled = chain_outputs(outputs, chain)
        key = (tuple(chain.values()), id(design), id(fields), id(structures), id(compiled))
        if key == self._outputs_key:
            return
        self._outputs_key = key
        if fields is None and design is not None:
            fields = fields_of_design(design)
        brush_data = painted(self.doc, chain)
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
            if brush_data != self._shown_painted and (self.fields is not None or self.structures is not None):
                self.before = self.data()    # the brush data changed: what was shown is "before"
        self._shown_painted = brush_data
        if self.canvas.in_stroke:
            self.canvas.abort_stroke()
        self.chain = chain
        self.design, self.fields, self.structures, self.compiled = design, fields, structures, compiled
        d = self._ndim()
        self.view_row.fill(d or 2)
        self.slice_row.set_grid(self.view_grid())
        self._update_caption()
        self._sync_source()
        self.redraw()
        self._update_live_buttons()

    def _sync_source(self) -> None:
        """The preset box shows the TopOpt node's preset; import needs an RDFields node."""
        self.source_row.sync(self.node_of("TopOpt"), self.node_of("RDFields") is not None and self.undo is not None)

    def _on_preset(self, name: str) -> None:
        topopt = self.node_of("TopOpt")
        if topopt is not None and self.undo is not None and topopt.params.get("preset") != name:
            self.push_param(topopt.id, "preset", name)

    def import_fields(self, path: str | None = None) -> bool:
        """Point the RDFields node at a field file (asks for one without ``path``): one SetParam."""
        fnode = self.node_of("RDFields")
        if fnode is None or self.undo is None:
            self.message.setText("importing needs an RDFields node in the chain")
            return False
        if path is None:
            path, _ = QtWidgets.QFileDialog.getOpenFileName(self, "Import RD fields", "",
                                                            "Field files (*.npz *.vti)")
            if not path:
                return False
        if not self.push_param(fnode.id, "path", str(path)):
            return False
        if self.doc.inputs_of(fnode.id):
            self.message.setText("the connected design is used while one is connected; "
                                 "disconnect it to grow on the imported fields")
        return True

    def push_param(self, node_id: str, name: str, value) -> bool:
        """One SetParam on the undo stack; False (with the refusal shown) when the document refuses it."""
        try:
            self.undo.push(SetParam(node_id, name, value))
        except Exception as exc:   # refused by the document: nothing changed
            self.message.setText(f"<span style='color:#c0392b'>not changed: {exc}</span>")
            return False
        return True

    def data(self) -> dict:
        """What is shown now: fields, structures, compiled density, live frame."""
        return {"fields": self.fields, "structures": self.structures, "compiled": self.compiled,
                "live": self.live}

    def _ndim(self) -> int | None:
        shown = self.fields if self.fields is not None else self.structures
        return None if shown is None else shown.ndim

    def node_of(self, kind):
        """The chain's node of type ``kind`` (a Node), or None."""
        nid = self.chain.get(kind)
        return self.doc.nodes.get(nid) if self.doc is not None and nid else None

    def _update_caption(self) -> None:
        nodes = self.doc.nodes if self.doc is not None else {}
        self.caption.setText(caption_text(nodes, self.chain, self.fields, self.structures, self.growth_grid()))

    def _on_doc_event(self, event: str, payload) -> None:
        try:
            if event == "param_changed" and payload[0] in self.chain.values():
                self._update_caption()
                self._sync_source()
                if payload == (self.chain["RDGrow"], "resolution"):   # the view grid changed
                    self.slice_row.set_grid(self.view_grid())
                    self.redraw()
                else:
                    self.brush_tool.update_marks()
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
        grow = self.node_of("RDGrow")
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
        self.view_row.set_view(key)

    @property
    def view(self) -> str:
        return self.view_row.view

    @property
    def direction_style(self) -> str:
        """How the principal directions are drawn: "glyphs" or "streamlines"."""
        return self.view_row.style

    def iso(self) -> float:
        """The infill space threshold (rho >= iso) of the RDGrow node, else of the structures."""
        grow = self.node_of("RDGrow")
        if grow is not None:
            return float(grow.params.get("iso", 0.5))
        return float(self.structures.iso) if self.structures is not None else 0.5

    # -- pictures -----------------------------------------------------------------------------
    def picture(self, data: dict, key: str) -> dict | None:
        """What view ``key`` shows of ``data`` on the current slice (`ui.rd_pictures.RDPictures`)."""
        return self.pictures.picture(data, key)

    # -- brush --------------------------------------------------------------------------------
    @property
    def brush_mode(self) -> str:
        return self.brush.mode

    def brush_error(self) -> str | None:
        """The node's refusal of the current brush settings, or None."""
        return self.brush_tool.brush_error()

    def paint_block_reason(self) -> str | None:
        """Why painting is off now, or None when it is on."""
        return self.brush_tool.paint_block_reason()

    def redraw(self) -> None:
        """Draw the current view, slice and comparison from the data held."""
        if self.canvas.in_stroke:
            self.canvas.abort_stroke()      # a stroke lives on one picture; aborting redraws
            return
        grid = self.view_grid()
        self.style_box.setEnabled(self.view.startswith("tensor"))
        pic = None if grid is None else self.picture(self.data(), self.view)
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
        self.brush_tool.update_marks()
        reason = self.paint_block_reason()
        self.canvas.set_painting(reason is None)
        self.canvas.setToolTip(reason or "")

    def _draw_before(self) -> None:
        mode = self.compare_row.mode
        before = None
        if self.before is not None and mode != "now":
            pic = self.picture(self.before, self.view)
            if pic is not None and pic["rgb"].shape == self.canvas.rgb.shape:
                before = pic["rgb"]
        self.canvas.set_before(before)
        self.canvas.set_compare(mode, self.compare_row.split)
        if mode != "now" and before is None:
            self._set_note("nothing to compare yet: the view before the last edit is kept from the next stroke on")

    def _set_note(self, text: str) -> None:
        self.note.setText(text)

    # -- live growth ------------------------------------------------------------------------------
    def _live_session(self):
        """The growth session the RDGrow node would run now, or None; ValueError: the node refuses."""
        from engine.graph.node import node_seed
        from engine.nodes.rd_session import RDGrowthSession

        grow = self.node_of("RDGrow")
        if grow is None or self.fields is None:
            return None
        try:
            job = RDGrowthSession(self.fields, dict(grow.params), node_seed(self.doc.seed, grow.id))
        except Exception as exc:    # the node's refusal (NodeInputError)
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
        """Drop the live picture, hand over a finished growth (`LiveGrowthBox.adopt`), evaluate."""
        self.live = None
        self.redraw()
        self.message.setText("evaluating: the live growth is offered as the RDGrow node's result"
                             if self.live_box.adopt(self.node_of("RDGrow"), self.doc) else
                             "evaluating the document: the RDGrow node's result replaces the live view")
        self.evaluate_requested.emit()

    def _on_live_frame(self, frame) -> None:
        self.live = frame
        if self.view.startswith("s") or self.view == "combined":
            self.redraw()

    def _update_live_buttons(self) -> None:
        self.live_box.update_buttons(self.node_of("RDGrow") is not None and self.fields is not None)

    def shutdown(self) -> None:
        """Stop the growth thread and stop following the document (the window is closing)."""
        if self.doc is not None:
            self.doc.unsubscribe(self._on_doc_event)
        self.live_box.shutdown()
