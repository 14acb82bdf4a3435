"""The "Studies" dock: property studies of virtual-growth materials, run from the window.

The form describes a ``mesoforge study`` run -- tile set, grid, samples per
group, hint groups (one hint text per line) or a Dirichlet sweep, output
database -- and Run starts it OUT OF PROCESS: a ``QProcess`` runs ``python -m
app.cli study ... --progress-lines --json``. Dask's cluster and worker
processes so never share the GUI process (nor its VTK windows), the window
stays responsive, and Cancel is a signal to that process: SIGTERM makes the
study stop and close its cluster (a kill follows if it does not exit in
time). The engine appends whole rows only and resumes from them, so Resume
runs the same command again without ``--no-resume``.

``progress DONE TOTAL`` lines on the process's stderr drive the progress bar;
the database file is re-read as rows arrive and the plots
(``ui.study_plots``) redrawn. Other stderr lines are kept, and shown with the
exit code when the process fails.
"""

from __future__ import annotations

import collections
import json
from pathlib import Path

from PySide6 import QtCore, QtWidgets

from engine.batch.study_params import (MIN_DISTANCE, SAMPLES, SEED, SWEEP, WORKERS, check_resolution,
                                       resolution_param)
from engine.batch.study_process import parse_progress_line, study_argv, study_process
from engine.batch.study_summary import load_study
from engine.growth import load_tileset

from . import study_dialogs
from .study_dialogs import _number, _row, hint_groups_from_text, shipped_tilesets
from .study_plots import StudyPlots

ROOT = Path(__file__).resolve().parent.parent
RELOAD_MS = 1000         # least time between re-reads of the database while rows arrive
STOP_GRACE_MS = 8000     # after Cancel, kill the process if it has not stopped by then
STDERR_TAIL = 40         # lines of the process's stderr kept for error messages
EXIT_STOPPED = 130       # `mesoforge study` stopped by a signal, whole rows kept
DEFAULT_TILESET = "TL+-"
PROGRESS_FORMAT = "%v / %m samples"


