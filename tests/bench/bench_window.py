"""The real window's 3D viewport: GUI-thread stalls, first frame, rotation rate.

Run: xvfb-run -s "-screen 0 1920x1080x24" .venv/bin/python tests/bench/bench_window.py
     [--examples octet tpms_schwarz_p] [--frames 20]

For each example: with a 20 ms QTimer heartbeat on the GUI thread record
the longest gap between ticks while (0) the window starts (its docks' first draws,
kept apart from the example's), (a) it is opened in a real MainWindow,
evaluated and drawn, (b) every node is selected in turn, (c) View > Tile
3x3x3 is switched on until the tiled mesh is drawn ("first frame") and off
and on again, (d) the 3x3x3 block is exported as STL; at each tiling rotate
the camera --frames times, once as still frames (render() calls) and once as
a mouse drag through the VTK interactor (the level of detail for a moving
camera), and print frames/s.  Prints
a table; asserts nothing and leaves no file (the export goes to a
temporary folder and is deleted).  --sample adds, under each stall row, the
GUI thread's commonest stacks during its longest gaps over 50 ms
(tests/bench/stall_sampler.py); --quick stops after the selections.  Compare with the figures in
issue #14 (before: 1.6-2.9 s per selection, 18.5 s for the 3x3x3 toggle,
12-13 s per rotation frame on the 3x3x3 octet).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from PySide6 import QtCore, QtWidgets  # noqa: E402

from app.gui import create_main_window  # noqa: E402
from ui.main_window import EXAMPLES_DIR  # noqa: E402
from ui.qt_wait import process_events_until  # noqa: E402
from stall_sampler import StallSampler  # noqa: E402  (this folder is on sys.path)

QUICK = False           # --quick: stop after the selections (no rotation, tiling, export)
SAMPLE = False          # --sample: print where the GUI thread was during gaps > 50 ms


class Heartbeat:
    """A 20 ms timer on the GUI thread; `longest` is the largest gap between ticks (s)."""

    def __init__(self, interval_ms: int = 20):
        self.timer = QtCore.QTimer()
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self._tick)
        self.last = None
        self.longest = 0.0
        self.ticks = 0

    def _tick(self):
        now = time.perf_counter()
        if self.last is not None:
            self.longest = max(self.longest, now - self.last)
        self.last, self.ticks = now, self.ticks + 1

    def __enter__(self):
        self.last, self.longest, self.ticks = time.perf_counter(), 0.0, 0
        self.timer.start()
        self.sampler = StallSampler(self).__enter__() if SAMPLE else None
        return self

    def __exit__(self, *exc):
        self._tick()
        self.timer.stop()
        if self.sampler is not None:
            self.sampler.__exit__()

    def where(self) -> list[tuple[str, str]]:
        """Rows for the sampled gaps (empty without --sample)."""
        if self.sampler is None:
            return []
        return [(line, "") for line in self.sampler.report()]


def pump(done, timeout_ms=600000):
    return process_events_until(done, lambda: None, timeout_ms=timeout_ms)


def rotation_fps(window, frames: int) -> float:
    """Frames/s of `frames` render() calls, the camera turned between them but never
    "moving" for the interactor: every frame at the still level of detail."""
    plotter = window.viewport.plotter
    plotter.render()
    start = time.perf_counter()
    for _ in range(frames):
        plotter.camera.azimuth = plotter.camera.azimuth + 360.0 / frames
        plotter.render()
    return frames / (time.perf_counter() - start)


def drag_fps(window, frames: int) -> tuple[float, float, int]:
    """A left-button drag through the VTK interactor (what the mouse does): (frames/s of
    the `frames` mouse moves, ms of the still frame drawn at the release, triangles drawn
    while moving)."""
    vp = window.viewport
    iren = vp.plotter.iren.interactor
    w, h = vp.plotter.render_window.GetSize()
    iren.SetEventInformation(w // 2, h // 2, 0, 0)
    iren.InvokeEvent("LeftButtonPressEvent")
    drawn = 0
    start = time.perf_counter()
    for k in range(1, frames + 1):
        iren.SetEventInformation(w // 2 + int(0.6 * w * k / frames), h // 2, 0, 0)
        iren.InvokeEvent("MouseMoveEvent")
        drawn = vp.solid_view().drawn_triangles() if vp.solid_view() else 0
    fps = frames / (time.perf_counter() - start)
    t0 = time.perf_counter()
    iren.InvokeEvent("LeftButtonReleaseEvent")
    return fps, 1000 * (time.perf_counter() - t0), drawn


def bench(name: str, frames: int) -> list[tuple[str, str]]:
    window = create_main_window(autosave_dir=tempfile.mkdtemp())
    window.resize(1400, 850)
    window.show()
    rows = []
    with Heartbeat() as hb:
        pump(lambda: window.isVisible(), 5000)
        pump(lambda: False, 1500)            # the docks' first layout and draws (not the example's)
    rows.append(("window start (empty docks drawn): longest stall (ms)", f"{1000 * hb.longest:.0f}"))
    rows += hb.where()
    try:
        after = window.eval_count
        vp = window.viewport
        window.act_auto.setChecked(False)       # evaluated below, when the bench says so
        with Heartbeat() as hb:
            window.open_example(EXAMPLES_DIR / f"{name}.json", ask=False)
            pump(lambda: False, 1500)        # the document's docks and editor settle (not the viewport's work)
        rows.append(("open example (docks, editor): longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows += hb.where()
        with Heartbeat() as hb:
            window.evaluate_now()
            pump(lambda: window.eval_count > after and window.evaluation_idle)
            t0 = time.perf_counter()
            pump(lambda: vp.is_ready)
        rows.append(("evaluate + prepare + draw: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows += hb.where()
        rows.append(("all levels ready after evaluation (s)", f"{time.perf_counter() - t0:.2f}"))
        rows.append(("solid points / triangles (1 cell)", f"{vp.mesh_point_count():,} / {len(vp.solid.faces):,}"))
        rows.append(("  level triangles", " ".join(f"{m.n_cells}" for m in vp.solid_view().meshes)))
        with Heartbeat() as hb:
            for nid in list(window.doc.nodes):
                window.editor.select(nid)
                pump(lambda: vp.is_ready)
        rows.append((f"select {len(window.doc.nodes)} nodes: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows += hb.where()
        rows.append(("  solid actor swaps / full rebuilds", f"{vp.scene.replaced['solid']} / {vp.scene.full_rebuilds}"))
        if QUICK:
            return rows
        rows.append(("rotation 1x1x1, still frames (frames/s)", f"{rotation_fps(window, frames):.1f}"))
        fps, release, drawn = drag_fps(window, frames)
        rows.append(("rotation 1x1x1, drag (frames/s)", f"{fps:.1f}"))
        rows.append(("  triangles while dragging / still frame at release (ms)", f"{drawn:,} / {release:.0f}"))
        with Heartbeat() as hb:
            t0 = time.perf_counter()
            window.act_tiling.setChecked(True)
            pump(lambda: vp.is_ready)
            vp.plotter.render()
            first = time.perf_counter() - t0
        rows.append(("tile 3x3x3: first frame (s)", f"{first:.2f}"))
        rows.append(("tile 3x3x3: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows.append(("  tiled points (27 full cells) / triangles drawn still",
                     f"{vp.mesh_point_count():,} / {vp.solid_view().drawn_triangles():,}"))
        rows.append(("rotation 3x3x3, still frames (frames/s)", f"{rotation_fps(window, frames):.1f}"))
        fps, release, drawn = drag_fps(window, frames)
        rows.append(("rotation 3x3x3, drag (frames/s)", f"{fps:.1f}"))
        rows.append(("  triangles while dragging / still frame at release (ms)", f"{drawn:,} / {release:.0f}"))
        with Heartbeat() as hb:
            for nid in list(window.doc.nodes)[:6]:
                window.editor.select(nid)
                pump(lambda: vp.is_ready)
        rows.append(("select 6 nodes, tiled: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        with Heartbeat() as hb:
            window.act_tiling.setChecked(False)
            pump(lambda: vp.is_ready)
            window.act_tiling.setChecked(True)
            pump(lambda: vp.is_ready)
        rows.append(("tile off/on again (kept mesh): longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        out = Path(tempfile.mkdtemp()) / f"{name}_3x3x3.stl"
        with Heartbeat() as hb:
            t0 = time.perf_counter()
            ok = window.export_mesh(out, wait=True)
            took = time.perf_counter() - t0
        rows.append(("export 3x3x3 STL: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows.append(("  export time (s) / file MB", f"{took:.2f} / {out.stat().st_size / 1e6:.1f}" if ok else "failed"))
        out.unlink(missing_ok=True)            # the bench writes nothing that stays
    finally:
        window.shutdown()
        window.deleteLater()
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", nargs="+", default=["octet", "tpms_schwarz_p", "tpms_gyroid"])
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--sample", action="store_true",
                        help="print the GUI thread's commonest stacks during gaps over 50 ms")
    parser.add_argument("--quick", action="store_true",
                        help="only open, evaluate and select (no rotation, tiling or export)")
    args = parser.parse_args()
    global SAMPLE, QUICK
    SAMPLE, QUICK = args.sample, args.quick
    os.environ.setdefault("MESOFORGE_AUTOSAVE_DIR", tempfile.mkdtemp())
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv)
    print(f"# bench_window on {platform.machine()} {platform.system()}, Python {platform.python_version()}")
    for name in args.examples:
        print(f"\n## {name}")
        for label, value in bench(name, args.frames):
            print(f"{label:<52} {value:>12}" if value else label)
    app.processEvents()


if __name__ == "__main__":
    main()
