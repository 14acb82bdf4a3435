"""The Implicit Media dock's "Fit to an exemplar" box: an SDF node's parameters fitted to a
signed-distance grid (`engine.nodes.sdf_fit.NodeFit`, the object `mesoforge reconstruct` runs),
off the GUI thread, with progress and cancel; the result is applied, as one undo step, only when
the user asks."""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtWidgets

from engine.graph import Macro, SetParam
from engine.nodes.sdf_fit import FIT_PARAMS, NodeFit, fit_param, load_any_exemplar, parse_bounds

from .colours import STATUS_COLOURS
from .task_runner import TaskRunner
from .tool_number import ToolNumber

EXEMPLAR_FILTER = "Exemplars (*.npy *.vti *.tif *.tiff *.png *.jpg *.bmp);;All files (*)"


def _fit_task(fitting: NodeFit, exemplar, settings: dict, view=None):
    """The fit as a task; `view` (camera, bounds) for an image exemplar (analysis by synthesis)."""
    def run(task):
        def progress(done, best, x):
            task.progress(int(1000 * done), 1000)
            task.publish({"done": done, "loss": best, "params": [float(v) for v in x]})
        if view is not None:              # an image is compared by its DFT amplitudes (eq. 39)
            return fitting.fit_image(exemplar, view[0], bounds=view[1], progress=progress, check=task.check,
                                     **settings)
        return fitting.fit(exemplar, progress=progress, check=task.check, **settings)
    return run