class StudyPanel(QtWidgets.QWidget):
    """Run, cancel and resume studies; plot their database."""

    study_finished = QtCore.Signal(int)      # exit code of the study process

    def __init__(self, parent: QtWidgets.QWidget | None = None):
        super().__init__(parent)
        self._process: QtCore.QProcess | None = None
        self._stderr_buffer = b""
        self._stdout = b""
        self._tail: collections.deque = collections.deque(maxlen=STDERR_TAIL)
        self._cancelling = False
        self._database: Path | None = None
        self.last_exit_code: int | None = None
        self.last_summary: dict | None = None
        # dialogs behind attributes so tests can answer them
        self.ask_open_path = self._dialog_open_path
        self.ask_save_path = self._dialog_save_path
        self.confirm_replace = self._dialog_confirm_replace

        self._reload_timer = QtCore.QTimer(self, singleShot=True, interval=RELOAD_MS)
        self._reload_timer.timeout.connect(self.reload_database)
        self._kill_timer = QtCore.QTimer(self, singleShot=True, interval=STOP_GRACE_MS)
        self._kill_timer.timeout.connect(self._kill)

        self._build_form()
        self.plots = StudyPlots()
        split = QtWidgets.QSplitter(QtCore.Qt.Orientation.Vertical)
        split.addWidget(self._controls)
        split.addWidget(self.plots)
        split.setStretchFactor(1, 1)
        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(4, 4, 4, 4)
        outer.addWidget(split)
        self._update_buttons()
        app = QtCore.QCoreApplication.instance()
        if app is not None:
            app.aboutToQuit.connect(self.shutdown)

    # ------------------------------------------------------------ form

    def _build_form(self) -> None:
        self.tileset_box = QtWidgets.QComboBox()
        self.tileset_box.addItems(shipped_tilesets())
        self.size_edit = QtWidgets.QLineEdit("20x20")
        self.size_edit.setToolTip("grid size in blocks: NXxNY (2D) or NXxNYxNZ (3D)")
        self.periodic_check = QtWidgets.QCheckBox("periodic cell")
        self.periodic_check.setChecked(True)
        # the fields refuse what `mesoforge study` refuses, with the same ranges (study_params)
        self.samples_spin = _number(SAMPLES)
        self.seed_spin = _number(SEED)
        self.resolution_spin = _number(resolution_param(), check=check_resolution, rule="0 or >= 2",
                                       special=(0, "default"))
        self.workers_spin = _number(WORKERS)
        self.scheduler_edit = QtWidgets.QLineEdit()
        self.scheduler_edit.setPlaceholderText("local cluster (or tcp://host:8786)")

        self.groups_radio = QtWidgets.QRadioButton("Hint groups")
        self.sweep_radio = QtWidgets.QRadioButton("Dirichlet sweep")
        self.groups_radio.setChecked(True)
        self.groups_edit = QtWidgets.QPlainTextEdit("T=1,L=1,+=1,-=1\nT=4,L=1,+=1,-=1")
        self.groups_edit.setToolTip("one group per line: block=weight,...; 'uniform' for equal "
                                    "weights")
        self.groups_edit.setFixedHeight(72)
        self.sweep_spin = _number(SWEEP)
        self.distance_spin = _number(MIN_DISTANCE)
        sweep = QtWidgets.QHBoxLayout()
        top = QtCore.Qt.AlignmentFlag.AlignTop
        sweep.addWidget(QtWidgets.QLabel("sets"), 0, top)
        sweep.addWidget(self.sweep_spin, 0, top)
        sweep.addWidget(QtWidgets.QLabel("min distance"), 0, top)
        sweep.addWidget(self.distance_spin, 0, top)

        self.out_edit = QtWidgets.QLineEdit()
        self.out_edit.setPlaceholderText("study.csv (or .parquet)")
        browse = QtWidgets.QToolButton(text="…")
        browse.clicked.connect(self._browse_out)
        out_row = QtWidgets.QHBoxLayout()
        out_row.addWidget(self.out_edit, 1)
        out_row.addWidget(browse)

        self._form = QtWidgets.QWidget()
        form = QtWidgets.QFormLayout(self._form)
        form.setContentsMargins(0, 0, 0, 0)
        form.addRow("Tile set", self.tileset_box)
        form.addRow("Grid", _row(self.size_edit, self.periodic_check))
        form.addRow("Samples / group", self.samples_spin)
        form.addRow("Seed", self.seed_spin)
        form.addRow("Resolution", self.resolution_spin)
        form.addRow("Workers", _row(self.workers_spin, self.scheduler_edit))
        form.addRow(self.groups_radio, self.groups_edit)
        form.addRow(self.sweep_radio, sweep)
        form.addRow("Database", out_row)

        self.run_button = QtWidgets.QPushButton("Run")
        self.run_button.setToolTip("start the study afresh in its own process")
        self.resume_button = QtWidgets.QPushButton("Resume")
        self.resume_button.setToolTip("run the samples not yet in the database")
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.open_button = QtWidgets.QPushButton("Open database…")
        self.run_button.clicked.connect(self.run)
        self.resume_button.clicked.connect(self.resume)
        self.cancel_button.clicked.connect(self.cancel)
        self.open_button.clicked.connect(self._open_clicked)
        buttons = QtWidgets.QHBoxLayout()
        for b in (self.run_button, self.resume_button, self.cancel_button):
            buttons.addWidget(b)
        buttons.addStretch(1)
        buttons.addWidget(self.open_button)

        self.progress = QtWidgets.QProgressBar()
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.progress.setFormat("")
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        self.status.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        self.error_log = QtWidgets.QPlainTextEdit()
        self.error_log.setReadOnly(True)
        self.error_log.setMaximumHeight(110)
        self.error_log.hide()

        self._controls = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(self._controls)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self._form)
        lay.addLayout(buttons)
        lay.addWidget(self.progress)
        lay.addWidget(self.status)
        lay.addWidget(self.error_log)
        self.tileset_box.currentTextChanged.connect(self._tileset_changed)
        if self.tileset_box.findText(DEFAULT_TILESET) >= 0:
            self.tileset_box.setCurrentText(DEFAULT_TILESET)
        self._tileset_changed(self.tileset_box.currentText())
        self.groups_radio.toggled.connect(self._mode_changed)
        self._mode_changed()

    def _mode_changed(self, _checked: bool = False) -> None:
        groups = self.groups_radio.isChecked()
        self.groups_edit.setEnabled(groups)
        self.sweep_spin.setEnabled(not groups)
        self.distance_spin.setEnabled(not groups)

    def _tileset_changed(self, name: str) -> None:
        try:
            ndim = load_tileset(name).ndim
        except ValueError:
            return
        if self.size_edit.text().count("x") + 1 != ndim:
            self.size_edit.setText("20x20" if ndim == 2 else "10x10x10")

    # ------------------------------------------------------------ state

    @property
    def is_running(self) -> bool:
        return self._process is not None

    def process_id(self) -> int | None:
        return int(self._process.processId()) if self._process is not None else None

    def database_path(self) -> Path | None:
        text = self.out_edit.text().strip()
        return Path(text).expanduser().resolve() if text else None

    def study_arguments(self, *, resume: bool) -> list:
        """The ``mesoforge study`` arguments the form describes (ValueError naming a bad value)."""
        out = self.database_path()
        if out is None:
            raise ValueError("Database: choose the .csv or .parquet file the rows go to")
        sweep = self.sweep_radio.isChecked()
        numbers = [self.samples_spin, self.seed_spin, self.resolution_spin, self.workers_spin]
        for box in numbers + ([self.sweep_spin, self.distance_spin] if sweep else []):
            if box.refused:           # the user typed a value the field refused: never run the kept one
                raise ValueError(box.message.text())
        common = dict(n=self.samples_spin.value(), size=self.size_edit.text().strip(),
                      periodic=self.periodic_check.isChecked(), out=str(out),
                      seed=self.seed_spin.value(), workers=self.workers_spin.value(),
                      scheduler=self.scheduler_edit.text().strip() or None,
                      resolution=self.resolution_spin.value() or None, resume=resume)
        name = self.tileset_box.currentText()
        if sweep:
            return study_argv(name, sweep=self.sweep_spin.value(),
                              min_distance=self.distance_spin.value(), **common)
        return study_argv(name, groups=hint_groups_from_text(self.groups_edit.toPlainText()),
                          **common)

    def _update_buttons(self) -> None:
        running = self.is_running
        for w in (self.run_button, self.resume_button, self.open_button, self._form):
            w.setEnabled(not running)
        self.cancel_button.setEnabled(running and not self._cancelling)

    # ------------------------------------------------------------ actions

    def run(self) -> bool:
        """Start the study afresh (the database is replaced after asking)."""
        return self._launch(resume=False)

    def resume(self) -> bool:
        """Run the samples of the study not yet in its database."""
        return self._launch(resume=True)

    def _launch(self, *, resume: bool) -> bool:
        if self.is_running:
            return False
        try:
            argv = self.study_arguments(resume=resume)
        except ValueError as exc:
            self._show_error(f"Not started: {exc}")
            return False
        out = self.database_path()
        if not resume and out.exists() and not self.confirm_replace(out):
            return False
        self._start(argv, out)
        return True

    def _start(self, argv: list, out: Path) -> None:
        program, args = study_process(argv)
        proc = QtCore.QProcess(self)
        proc.setProgram(program)
        proc.setArguments(args)
        proc.setWorkingDirectory(str(ROOT))
        env = QtCore.QProcessEnvironment.systemEnvironment()
        env.insert("PYTHONUNBUFFERED", "1")
        proc.setProcessEnvironment(env)
        proc.readyReadStandardError.connect(self._read_stderr)
        proc.readyReadStandardOutput.connect(self._read_stdout)
        proc.finished.connect(self._finished)
        proc.errorOccurred.connect(self._process_error)
        self._process, self._database = proc, out
        self._stderr_buffer, self._stdout = b"", b""
        self._tail.clear()
        self._cancelling = False
        self.last_exit_code, self.last_summary = None, None
        self.progress.setRange(0, 0)           # busy until the first progress line
        self.progress.setFormat(PROGRESS_FORMAT)
        self.error_log.hide()
        self._set_status("Starting the study process…")
        self._update_buttons()
        proc.start()

    def cancel(self) -> None:
        """Ask the study to stop (SIGTERM); it is killed if still running after a grace time."""
        if self._process is None or self._cancelling:
            return
        self._cancelling = True
        self._set_status("Cancelling: the study keeps the rows it wrote…")
        self._process.terminate()
        self._kill_timer.start()
        self._update_buttons()

    def _kill(self) -> None:
        if self._process is not None:
            self._process.kill()

    def shutdown(self, timeout_ms: int = 5000) -> None:
        """Stop a running study and wait for its process, and the plots' draw threads
        (call before the window closes)."""
        self.plots.shutdown()
        proc = self._process
        if proc is None:
            return
        self._cancelling = True
        proc.terminate()
        if not proc.waitForFinished(timeout_ms):
            proc.kill()
            proc.waitForFinished(timeout_ms)

    def load_database(self, path) -> bool:
        """Plot an existing study database (CSV or Parquet made by ``mesoforge study``)."""
        try:
            rows = load_study(path)
            self.plots.show_rows(rows)
        except (ValueError, OSError) as exc:
            self._show_error(f"Cannot open {path}: {exc}")
            return False
        self._database = Path(path)
        groups = len(self.plots.groups)
        self._set_status(f"{Path(path).name}: {len(rows)} rows in {groups} hint group"
                         f"{'s' if groups != 1 else ''}")
        return True

    def reload_database(self) -> None:
        """Re-read the running (or last) study's database and redraw the plots."""
        path = self._database
        if path is None:
            return
        parquet = path.suffix.lower() == ".parquet"
        journal = path.with_name(path.name + ".rows.csv") if parquet else path
        if not journal.exists():
            return
        try:
            self.plots.show_rows(load_study(path))
        except (ValueError, OSError) as exc:
            self._show_error(f"Cannot read {path}: {exc}")

    def _open_clicked(self) -> None:
        path = self.ask_open_path()
        if path:
            self.load_database(path)

    def _browse_out(self) -> None:
        path = self.ask_save_path()
        if path:
            self.out_edit.setText(path)

    # ------------------------------------------------------------ process output

    def _read_stderr(self) -> None:
        if self._process is None:
            return
        self._stderr_buffer += bytes(self._process.readAllStandardError())
        *lines, self._stderr_buffer = self._stderr_buffer.split(b"\n")
        for raw in lines:
            self._stderr_line(raw.decode("utf-8", "replace").rstrip("\r"))

    def _stderr_line(self, line: str) -> None:
        p = parse_progress_line(line)
        if p is None:
            if line.strip():
                self._tail.append(line)
            return
        done, total = p
        self.progress.setRange(0, max(total, 1))
        self.progress.setValue(done)
        if not self._cancelling:
            self._set_status(f"Running: {done} of {total} samples")
        if done and not self._reload_timer.isActive():
            self._reload_timer.start()

    def _read_stdout(self) -> None:
        if self._process is not None:
            self._stdout += bytes(self._process.readAllStandardOutput())

    def _process_error(self, error) -> None:
        if error == QtCore.QProcess.ProcessError.FailedToStart:
            self._tail.append(f"could not start {self._process.program()}: "
                              f"{self._process.errorString()}")
            self._finished(-1, QtCore.QProcess.ExitStatus.CrashExit)

    def _finished(self, code: int, status) -> None:
        proc = self._process
        if proc is None:
            return
        self._read_stdout()
        self._read_stderr()
        if self._stderr_buffer:
            self._stderr_line(self._stderr_buffer.decode("utf-8", "replace"))
            self._stderr_buffer = b""
        self._kill_timer.stop()
        self._reload_timer.stop()
        self._process = None
        proc.deleteLater()
        crashed = status == QtCore.QProcess.ExitStatus.CrashExit
        self.last_exit_code = -1 if crashed and code == 0 else int(code)
        try:
            self.last_summary = json.loads(self._stdout.decode("utf-8", "replace"))
        except ValueError:
            self.last_summary = None
        self.reload_database()
        if self.progress.maximum() == 0:
            self.progress.setRange(0, 1)
        if self._cancelling and (crashed or code == EXIT_STOPPED):
            rows = sum(g.n_samples for g in self.plots.groups)
            self._set_status(f"Cancelled: {rows} of {self.progress.maximum()} samples are in "
                             f"{self._database.name}; Resume continues the study.")
        elif code == 0 and not crashed:
            self._set_status(self._done_text())
        else:
            what = "crashed" if crashed else f"failed (exit code {code})"
            self._show_error(f"The study {what}.", "\n".join(self._tail))
        self._cancelling = False
        self._update_buttons()
        self.study_finished.emit(self.last_exit_code)

    def _done_text(self) -> str:
        s = self.last_summary or {}
        if "n_done" not in s:
            return "Done."
        return (f"Done: {s['n_done']} of {s['n_samples']} samples ({s['n_ok']} ok, "
                f"{s['n_singular']} mechanisms, {s['n_error']} failed) in "
                f"{s['seconds']:.1f} s; {s.get('n_resumed', 0)} resumed. Rows in "
                f"{self._database}.")

    # ------------------------------------------------------------ messages

    def _set_status(self, text: str) -> None:
        self.status.setStyleSheet("")
        self.status.setText(text)

    def _show_error(self, text: str, details: str = "") -> None:
        self.status.setStyleSheet("color: #e06060;")
        self.status.setText(text)
        self.error_log.setPlainText(details)
        self.error_log.setVisible(bool(details))

    # ------------------------------------------------------------ dialogs (replaceable by tests)

    def _dialog_open_path(self) -> str | None:
        return study_dialogs.open_path(self)

    def _dialog_save_path(self) -> str | None:
        return study_dialogs.save_path(self)

    def _dialog_confirm_replace(self, path: Path) -> bool:
        return study_dialogs.confirm_replace(self, path)
