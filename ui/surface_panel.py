"""The "Surfaces" dock: what the Surface solvers did, and their key parameters.

The dock lists every Surface, Dual Surface and Associate Family node of the
graph; selecting one here selects it in the node editor and the other way
round (signal ``node_selected``, slot :meth:`SurfacePanel.set_selected`).
For the chosen node, from the latest evaluation (slot
:meth:`SurfacePanel.set_report`), it shows

* the Surface's ``SurfaceReport`` (solver, iterations, final energy, area,
  max and mean |H|, seconds, converged, warning) -- for a Dual Surface or an
  Associate Family the report of the Surface upstream of it;
* the node's error verbatim in red when its evaluation failed (the FBV
  requirement checks name the loop vertex and the rule);
* the energy after each solver step (``details["energy_history"]``);
* the boundary loop in its best-fit plane, sliding segments dashed, the
  vertex an error names ringed in red.

Each parameter edit is one ``SetParam`` on the undo stack (arrow ticks of
one parameter within a second merge, as in the inspector); "Solve again"
asks the window to evaluate (signal ``evaluate_requested``). The dock never
changes the document itself.
"""

from __future__ import annotations

import html
import re

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.graph import all_node_types
from engine.graph.errors import NodeInputError
from engine.graph.query import nearest_upstream, of_types, type_of
from engine.geometry.surfaces.values import SurfaceReport
from engine.nodes.surfaces import boundary_schematic

from .colours import STATUS_COLOURS
from .param_form import ParamForm
from .surface_plots import ConvergenceChart, LoopSchematic

SURFACE_NODE_TYPES = ("Surface", "DualSurface", "AssociateFamily")
# Parameters that only matter for some values of another one: name -> (other, values).
SHOWN_WHEN = {"alpha": ("type", {"direct"}), "fbv_planes": ("fbv", {"custom"})}
ERROR_STYLE = "color: #e04040;"
WARNING_STYLE = "color: #e0a030;"
_LOOP_VERTEX = re.compile(r"loop vertex (\d+)")


def _g(x) -> str:
    return f"{x:.6g}"


# (report field, row label, text of the value)
REPORT_ROWS = (
    ("solver", "solver", str),
    ("iterations", "iterations", str),
    ("energy", "final energy", _g),
    ("area", "area", lambda a: f"{a:.6g} cell²"),
    ("max_abs_H", "max |H|", lambda h: f"{h:.4g} /cell"),
    ("mean_abs_H", "mean |H|", lambda h: f"{h:.4g} /cell"),
    ("seconds", "seconds", lambda s: f"{s:.3f} s"),
    ("converged", "converged", lambda c: "yes" if c else "no"),
    ("warning", "warning", lambda w: w or "—"),
)


# -- reading the graph ------------------------------------------------------------------------
def surface_nodes(doc) -> list[str]:
    """Ids of the Surface, Dual Surface and Associate Family nodes, in document order."""
    return [nid for nid, node in doc.nodes.items() if node.type_name in SURFACE_NODE_TYPES]


def source_surface(doc, node_id: str | None) -> str | None:
    """The Surface node ``node_id`` is, or the nearest one upstream of it
    (``engine.graph.query``; no fallback: a node with no Surface above has none)."""
    if type_of(doc, node_id) == "Surface":
        return node_id
    return nearest_upstream(doc, node_id, of_types(doc, ("Surface",))) if node_id else None


def input_chains(doc, outputs: dict, surface_id: str):
    """The EdgeChain values feeding ``surface_id``'s ``chains`` port in ``outputs``, or None
    when one has no value (not evaluated yet, or failed)."""
    chains = []
    for e in doc.inputs_of(surface_id, "chains"):
        value = (outputs.get(e.src) or {}).get(e.src_port)
        if value is None:
            return None
        chains.append(value)
    return chains


def sliding_segments(solver: str, segment_chain, smooth, report: SurfaceReport | None) -> np.ndarray:
    """(k,) bool: which loop segments slide for a ``solver`` solve.

    conjugate: all; direct: none (the shell is pinned to its loop); mixed_minimal: the
    chains the report names as sliding, else (not solved yet) the smooth chains.
    """
    chain = np.asarray(segment_chain, dtype=np.int64)
    if solver == "conjugate":
        return np.ones(chain.size, bool)
    if solver != "mixed_minimal":
        return np.zeros(chain.size, bool)
    if report is not None and report.solver == solver and "sliding" in report.details:
        moving = {int(s["chain"]) for s in report.details["sliding"]}
    else:
        moving = {c for c, s in enumerate(smooth) if s}
    return np.isin(chain, sorted(moving))