class FitBox(QtWidgets.QGroupBox):
    """Fit the shown node's float parameters to an exemplar.

    prompter : asks for the exemplar file (``open_path(caption, directory, filters)``).
    Signals: ``message(level, text)``.
    """

    message = QtCore.Signal(str, str)

    def __init__(self, doc, undo, prompter=None, view=None, parent=None):
        super().__init__("Fit to an exemplar", parent)
        self.doc, self.undo, self.prompter = doc, undo, prompter
        self.view = view or (lambda: None)      # () -> (camera, bounds) of the dock's view, or None
        self.node_id: str | None = None
        self.inputs: dict = {}
        self.result = None
        self.fitting: NodeFit | None = None
        self.runner = TaskRunner(self)
        self.runner.published.connect(self._on_progress)
        self.runner.finished.connect(self._on_finished)
        self.runner.failed.connect(lambda task, text: self._show_error(text))
        self.runner.busy_changed.connect(self._on_busy)
        form = QtWidgets.QFormLayout(self)
        row = QtWidgets.QHBoxLayout()
        self.path_edit = QtWidgets.QLineEdit()
        self.path_edit.setPlaceholderText("a grid (.npy .vti .tif) or an image taken at this view (.png)")
        browse = QtWidgets.QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row.addWidget(self.path_edit, 1)
        row.addWidget(browse)
        form.addRow("exemplar", row)
        self.bounds_edit = QtWidgets.QLineEdit()
        self.bounds_edit.setPlaceholderText("default: every non-zero float parameter ±50 %")
        self.bounds_edit.setToolTip("NAME=LO:HI, separated by spaces or commas, e.g. cell=0.2:0.6 level=-0.5:0.5")
        form.addRow("fit", self.bounds_edit)
        self.algorithm_box = QtWidgets.QComboBox()
        algorithm = fit_param("algorithm")
        for choice in algorithm.choices:
            self.algorithm_box.addItem(choice, choice)
        self.algorithm_box.setToolTip(algorithm.doc)
        form.addRow("algorithm", self.algorithm_box)
        self.budget_box = ToolNumber(fit_param("budget"))
        form.addRow("budget", self.budget_box)
        self.loss_box = QtWidgets.QComboBox()
        for choice in fit_param("loss").choices:
            self.loss_box.addItem(choice, choice)
        form.addRow("loss", self.loss_box)
        buttons = QtWidgets.QHBoxLayout()
        self.start_button = QtWidgets.QPushButton("Fit")
        self.start_button.clicked.connect(self.start)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(self.runner.cancel)
        self.apply_button = QtWidgets.QPushButton("Apply")
        self.apply_button.setToolTip("set the node's parameters to the values found (one undo step)")
        self.apply_button.setEnabled(False)
        self.apply_button.clicked.connect(self.apply)
        for b in (self.start_button, self.cancel_button, self.apply_button):
            buttons.addWidget(b)
        form.addRow(buttons)
        self.progress = QtWidgets.QProgressBar()
        self.progress.setRange(0, 1000)
        form.addRow(self.progress)
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        self.status.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        form.addRow(self.status)

    # -- what is fitted -------------------------------------------------------------------------
    def set_node(self, node_id: str | None, inputs: dict) -> None:
        """The node (and its evaluated inputs) a fit works on."""
        if node_id != self.node_id:
            self.runner.cancel()
            self.result = None
            self.apply_button.setEnabled(False)
            self.status.setText("")
        self.node_id, self.inputs = node_id, dict(inputs)
        self.setEnabled(node_id is not None)

    def _browse(self) -> None:
        if self.prompter is None:
            return
        path = self.prompter.open_path("Exemplar grid", str(Path(self.path_edit.text()).parent), EXEMPLAR_FILTER)
        if path:
            self.path_edit.setText(path)

    def _bounds(self):
        text = self.bounds_edit.text().replace(",", " ").split()
        if not text:
            return None
        return {name: (lo, hi) for name, lo, hi in (parse_bounds(t) for t in text)}

    def start(self) -> bool:
        """Check everything, then fit off the GUI thread; False (and a message) when refused."""
        if self.node_id is None or self.node_id not in self.doc.nodes:
            return False
        node = self.doc.nodes[self.node_id]
        try:
            exemplar, image = load_any_exemplar(self.path_edit.text().strip())
            fitting = NodeFit(node.type_name, node.params, self.inputs, self._bounds())
        except ValueError as exc:
            self._show_error(str(exc))
            return False
        view = self.view() if image else None
        if image and view is None:
            self._show_error("an image exemplar is fitted at the dock's view: trace the node first")
            return False
        self.fitting, self.result = fitting, None
        self.apply_button.setEnabled(False)
        settings = {"algorithm": self.algorithm_box.currentData(), "budget": self.budget_box.value(),
                    "seed": fit_param("seed").default, "max_evaluations": fit_param("max_evaluations").default}
        if not image:
            settings["loss"] = self.loss_box.currentData()
        what = "by rendering at this view" if image else "to the grid"
        self.status.setText(f"fitting {', '.join(fitting.names)} {what} …")
        self.runner.submit(_fit_task(fitting, exemplar, settings, view))
        return True

    # -- results ---------------------------------------------------------------------------------
    def _on_progress(self, task, info) -> None:
        self.progress.setValue(int(1000 * info["done"]))
        found = ", ".join(f"{n} = {v:.5g}" for n, v in zip(self.fitting.names, info["params"]))
        self.status.setText(f"best loss {info['loss']:.4g}: {found}")

    def _on_finished(self, task, result) -> None:
        self.result = result
        self.progress.setValue(1000)
        found = ", ".join(f"{n} = {v:.6g}" for n, v in zip(self.fitting.names, result.params))
        self.status.setText(f"{result.algorithm}: {found} · loss {result.loss:.4g} · {result.evaluations} "
                            f"evaluations in {result.seconds:.1f} s ({result.stopped_by})")
        self.apply_button.setEnabled(self.node_id in self.doc.nodes)
        self.message.emit("info", f"fit of {self.node_id}: {found}")

    def apply(self) -> bool:
        """Set the node's parameters to the values found, as one undo step."""
        if self.result is None or self.node_id not in self.doc.nodes:
            return False
        commands = [SetParam(self.node_id, n, float(v)) for n, v in zip(self.fitting.names, self.result.params)]
        self.undo.push(Macro(f"apply the fit of {self.node_id}", commands))
        self.apply_button.setEnabled(False)
        return True

    def _on_busy(self, busy: bool) -> None:
        self.start_button.setEnabled(not busy)
        self.cancel_button.setEnabled(busy)

    def _show_error(self, text: str) -> None:
        self.status.setText(f"<span style='color:{STATUS_COLOURS['failed']}'>{text}</span>")
        self.message.emit("warning", f"fit: {text}")

    def shutdown(self) -> None:
        self.runner.shutdown()


__all__ = ["FitBox", "FIT_PARAMS"]
