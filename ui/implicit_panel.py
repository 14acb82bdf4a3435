"""The "Implicit Media" dock: the sphere-traced view of an SDF node, its parameters, its
particle sizes and volume fraction.

The dock follows the selection (`engine.graph.query.pick_node`: the selected node if it has an
SDF output, else the nearest such node above it, else the previous one) and shows, from the
latest evaluation (slot :meth:`ImplicitPanel.set_report`):

* the SDF traced by `engine.nodes.sdf_preview.SDFPreview` (the object `mesoforge sdf --render`
  uses) in a `TraceView`: drag to orbit, wheel to zoom, quick half-size frames while dragging;
  the step rule and N, with the frame time, steps per ray and re-traced rays under it;
* "Path trace": progressive frames of the path tracer, each shown as it lands, cancellable;
* the node's parameters (`ParamForm`: one ``SetParam`` per edit, refusals at the field), so an
  edit re-evaluates and the view follows;
* the solid volume fraction of the view box and the particle size histogram of a suspension;
* "Fit to an exemplar" (`ui.implicit_fit.FitBox`): the node's parameters fitted to a grid, or
  to an image taken at this view, applied as one undo step when asked;
* for a Scalar Field node (a density / offset field, no SDF) instead of the view: its paint
  canvas (`ui.implicit_paint.FieldPaintBox`): a slice of the field, and each brush drag one
  ``SetParam(node, "strokes", old + [stroke])`` on the undo stack.

Every trace and measurement runs in a `TaskRunner` (a burst of view changes traces only the
last); the GUI thread only draws.
"""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from engine.graph import all_node_types
from engine.graph.query import pick_node
from engine.implicit.values import SDF
from engine.nodes.sdf_preview import SDFPreview, fallback_box_for, orbit_direction, preview_param

from .colours import STATUS_COLOURS
from .implicit_fit import FitBox
from .implicit_paint import PAINTABLE, FieldPaintBox
from .implicit_plots import SizeHistogram
from .implicit_view import TraceView
from .param_form import ParamForm
from .task_runner import TaskRunner
from .tool_number import ToolNumber

MOVING_SCALE = 0.5          # frames while dragging: half the size
VOLUME_RESOLUTION = 48      # samples per axis of the view box's volume fraction


def sdf_node_types() -> frozenset[str]:
    """Node types with an SDF output."""
    return frozenset(name for name, cls in all_node_types().items() if any(p.type == "SDF" for p in cls.outputs))


def _trace(preview, camera, size, step, every, max_steps):
    def run(task):
        r = preview.trace(camera, width=size[0], height=size[1], step=step, adaptive_every=every,
                          max_steps=max_steps, check=task.check)
        return {"rgba": r.rgba, "frame_ms": r.frame_ms, "mean_steps": r.mean_steps, "max_steps": r.max_steps,
                "retraced": int(r.retraced.sum()), "hit": float(r.hit.mean())}
    return run


def _path_trace(preview, camera, size, frames, depth):
    def run(task):
        def on_frame(k, image):
            task.check()
            task.progress(k, frames)
            task.publish({"rgba": image, "frame": k})
        r = preview.path_trace(camera, width=size[0], height=size[1], paths=frames, max_depth=depth,
                               check=task.check, on_frame=on_frame)
        return {"rgba": r.rgba, "frames": r.frames, "mean_depth": r.mean_depth}
    return run


def _measure(preview):
    def run(task):
        sizes = preview.particle_sizes()
        task.check()
        return {"fraction": preview.volume_fraction(VOLUME_RESOLUTION), "sizes": sizes}
    return run


