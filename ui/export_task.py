"""File › Export Mesh off the GUI thread, with progress and cancel.

`check_export` refuses bad input before anything is computed or written
(unknown suffix, missing folder, tiles out of range, a tiled mesh over the
memory budget).  `write_mesh` runs in a `ui.task_runner.TaskRunner`: it
meshes the tiled block (`engine.geometry.marching.periodic_mesh`, the call
`engine.tiled_mesh.tiled_arrays` makes, with progress and cancel between
slabs), encodes it with `engine.geometry.mesh_io.export_mesh` into a
temporary sibling of the target and renames that over the target only if
the export was not cancelled: a cancelled or failed export leaves no file
and an existing file untouched.  The bytes are those `mesoforge eval --out`
writes for the same solid and tiles.

`MeshExport` is the window's side: the runner, a progress bar with a
Cancel button in the status bar, and the messages.
"""

from __future__ import annotations

import os
import secrets
import stat
from pathlib import Path
from typing import Callable

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.geometry.mesh_io import SUPPORTED_SUFFIXES
from engine.memory import check_budget
from engine.tiled_mesh import check_tiles, tiled_arrays, tiled_mesh_estimate

from .qt_wait import process_events_until
from .task_runner import Task, TaskRunner

MESH_SHARE = 0.85      # fraction of the progress bar for meshing; the rest is encoding and writing


def check_export(solid, tiles, path: str | os.PathLike) -> tuple[tuple, Path]:
    """((tx, ty, tz), path) of a valid export request; ValueError (a MemoryLimitError for
    a block over the memory budget) naming what is wrong, before anything is written."""
    path = Path(path)
    if path.suffix.lower() not in SUPPORTED_SUFFIXES:
        raise ValueError(f"cannot export {str(path)!r}: expected a file ending in {', '.join(SUPPORTED_SUFFIXES)}")
    if not path.parent.is_dir():
        raise ValueError(f"cannot export {str(path)!r}: the folder {str(path.parent)!r} does not exist")
    if path.is_dir():
        raise ValueError(f"cannot export {str(path)!r}: it is a folder")
    if solid is None or not len(solid.faces):
        raise ValueError("there is no solid to export yet: evaluate a graph with an Object node")
    tiles = check_tiles(tiles)
    check_budget(tiled_mesh_estimate(solid, tiles), what=f"tiling {'x'.join(map(str, tiles))} cells",
                 lower="the tiles or the resolution", where="tiles")
    return tiles, path


def mesh_arrays(solid, tiles: tuple, progress=None) -> tuple[np.ndarray, np.ndarray]:
    """The arrays `engine.tiled_mesh.tiled_arrays` gives, with `progress(done, total)`
    between slabs of the marching cubes (returning False raises Cancelled)."""
    return tiled_arrays(solid, tiles if solid.periodic else (1, 1, 1), progress=progress)


def write_mesh(task: Task, solid, tiles: tuple, path: Path) -> dict:
    """Worker thread: mesh, encode into a temporary sibling, rename over `path`.

    Returns {"path", "triangles", "tiles"}.  Raises Cancelled (nothing written) when
    the task is stopped before the rename."""
    from engine.geometry.mesh_io import export_mesh

    task.progress(0.0, 1.0)
    v, f = mesh_arrays(solid, tiles, progress=lambda d, t: task.progress(MESH_SHARE * d / max(t, 1), 1.0))
    task.check()
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    tmp = target.parent / f".{target.stem}.{secrets.token_hex(4)}.export{target.suffix}"
    try:
        export_mesh(v, f, tmp)
        task.progress(0.98, 1.0)
        task.check()
        try:
            os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode))   # a replaced file keeps its mode
        except FileNotFoundError:
            pass
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    task.progress(1.0, 1.0)
    return {"path": str(path), "triangles": int(len(f)), "tiles": tiles}


