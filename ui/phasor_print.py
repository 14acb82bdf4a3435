"""The print part of the Phasor Infill dock: export G-code, preview it.

"Export G-code…" slices the evaluated infill layer by layer and writes the
file (``PhasorInfillSession.write_print``, through ``engine.fab``) in a
`TaskRunner`, with progress and Cancel (a cancelled export leaves no file).
"Preview G-code…" reads a file back (``engine.phasor.preview.gcode_preview``,
the last written one after an export) and emits its toolpaths as coloured
line segments for the 3D viewport; one layer at a time is drawn here too.

Printability (paper 5.1, ``engine.fab.printability``): after an export the
written file's paths are emulated, and "Printability…" emulates a print of
the current infill (the previewed G-code when there is no infill), in a
second `TaskRunner`; `PrintabilityView` shows the overhang and overlap segments as
two histograms by length (matplotlib) with their totals.
"""

from __future__ import annotations

import os

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.nodes.phasor_session import PhasorInfillSession

from .task_runner import TaskRunner

ERROR_STYLE = "<span style='color:#c0392b'>{}</span>"
PROGRESS_DELAY_MS = 300     # a progress bar only for what takes longer


class GcodeLayerView(QtWidgets.QWidget):
    """The extruding paths of one G-code layer, coloured by kind, scaled to fit."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.layers: list = []
        self.index = 0
        self.colours: dict = {}
        self._bounds = np.array([[0.0, 1.0], [0.0, 1.0]])
        self.setMinimumHeight(160)

    def set_layers(self, layers, colours: dict) -> None:
        """``layers``: GcodeLayer-like objects (``z``, ``paths``, ``kinds``); ``colours``: kind -> RGB."""
        self.layers = list(layers)
        self.colours = dict(colours)
        pts = [np.asarray(path)[:, :2] for layer in self.layers for path in layer.paths]
        if pts:
            allp = np.concatenate(pts)
            self._bounds = np.stack([allp.min(axis=0), allp.max(axis=0)], axis=1)
        self.index = 0
        self.update()

    def set_layer(self, index: int) -> None:
        self.index = int(np.clip(index, 0, max(0, len(self.layers) - 1)))
        self.update()

    def paintEvent(self, _event) -> None:
        p = QtGui.QPainter(self)
        p.fillRect(self.rect(), QtGui.QColor(250, 250, 248))
        if not self.layers:
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "no G-code previewed")
            p.end()
            return
        (x0, x1), (y0, y1) = self._bounds
        s = min((self.width() - 12) / max(x1 - x0, 1e-9), (self.height() - 12) / max(y1 - y0, 1e-9))
        ox = (self.width() - (x1 - x0) * s) / 2
        oy = (self.height() - (y1 - y0) * s) / 2
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        layer = self.layers[self.index]
        for path, kind in zip(layer.paths, layer.kinds):
            rgb = self.colours.get(kind, self.colours.get("infill", (40, 110, 200)))
            p.setPen(QtGui.QPen(QtGui.QColor(*(int(c) for c in rgb)), 1.0))
            q = np.asarray(path, dtype=np.float64)
            poly = QtGui.QPolygonF([QtCore.QPointF(ox + (x - x0) * s, self.height() - oy - (y - y0) * s)
                                    for x, y in q[:, :2]])
            p.drawPolyline(poly)
        p.setPen(QtGui.QColor(40, 40, 40))
        p.drawText(6, 14, f"layer {self.index + 1} / {len(self.layers)}, z = {layer.z:.3g} mm")
        p.end()


class PrintabilityView(QtWidgets.QWidget):
    """Totals and two histograms (overhang, overlap segments by length) of a
    :class:`engine.fab.PrintabilityReport`; call :meth:`show_report`."""

    KINDS = (("overhang", "overhangs", "#d0641e"), ("overlap", "overlaps", "#2c6fbb"))

    def __init__(self, parent=None):
        super().__init__(parent)
        from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
        from matplotlib.figure import Figure

        self.report = None
        self.bars: dict = {}          # kind -> matplotlib BarContainer
        self.totals = QtWidgets.QLabel("")
        self.totals.setWordWrap(True)
        self.canvas = FigureCanvasQTAgg(Figure(figsize=(5, 2.4), layout="constrained"))
        self.canvas.setMinimumHeight(180)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.totals)
        lay.addWidget(self.canvas)

    def show_report(self, report, source: str = "") -> None:
        from engine.fab.printability import MAX_OVERLAP, MIN_SUPPORT

        self.report = report
        fig = self.canvas.figure
        fig.clear()
        edges = np.asarray(report.bin_edges, dtype=np.float64)
        axes = fig.subplots(1, 2, sharey=True)
        self.bars = {}
        for ax, (kind, title, colour) in zip(axes, self.KINDS):
            counts = getattr(report, f"{kind}_histogram")
            self.bars[kind] = ax.bar(edges[:-1], counts, width=np.diff(edges), align="edge", color=colour,
                                     edgecolor="white", linewidth=0.5)
            ax.set_title(f"{title}: {len(getattr(report, f'{kind}_segments'))}", fontsize=9)
            ax.set_xlabel("segment length (mm)", fontsize=8)
            ax.tick_params(labelsize=7)
        axes[0].set_ylabel("segments", fontsize=8)
        self.canvas.draw_idle()
        lead = f"{source}: " if source else ""
        self.totals.setText(
            f"{lead}{len(report.overhang_per_layer)} layers, {len(report.segment_length)} pieces; "
            f"{report.overhang_count} overhang segments ({report.overhang_segments.sum():.1f} mm, "
            f"< {100 * MIN_SUPPORT:g} % supported), {report.overlap_count} overlap segments "
            f"({report.overlap_segments.sum():.1f} mm, > {100 * MAX_OVERLAP:g} % of the nozzle)")


class PrintBox(QtWidgets.QGroupBox):
    """Export and preview buttons with a per-layer view.

    Signals
    -------
    preview_lines(points (n, 3) float64 mm, segments (m, 2) int64, colours (m, 3) uint8)
    message(str) : rich text for the dock's message line
    progress(done, total), running(bool) : the export's progress (the printability check
        has its own bar and Cancel button here)
    printability(report) : a PrintabilityReport was computed and is shown
    """

    preview_lines = QtCore.Signal(object, object, object)
    message = QtCore.Signal(str)
    progress = QtCore.Signal(int, int)
    running = QtCore.Signal(bool)
    printability = QtCore.Signal(object)

    def __init__(self, parent=None):
        super().__init__("Print", parent)
        self.infill = None
        self.name = "phasor"
        self.engine = "gpu"
        self.last_gcode: str | None = None
        self.previewed: str | None = None      # the G-code file whose layers are shown
        self.layers: list = []
        self._export = TaskRunner(self)
        self._export.progress.connect(lambda _t, done, total: self.progress.emit(int(done), int(total)))
        self._export.finished.connect(lambda task, summary: self._on_done(task.data, summary))
        self._export.failed.connect(lambda _t, msg: self._end(ERROR_STYLE.format(f"export failed: {msg}")))
        self._export.cancelled.connect(lambda _t: self._end("export cancelled; no file written"))
        self._checker = TaskRunner(self)
        self._checker.progress.connect(lambda _t, done, total: self._on_check_progress(int(done), int(total)))
        self._checker.finished.connect(lambda task, report: self._on_checked(report, task.data))
        self._checker.failed.connect(
            lambda _t, msg: self._end_check(ERROR_STYLE.format(f"printability failed: {msg}")))
        self._checker.cancelled.connect(lambda _t: self._end_check("printability check cancelled"))
        self._settings = None          # of the last export; the printability check uses them too
        self._pixel = None
        self.printability_view: PrintabilityView | None = None
        # replaceable for tests and scripting: (caption, start path) -> path or None
        self.ask_open_path = self._dialog_open
        self.ask_save_path = self._dialog_save
        v = QtWidgets.QVBoxLayout(self)
        row = QtWidgets.QHBoxLayout()
        self.export_button = QtWidgets.QPushButton("Export G-code…")
        self.export_button.clicked.connect(self._on_export_clicked)
        self.preview_button = QtWidgets.QPushButton("Preview G-code…")
        self.preview_button.clicked.connect(self._on_preview_clicked)
        self.check_button = QtWidgets.QPushButton("Printability…")
        self.check_button.setToolTip("emulate a print of the infill (or of the previewed G-code): overhang "
                                     "and overlap segments, as in Tricard et al. 5.1")
        self.check_button.clicked.connect(self._on_check_clicked)
        self.check_button.setEnabled(False)
        row.addWidget(self.export_button)
        row.addWidget(self.preview_button)
        row.addWidget(self.check_button)
        v.addLayout(row)
        self.check_progress = QtWidgets.QProgressBar()
        self.check_cancel = QtWidgets.QPushButton("Cancel")
        self.check_cancel.clicked.connect(self.cancel_check)
        self.check_row = QtWidgets.QWidget()
        check_row = QtWidgets.QHBoxLayout(self.check_row)
        check_row.setContentsMargins(0, 0, 0, 0)
        check_row.addWidget(self.check_progress, 1)
        check_row.addWidget(self.check_cancel)
        self.check_row.hide()
        v.addWidget(self.check_row)
        self._view_layout = v
        self.layer_view = GcodeLayerView()
        self.layer_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.layer_slider.valueChanged.connect(self.layer_view.set_layer)
        self.layer_view.hide()
        self.layer_slider.hide()
        v.addWidget(self.layer_view)
        v.addWidget(self.layer_slider)

    def set_infill(self, infill, name: str | None, engine: str = "gpu") -> None:
        """The evaluated infill to export (None: export is off)."""
        self.infill, self.name, self.engine = infill, name or "phasor", engine
        self.export_button.setEnabled(infill is not None and not self.exporting)
        self.export_button.setToolTip("" if infill is not None else "needs an evaluated Phasor Noise")
        self._update_check_button()

    def _update_check_button(self) -> None:
        self.check_button.setEnabled(not self.checking and (self.infill is not None or bool(self.layers)))

    @property
    def exporting(self) -> bool:
        return self._export.is_busy

    def _session(self) -> PhasorInfillSession:
        return PhasorInfillSession.of_infill(self.infill)

    def _dialog_open(self, caption: str, start: str):
        path, _ = QtWidgets.QFileDialog.getOpenFileName(self, caption, start,
                                                        "G-code (*.gcode *.gco *.g);;All files (*)")
        return path or None

    def _dialog_save(self, caption: str, start: str):
        path, _ = QtWidgets.QFileDialog.getSaveFileName(self, caption, start, "G-code (*.gcode)")
        return path or None

    # -- preview ----------------------------------------------------------------------------------
    def _on_preview_clicked(self) -> None:
        path = self.ask_open_path("Preview G-code", self.last_gcode or os.getcwd())
        if path:
            self.preview_gcode(path)

    def preview_gcode(self, path) -> bool:
        """Read ``path``, show its layers and emit `preview_lines`; False (and a message) if unreadable."""
        from engine.fab import KIND_CODES, KIND_COLOURS
        from engine.phasor.preview import gcode_preview

        try:
            lines = gcode_preview(path)
        except (ValueError, OSError) as exc:
            self.message.emit(ERROR_STYLE.format(f"cannot preview: {exc}"))
            return False
        self.layers = lines.layers
        self.previewed = str(path)
        colours = {kind: tuple(KIND_COLOURS[code]) for kind, code in KIND_CODES.items()}
        self.layer_view.set_layers(lines.layers, colours)
        self.layer_slider.setRange(0, max(0, len(lines.layers) - 1))
        self.layer_slider.setValue(0)
        self.layer_view.setVisible(bool(lines.layers))
        self.layer_slider.setVisible(len(lines.layers) > 1)
        self._update_check_button()
        self.message.emit(f"{os.path.basename(str(path))}: {len(lines.layers)} layers, "
                          f"{len(lines.segments)} segments")
        self.preview_lines.emit(lines.points, lines.segments, lines.colours)
        return True

    # -- export -----------------------------------------------------------------------------------
    def _on_export_clicked(self) -> None:
        if self.exporting or self.infill is None:
            return
        start = self.last_gcode or os.path.join(os.getcwd(), f"{self.name}.gcode")
        path = self.ask_save_path("Export G-code", start)
        if path:
            self.export_gcode(path)

    def export_gcode(self, path, *, settings=None, pixel=None) -> None:
        """Write the G-code of the infill in a thread; the preview follows when it is written.

        ``pixel`` (mm) defaults to 0.1, finer when the highest F needs it
        (``PhasorInfillSession.export_pixel``).
        """
        if self.infill is None or self.exporting:
            return
        session, engine = self._session(), self.engine
        pixel = session.export_pixel() if pixel is None else pixel
        self._settings, self._pixel = settings, pixel
        self.export_button.setEnabled(False)
        self.message.emit(f"exporting {os.path.basename(str(path))}…")
        self.running.emit(True)
        self._export.submit(lambda task: session.write_print(path, settings=settings, pixel=pixel, engine=engine,
                                                             progress=task.progress), data=path)

    def cancel(self) -> None:
        self._export.cancel()
        self._checker.cancel()

    def _end(self, text: str) -> None:
        self.export_button.setEnabled(self.infill is not None)
        self.running.emit(False)
        self.message.emit(text)

    def _on_done(self, path, summary) -> None:
        self.last_gcode = str(path)
        self._end(f"wrote {os.path.basename(str(path))}: {summary.layers} layers, "
                  f"{summary.print_time / 60:.1f} min")
        if self.preview_gcode(path):
            self.check_printability(self.layers, source=os.path.basename(str(path)))

    # -- printability -----------------------------------------------------------------------------
    @property
    def checking(self) -> bool:
        return self._checker.is_busy

    def _on_check_clicked(self) -> None:
        if self.infill is not None:
            self.check_printability()
        elif self.layers:
            self.check_printability(self.layers, source=os.path.basename(self.previewed or "the G-code"))

    def check_printability(self, layers=None, *, source: str = "") -> None:
        """Emulate the print in a thread and show the histograms when done.

        ``layers``: toolpath layers (``paths`` per layer, e.g. the previewed
        G-code's); None slices the infill with the last export's settings
        and pixel (the defaults before any export).
        """
        from engine.fab import PrintSettings, printability

        if self.checking:
            return
        settings = self._settings or PrintSettings()
        nozzle = settings.nozzle_diameter
        if layers is None:
            if self.infill is None:
                return
            session, engine, pixel = self._session(), self.engine, self._pixel
            source = source or f"{self.name} ({settings.layer_height:g} mm layers)"

            def work(task):
                return session.printability(settings, pixel=pixel, engine=engine, progress=task.progress)
        else:
            layers = list(layers)
            source = source or "the G-code"

            def work(task):
                return printability(layers, nozzle_diameter=nozzle, progress=task.progress)
        self._checker.submit(work, data=source)
        self._update_check_button()
        self.check_progress.setRange(0, 0)
        QtCore.QTimer.singleShot(PROGRESS_DELAY_MS, self, self._show_check_progress)
        self.message.emit(f"emulating the print of {source}…")

    def _show_check_progress(self) -> None:
        if self.checking:
            self.check_row.show()

    def _on_check_progress(self, done: int, total: int) -> None:
        if total > 0:
            self.check_progress.setRange(0, total)
            self.check_progress.setValue(min(done, total))

    def cancel_check(self) -> None:
        self._checker.cancel()

    def _end_check(self, text: str) -> None:
        self.check_row.hide()
        self._update_check_button()
        self.message.emit(text)

    def _on_checked(self, report, source: str) -> None:
        if self.printability_view is None:
            self.printability_view = PrintabilityView()
            self._view_layout.addWidget(self.printability_view)
        self.printability_view.show_report(report, source)
        self.printability_view.show()
        self._end_check(f"printability of {source}: {report.overhang_count} overhang and "
                        f"{report.overlap_count} overlap segments")
        self.printability.emit(report)

    def shutdown(self, timeout_ms: int = 10000) -> None:
        self._export.shutdown(timeout_ms)
        self._checker.shutdown(timeout_ms)