class ImplicitPanel(QtWidgets.QWidget):
    """Dock content for the implicit media nodes.

    Parameters
    ----------
    doc : GraphDocument; undo : UndoStack over it (parameter edits are pushed there)

    Signals
    -------
    message(str, str) : (level, text) for the log
    """

    message = QtCore.Signal(str, str)

    def __init__(self, doc, undo, parent=None, *, prompter=None):
        super().__init__(parent)
        self.doc, self.undo, self.prompter = doc, undo, prompter
        self.node_id: str | None = None
        self.outputs: dict = {}
        self.results: dict = {}
        self.sdf: SDF | None = None
        self.preview: SDFPreview | None = None
        self.last_trace: dict = {}
        self.measured: dict = {}
        self.traces = TaskRunner(self)
        self.traces.finished.connect(self._on_traced)
        self.traces.published.connect(self._on_path_frame)
        self.traces.failed.connect(lambda task, text: self._failed(text))
        self.traces.busy_changed.connect(lambda busy: self.cancel_button.setEnabled(busy))
        self.measures = TaskRunner(self)
        self.measures.finished.connect(self._on_measured)
        self.measures.failed.connect(lambda task, text: self._failed(text))
        self._build()
        doc.subscribe(self._on_doc_event)

    # -- layout ---------------------------------------------------------------------------------
    def _build(self) -> None:
        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(6, 6, 6, 6)
        self.title = QtWidgets.QLabel("")
        self.title.setWordWrap(True)
        outer.addWidget(self.title)
        self.readout = QtWidgets.QLabel("")
        self.readout.setWordWrap(True)
        self.readout.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        self.sdf_box = QtWidgets.QWidget(self)      # what an SDF node shows; hidden for a field
        sdf = QtWidgets.QVBoxLayout(self.sdf_box)
        sdf.setContentsMargins(0, 0, 0, 0)
        self.view = TraceView(self)
        self.view.view_changed.connect(lambda moving: self.request_trace(moving=moving))
        sdf.addWidget(self.view, 1)
        sdf.addWidget(self.readout)

        controls = QtWidgets.QFormLayout()
        self.step_box = QtWidgets.QComboBox()
        step = preview_param("step")
        for choice in step.choices:
            self.step_box.addItem(choice, choice)
        self.step_box.setCurrentIndex(self.step_box.findData(step.default))
        self.step_box.setToolTip(step.doc)
        self.step_box.currentIndexChanged.connect(lambda _i: self.request_trace())
        controls.addRow("step", self.step_box)
        self.every_box = ToolNumber(preview_param("adaptive_every"))
        self.every_box.valueChanged.connect(lambda _v: self.request_trace())
        controls.addRow("N (adaptive)", self.every_box)
        self.paths_box = ToolNumber(preview_param("paths"))
        self.paths_box.setValue(16)
        controls.addRow("path frames", self.paths_box)
        self.depth_box = ToolNumber(preview_param("max_depth"))
        controls.addRow("max depth", self.depth_box)
        sdf.addLayout(controls)
        row = QtWidgets.QHBoxLayout()
        self.path_button = QtWidgets.QPushButton("Path trace")
        self.path_button.setToolTip("accumulate path-traced frames of this view (Monte Carlo)")
        self.path_button.clicked.connect(self.start_path_trace)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(self.traces.cancel)
        row.addWidget(self.path_button)
        row.addWidget(self.cancel_button)
        sdf.addLayout(row)

        self.fraction_label = QtWidgets.QLabel("volume fraction: —")
        sdf.addWidget(self.fraction_label)
        self.histogram = SizeHistogram(self)
        sdf.addWidget(self.histogram)
        outer.addWidget(self.sdf_box, 1)
        self.paint_box = FieldPaintBox(self.doc, self.undo, self)
        self.paint_box.message.connect(self.message.emit)
        self.paint_box.setVisible(False)
        outer.addWidget(self.paint_box, 1)
        self.params_box = QtWidgets.QGroupBox("Parameters")
        self.form = QtWidgets.QFormLayout(self.params_box)
        self.form.setFieldGrowthPolicy(QtWidgets.QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        self.param_form = ParamForm(self.doc, self.undo, self.form, self)
        self.param_form.message.connect(self.message.emit)
        outer.addWidget(self.params_box)
        self.fit_box = FitBox(self.doc, self.undo, self.prompter, view=self.fit_view, parent=self)
        self.fit_box.message.connect(self.message.emit)
        outer.addWidget(self.fit_box)
        self._show_node()

    # -- which node -----------------------------------------------------------------------------
    def _accept(self, node_id: str) -> bool:
        node = self.doc.nodes.get(node_id)
        return node is not None and (node.type_name in sdf_node_types() or node.type_name in PAINTABLE)

    @QtCore.Slot(object)
    def set_selected(self, node_id) -> None:
        """Follow the editor's selection (`pick_node`)."""
        picked = pick_node(self.doc, node_id, self._accept, previous=self.node_id)
        if picked != self.node_id:
            self.node_id = picked
            self._show_node()

    @QtCore.Slot(object)
    def set_report(self, report) -> None:
        """Take the outputs of a finished evaluation (an EvalReport)."""
        if report is None or getattr(report, "cancelled", False):
            return
        self.outputs, self.results = dict(report.outputs), dict(report.results)
        if self.node_id is None:
            self.node_id = pick_node(self.doc, None, self._accept)
        self._show_node()

    def _show_node(self) -> None:
        nid = self.node_id if self.node_id in self.doc.nodes else None
        self.node_id = nid
        self.params_box.setVisible(nid is not None)
        if self.param_form.node_id != nid or (nid is not None and not self.param_form.editors):
            cls = all_node_types()[self.doc.nodes[nid].type_name] if nid else None
            self.param_form.show_node(nid, cls.params if cls else ())
        painted = nid is not None and self.doc.nodes[nid].type_name in PAINTABLE
        self.sdf_box.setVisible(not painted)
        self.fit_box.setVisible(not painted)
        self.paint_box.setVisible(painted)
        if nid is None:
            self.fit_box.set_node(None, {})
            self.paint_box.set_field(None, None, {})
            self.title.setText("No node with an SDF output: add Particles, Periodic Function, Agglomerate "
                               "or Pile (Tab in the node graph), or a Scalar Field to paint.")
            self._set_sdf(None, "select a node with an SDF output")
            return
        node = self.doc.nodes[nid]
        self.title.setText(f"<b>{node.type_name}</b> · {nid}")
        if painted:
            self._show_field(nid, node)
            return
        self.paint_box.set_field(None, None, {})
        self.fit_box.set_node(nid, self.node_inputs())
        result = self.results.get(nid)
        value = (self.outputs.get(nid) or {}).get("sdf")
        if result is not None and getattr(result, "status", "") == "failed":
            colour = STATUS_COLOURS["failed"]
            self.readout.setText(f"<span style='color:{colour}'>{result.error}</span>")
            self._set_sdf(None, "the node failed: see its message")
        elif isinstance(value, SDF):
            self._set_sdf(value, "")
        else:
            self._set_sdf(None, "not evaluated yet")

    def _show_field(self, nid: str, node) -> None:
        """A Scalar Field node: its paint canvas over the latest evaluated field."""
        self.fit_box.set_node(None, {})
        self._set_sdf(None, "")
        result = self.results.get(nid)
        field = (self.outputs.get(nid) or {}).get("field")
        failed = result is not None and getattr(result, "status", "") == "failed"
        self.paint_box.set_field(nid, None if failed else field, node.params)
        if failed:
            self.paint_box.status.setText(f"<span style='color:{STATUS_COLOURS['failed']}'>{result.error}</span>")

    def _set_sdf(self, sdf, note: str) -> None:
        if sdf is self.sdf and sdf is not None:
            return
        self.sdf = sdf
        self.traces.cancel()
        self.measures.cancel()
        if sdf is None:
            self.preview = None
            self.view.clear(note)
            self.fraction_label.setText("volume fraction: —")
            self.histogram.set_sizes(None, "no suspension")
            return
        try:
            self.preview = SDFPreview(sdf, fallback_box=fallback_box_for(self.doc, self.node_id))
        except ValueError as exc:
            self._set_sdf(None, str(exc))
            return
        self.request_trace()
        self.measures.submit(_measure(self.preview))

    def node_inputs(self) -> dict:
        """The evaluated inputs of the node shown (from the latest evaluation)."""
        if self.node_id is None:
            return {}
        return {e.dst_port: (self.outputs.get(e.src) or {}).get(e.src_port)
                for e in self.doc.edges if e.dst == self.node_id}

    def fit_view(self):
        """(camera, bounds) of the traced view, what an image exemplar is compared at; None
        before anything is traced."""
        if self.preview is None:
            return None
        lo, hi = self.preview.box
        return self.camera(), (tuple(lo), tuple(hi))

    # -- tracing --------------------------------------------------------------------------------
    def camera(self):
        direction = orbit_direction(self.view.azimuth, self.view.elevation)
        return self.preview.camera(preview_param("fov").default, direction, self.view.zoom)

    def request_trace(self, *, moving: bool = False) -> None:
        """Trace the current view (half size while `moving`); a newer request replaces a waiting one."""
        if self.preview is None:
            return
        size = self.view.frame_size(MOVING_SCALE if moving else 1.0)
        self.traces.submit(_trace(self.preview, self.camera(), size, self.step_box.currentData(),
                                  self.every_box.value(), preview_param("max_steps").default),
                           data="trace")

    def start_path_trace(self) -> None:
        if self.preview is None:
            return
        self.traces.submit(_path_trace(self.preview, self.camera(), self.view.frame_size(),
                                       self.paths_box.value(), self.depth_box.value()), data="paths")

    def _on_traced(self, task, result) -> None:
        self.view.show_frame(result["rgba"])
        if task.data == "paths":
            self.readout.setText(f"path traced: {result['frames']} frames · mean path depth "
                                 f"{result['mean_depth']:.2f}")
            return
        self.last_trace = result
        lip = self.sdf.lipschitz if self.sdf is not None else 1.0
        self.readout.setText(
            f"frame {result['frame_ms']:.1f} ms · {result['mean_steps']:.1f} steps/ray (max "
            f"{result['max_steps']}) · {result['retraced']} rays re-traced · hits {100 * result['hit']:.0f}% · "
            f"Lipschitz bound {lip:.4g}")

    def _on_path_frame(self, task, frame) -> None:
        self.view.show_frame(frame["rgba"])
        self.readout.setText(f"path tracing: frame {frame['frame'] + 1} of {self.paths_box.value()}")

    def _on_measured(self, task, result) -> None:
        self.measured = result
        self.fraction_label.setText(f"volume fraction of the view box: {result['fraction']:.4f}")
        sizes = result["sizes"]
        self.histogram.set_sizes(sizes, "no suspension in this SDF" if sizes is None else "")

    def _failed(self, text: str) -> None:
        self.readout.setText(f"<span style='color:{STATUS_COLOURS['failed']}'>{text}</span>")
        self.message.emit("warning", f"Implicit Media: {text}")

    # -- document -------------------------------------------------------------------------------
    def _on_doc_event(self, event: str, payload) -> None:
        if event == "reset":
            self.node_id, self.outputs, self.results = None, {}, {}
            self._show_node()
        elif event == "node_removed" and payload == self.node_id:
            self.node_id = None
            self._show_node()
        elif event == "param_changed" and payload[0] == self.node_id:
            self.param_form.on_param_changed(*payload)

    def wait_idle(self, timeout_ms: int = 60000) -> bool:
        return self.traces.wait_idle(timeout_ms) and self.measures.wait_idle(timeout_ms)

    def shutdown(self) -> None:
        self.fit_box.shutdown()
        self.traces.shutdown()
        self.measures.shutdown()
        self.histogram.shutdown()