def error_vertex(text: str) -> int | None:
    """The first loop vertex an error message names, or None."""
    m = _LOOP_VERTEX.search(text or "")
    return int(m.group(1)) if m else None


# -- the dock -------------------------------------------------------------------------------------
class SurfacePanel(QtWidgets.QWidget):
    """Dock content: surface nodes, their solve reports, convergence and boundary loop.

    Parameters
    ----------
    doc : GraphDocument; undo : UndoStack over it (parameter edits are pushed there)

    Signals
    -------
    node_selected(str) : the user picked a node in the list (select it in the editor)
    evaluate_requested() : "Solve again"
    message(str, str) : (level, text) for the log
    """

    node_selected = QtCore.Signal(str)
    evaluate_requested = QtCore.Signal()
    message = QtCore.Signal(str, str)

    def __init__(self, doc, undo, parent=None):
        super().__init__(parent)
        self.doc, self.undo = doc, undo
        self.node_id: str | None = None
        self.results: dict = {}
        self.outputs: dict = {}
        self._stale: set[str] = set()      # nodes edited since the report shown
        self._build()
        doc.subscribe(self._on_doc_event)
        self._refresh_list()

    # -- layout ---------------------------------------------------------------------------------
    def _build(self) -> None:
        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(6, 6, 6, 6)
        self.node_list = QtWidgets.QListWidget()
        self.node_list.setMaximumHeight(80)
        self.node_list.currentItemChanged.connect(self._on_list_pick)
        outer.addWidget(self.node_list)

        self.title = QtWidgets.QLabel("")
        self.title.setWordWrap(True)
        outer.addWidget(self.title)
        self.status_label = QtWidgets.QLabel("")
        self.status_label.setWordWrap(True)
        outer.addWidget(self.status_label)
        self.error_label = QtWidgets.QLabel("")
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet(ERROR_STYLE)
        self.error_label.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        self.error_label.hide()
        outer.addWidget(self.error_label)

        self.report_box = QtWidgets.QGroupBox("Solve")
        grid = QtWidgets.QGridLayout(self.report_box)
        grid.setHorizontalSpacing(10)
        self.report_labels: dict[str, QtWidgets.QLabel] = {}
        for k, (key, label, _) in enumerate(REPORT_ROWS):
            value = QtWidgets.QLabel("—")
            value.setWordWrap(True)
            value.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
            name = QtWidgets.QLabel(label)
            name.setStyleSheet("color: #777777;")
            row, col, span = (k // 2, 2 * (k % 2), 1) if key != "warning" else ((k + 1) // 2, 0, 3)
            grid.addWidget(name, row, col)
            grid.addWidget(value, row, col + 1, 1, span)
            self.report_labels[key] = value
        grid.setColumnStretch(1, 1)
        grid.setColumnStretch(3, 1)
        outer.addWidget(self.report_box)

        self.solve_button = QtWidgets.QPushButton("Solve again")
        self.solve_button.setToolTip("evaluate the graph now")
        self.solve_button.clicked.connect(self.evaluate_requested.emit)
        outer.addWidget(self.solve_button)

        self.params_box = QtWidgets.QWidget()
        self.form = QtWidgets.QFormLayout(self.params_box)
        self.form.setFieldGrowthPolicy(QtWidgets.QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        # the form is built when its tab shows (or a test asks for it): a hidden dock builds none
        self._param_form = ParamForm(self.doc, self.undo, self.form, self)
        self._param_form.message.connect(self.message.emit)
        self._form_pending = False
        self.form_builds = 0
        self.params_box.installEventFilter(self)
        params = QtWidgets.QScrollArea()
        params.setWidgetResizable(True)
        params.setFrameShape(QtWidgets.QFrame.Shape.NoFrame)
        params.setWidget(self.params_box)
        self.tabs = QtWidgets.QTabWidget()
        self.tabs.setMinimumHeight(240)
        self.chart = ConvergenceChart()
        self.schematic = LoopSchematic()
        self.tabs.addTab(self.chart, "Convergence")
        self.tabs.addTab(self.schematic, "Boundary loop")
        self.tabs.addTab(params, "Parameters")
        outer.addWidget(self.tabs, 1)

    # -- the list and the selection -------------------------------------------------------
    def _refresh_list(self) -> None:
        ids = surface_nodes(self.doc)
        if self.node_id not in ids:
            self.node_id = ids[0] if ids else None
        blocked = self.node_list.blockSignals(True)
        try:
            self.node_list.clear()
            for nid in ids:
                node = self.doc.nodes[nid]
                title = all_node_types()[node.type_name].title or node.type_name
                text = f"{node.label or nid}  ({title})"
                item = QtWidgets.QListWidgetItem(text)
                item.setData(QtCore.Qt.ItemDataRole.UserRole, nid)
                self.node_list.addItem(item)
                if nid == self.node_id:
                    self.node_list.setCurrentItem(item)
        finally:
            self.node_list.blockSignals(blocked)
        self._show_node()

    def listed_ids(self) -> list[str]:
        return [self.node_list.item(i).data(QtCore.Qt.ItemDataRole.UserRole)
                for i in range(self.node_list.count())]

    def _on_list_pick(self, item, _previous=None) -> None:
        nid = item.data(QtCore.Qt.ItemDataRole.UserRole) if item is not None else None
        if nid is None or nid == self.node_id:
            return
        self.node_id = nid
        self._show_node()
        self.node_selected.emit(nid)

    @QtCore.Slot(object)
    def set_selected(self, node_id) -> None:
        """Follow the editor's selection; a node that is no surface node keeps the one shown."""
        if node_id not in surface_nodes(self.doc) or node_id == self.node_id:
            return
        self.node_id = node_id
        ids = self.listed_ids()
        blocked = self.node_list.blockSignals(True)
        self.node_list.setCurrentRow(ids.index(node_id) if node_id in ids else -1)
        self.node_list.blockSignals(blocked)
        self._show_node()

    # -- evaluation results -------------------------------------------------------------------
    @QtCore.Slot(object)
    def set_report(self, report) -> None:
        """Take the statuses and outputs of a finished evaluation (an EvalReport)."""
        if report is None or getattr(report, "cancelled", False):
            return
        self.results = dict(report.results)
        self.outputs = dict(report.outputs)
        self._stale.clear()
        self._show_node()

    def surface_report(self) -> SurfaceReport | None:
        """The report shown: the selected Surface's, or that of the Surface upstream of it."""
        sid = source_surface(self.doc, self.node_id) if self.node_id else None
        value = (self.outputs.get(sid) or {}).get("report") if sid else None
        return value if isinstance(value, SurfaceReport) else None

    def error_text(self) -> str:
        """The error shown in red ("" when none)."""
        return self.error_label.text()

    # -- showing one node ---------------------------------------------------------------------
    def _show_node(self) -> None:
        nid = self.node_id if self.node_id in self.doc.nodes else None
        self.node_id = nid
        for w in (self.report_box, self.solve_button, self.tabs):
            w.setVisible(nid is not None)
        self._build_editors()
        if nid is None:
            self.title.setText("no surface node: add a Surface node or open a tpms_* example")
            self.status_label.setText("")
            self._set_error("")
            return
        node = self.doc.nodes[nid]
        sid = source_surface(self.doc, nid)
        title = f"<b>{html.escape(node.label or nid)}</b> ({node.type_name})"
        if node.type_name != "Surface":
            title += f" — source: {html.escape(sid) if sid else 'no Surface upstream'}"
        self.title.setText(title)
        self._show_status(nid, sid)
        self._show_report()
        self._show_loop(sid)

    def _show_status(self, nid: str, sid: str | None) -> None:
        r = self.results.get(nid)
        if r is None:
            text = "not evaluated yet"
        else:
            colour = STATUS_COLOURS.get(r.status, "#cccccc")
            text = f"<b style='color:{colour}'>{r.status}</b>"
            if r.status == "evaluated":
                text += f" in {r.seconds:.3f} s"
        if self._stale & {nid, sid}:
            text += " — <i>changed since this solve: solve again</i>"
        self.status_label.setText(text)
        # the node's own error, else (a Dual / Associate node blocked by it) its source's
        errors = [self.results[n].error for n in (nid, sid) if n in self.results and self.results[n].error]
        self._set_error(errors[0] if errors else "")

    def _set_error(self, text: str) -> None:
        self.error_label.setText(text)
        self.error_label.setVisible(bool(text))

    def _show_report(self) -> None:
        rep = self.surface_report()
        for key, _label, fmt in REPORT_ROWS:
            label = self.report_labels[key]
            label.setText("—" if rep is None else fmt(getattr(rep, key)))
            label.setStyleSheet(WARNING_STYLE if key == "warning" and rep is not None and rep.warning else "")
        if rep is None:
            self.chart.set_history(None, note="no report: evaluate the graph" if not self.error_label.text()
                                   else "the solve failed")
        else:
            self.chart.set_history(rep.details.get("energy_history"), rep.solver,
                                   note="this report carries no energy history")

    def _show_loop(self, sid: str | None) -> None:
        if sid is None:
            self.schematic.set_loop(None, note="no Surface node upstream")
            return
        chains = input_chains(self.doc, self.outputs, sid)
        if not chains:
            self.schematic.set_loop(None, note="evaluate the graph to see the boundary loop")
            return
        try:
            points, owners, segment_chain, smooth = boundary_schematic(chains)
        except NodeInputError as exc:
            self.schematic.set_loop(None, note=str(exc))
            return
        solver = self.doc.nodes[sid].params.get("type", "")
        sliding = sliding_segments(solver, segment_chain, smooth, self.surface_report())
        one_chain = all(c == 0 and j == i for i, (c, j) in enumerate(owners))
        labels = [str(i) if one_chain else f"{i} (chain {c}, v{j})" for i, (c, j) in enumerate(owners)]
        marked = error_vertex(self.results[sid].error) if sid in self.results else None
        self.schematic.set_loop(points, sliding, labels, segment_chain, marked=marked)

    # -- parameter editors -------------------------------------------------------------------
    @property
    def param_form(self) -> ParamForm:
        """The shown node's parameter form (built now if it waits)."""
        self._flush_form()
        return self._param_form

    @property
    def editors(self) -> dict:
        return self.param_form.editors

    def _build_editors(self) -> None:
        self._form_pending = True
        if self.params_box.isVisible():
            self._flush_form()

    def _flush_form(self) -> None:
        if not self._form_pending:
            return
        self._form_pending = False
        self.form_builds += 1
        node_id = self.node_id if self.node_id in self.doc.nodes else None
        node_type = self.doc.nodes[node_id].type_name if node_id is not None else None
        params = all_node_types()[node_type].params if node_type is not None else ()
        self._param_form.show_node(node_id, params)
        self._update_visibility()

    def _update_visibility(self) -> None:
        if self._form_pending:
            return                              # built with the right rows when it shows
        params = self.doc.nodes[self.node_id].params if self.node_id in self.doc.nodes else {}
        for name in self._param_form.editors:
            other, values = SHOWN_WHEN.get(name, (None, None))
            self._param_form.set_row_visible(name, other is None or params.get(other) in values)

    def eventFilter(self, watched, event) -> bool:
        if watched is self.params_box and event.type() == QtCore.QEvent.Type.Show:
            self._flush_form()
        return super().eventFilter(watched, event)

    def editor_widget(self, name: str) -> QtWidgets.QWidget:
        """The input widget of parameter ``name`` (tests drive it like a user would)."""
        return self.param_form.editor_widget(name)

    @property
    def refused_label(self) -> QtWidgets.QLabel:
        """The latest refusal's message, shown under its field."""
        return self.param_form.error_label

    def commit(self, name: str, value) -> bool:
        """Push one SetParam for the shown node; a refusal is shown at its field."""
        return self.param_form.commit(name, value)

    # -- document events ------------------------------------------------------------------------
    def _on_doc_event(self, event: str, payload) -> None:
        if event in ("node_added", "node_removed", "label_changed", "reset"):
            if event == "reset":
                self.results, self.outputs, self.node_id = {}, {}, None
                self._stale.clear()
            self._refresh_list()
        elif event in ("edge_added", "edge_removed"):
            self._show_node()                   # a Dual / Associate node's source may have changed
        elif event == "param_changed":
            nid, name = payload
            self._stale.add(nid)
            if nid == self.node_id and not self._form_pending:
                self._param_form.on_param_changed(nid, name)
                self._update_visibility()
            sid = source_surface(self.doc, self.node_id) if self.node_id else None
            if self.node_id is not None and nid in (self.node_id, sid):
                self._show_status(self.node_id, sid)
                if name == "type":
                    self._show_loop(sid)        # what slides follows the solver

    def shutdown(self) -> None:
        """Stop following the document and drawing (the window is closing)."""
        self.doc.unsubscribe(self._on_doc_event)
        self.chart.shutdown()
        self.schematic.shutdown()