class MeshExport(QtCore.QObject):
    """Runs exports one at a time for a window; shows progress and a Cancel button.

    log(level, text) and error(title, text) are the window's message calls.
    ``outcome`` is "done", "failed" or "cancelled" after an export ends."""

    def __init__(self, status_bar: QtWidgets.QStatusBar, log: Callable[[str, str], None],
                 error: Callable[[str, str], None], parent=None):
        super().__init__(parent)
        self._log, self._error = log, error
        self.runner = TaskRunner(self)
        self.runner.progress.connect(self._on_progress)
        self.runner.finished.connect(self._on_finished)
        self.runner.failed.connect(self._on_failed)
        self.runner.cancelled.connect(self._on_cancelled)
        self.outcome: str | None = None
        self.progress_seen = 0                  # progress reports received (tests)
        # A child of the status bar placed over its right end, outside its layout:
        # showing or hiding it relayouts nothing, so the viewport is not resized
        # and re-rendered (100-200 ms on llvmpipe, on the GUI thread).
        self._status_bar = status_bar
        self.box = QtWidgets.QWidget(status_bar)
        self.box.hide()
        self.box.setAutoFillBackground(True)
        row = QtWidgets.QHBoxLayout(self.box)
        row.setContentsMargins(0, 0, 0, 0)
        self.bar = QtWidgets.QProgressBar()
        self.bar.setRange(0, 1000)
        self.bar.setMaximumWidth(220)
        self.bar.setFormat("exporting… %p%")
        self.cancel_button = QtWidgets.QPushButton("Cancel export")
        self.cancel_button.setToolTip("Stop the mesh export; nothing is written")
        self.cancel_button.clicked.connect(self.cancel)
        row.addWidget(self.bar)
        row.addWidget(self.cancel_button)
        status_bar.installEventFilter(self)

    def eventFilter(self, obj, event):  # noqa: N802 (Qt's name)
        if obj is self._status_bar and event.type() == QtCore.QEvent.Type.Resize and self.box.isVisible():
            self._place()
        return False

    def _place(self) -> None:
        sb = self._status_bar
        h = max(1, sb.height() - 2)
        for w in (self.bar, self.cancel_button):
            w.setMaximumHeight(h)
        self.box.adjustSize()
        self.box.setGeometry(max(0, sb.width() - self.box.width() - 20), (sb.height() - h) // 2,
                             self.box.width(), h)

    @property
    def busy(self) -> bool:
        return self.runner.is_busy

    def start(self, solid, tiles: tuple, path: Path) -> Task:
        self.outcome = None
        self.bar.setValue(0)
        self._place()
        self.box.show()
        self.box.raise_()
        return self.runner.submit(lambda task: write_mesh(task, solid, tiles, path), data=(path, tiles))

    def wait(self, timeout_ms: int = 600000) -> bool:
        """Process events until the export ended; True if it wrote the file."""
        process_events_until(lambda: not self.runner.is_busy, lambda: None, timeout_ms=timeout_ms)
        return self.outcome == "done"

    def cancel(self) -> None:
        if self.runner.is_busy:
            self.bar.setFormat("cancelling…")
            self.runner.cancel()

    def shutdown(self) -> None:
        self.runner.shutdown()

    def _on_progress(self, task, done, total) -> None:
        self.progress_seen += 1
        self.bar.setValue(int(1000 * min(1.0, done / total if total else 0.0)))

    def _end(self, outcome: str) -> None:
        self.outcome = outcome
        self.box.hide()
        self.bar.setFormat("exporting… %p%")

    def _on_finished(self, task, result) -> None:
        self._end("done")
        tx, ty, tz = result["tiles"]
        self._log("info", f"exported {result['triangles']} triangles ({tx}x{ty}x{tz} cells) to {result['path']}")

    def _on_failed(self, task, message: str) -> None:
        self._end("failed")
        path, _tiles = task.data
        self._error("Export mesh", f"cannot export {str(path)!r}: {message}; nothing was written")

    def _on_cancelled(self, task) -> None:
        self._end("cancelled")
        path, _tiles = task.data
        self._log("info", f"export to {path} cancelled; nothing was written")
