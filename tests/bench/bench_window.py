"""The real window's 3D viewport: GUI-thread stalls, first frame, rotation rate.

Run: xvfb-run -s "-screen 0 1920x1080x24" .venv/bin/python tests/bench/bench_window.py
     [--examples octet tpms_schwarz_p] [--frames 20]

For each example: open it in a real MainWindow, evaluate, then with a 20 ms
QTimer heartbeat on the GUI thread record the longest gap between ticks
while (a) every node is selected in turn, (b) View > Tile 3x3x3 is switched
on until the tiled mesh is drawn ("first frame") and (c) off again; then
rotate the camera --frames times at each tiling and print frames/s.  Prints
a table; asserts nothing and writes nothing.  Compare with the figures in
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
        return self

    def __exit__(self, *exc):
        self._tick()
        self.timer.stop()


def pump(done, timeout_ms=600000):
    return process_events_until(done, lambda: None, timeout_ms=timeout_ms)


def rotation_fps(window, frames: int) -> float:
    plotter = window.viewport.plotter
    plotter.render()
    start = time.perf_counter()
    for _ in range(frames):
        plotter.camera.azimuth = plotter.camera.azimuth + 360.0 / frames
        plotter.render()
    return frames / (time.perf_counter() - start)


def bench(name: str, frames: int) -> list[tuple[str, str]]:
    window = create_main_window(autosave_dir=tempfile.mkdtemp())
    window.resize(1400, 850)
    window.show()
    pump(lambda: window.isVisible(), 5000)
    rows = []
    try:
        after = window.eval_count
        window.open_example(EXAMPLES_DIR / f"{name}.json", ask=False)
        window.evaluate_now()
        pump(lambda: window.eval_count > after and window.evaluation_idle)
        vp = window.viewport
        t0 = time.perf_counter()
        pump(lambda: vp.is_ready)
        rows.append(("first solid ready after evaluation (s)", f"{time.perf_counter() - t0:.2f}"))
        rows.append(("solid points (1 cell)", f"{vp.mesh_point_count():,}"))
        with Heartbeat() as hb:
            for nid in list(window.doc.nodes):
                window.editor.select(nid)
                pump(lambda: vp.is_ready)
        rows.append((f"select {len(window.doc.nodes)} nodes: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows.append(("  solid actor swaps / full rebuilds", f"{vp.scene.replaced['solid']} / {vp.scene.full_rebuilds}"))
        rows.append(("rotation 1x1x1 (frames/s)", f"{rotation_fps(window, frames):.1f}"))
        with Heartbeat() as hb:
            t0 = time.perf_counter()
            window.act_tiling.setChecked(True)
            pump(lambda: vp.is_ready)
            vp.plotter.render()
            first = time.perf_counter() - t0
        rows.append(("tile 3x3x3: first frame (s)", f"{first:.2f}"))
        rows.append(("tile 3x3x3: longest stall (ms)", f"{1000 * hb.longest:.0f}"))
        rows.append(("  tiled points", f"{vp.mesh_point_count():,}"))
        rows.append(("rotation 3x3x3 (frames/s)", f"{rotation_fps(window, frames):.1f}"))
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
    finally:
        window.shutdown()
        window.deleteLater()
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", nargs="+", default=["octet", "tpms_schwarz_p"])
    parser.add_argument("--frames", type=int, default=20)
    args = parser.parse_args()
    os.environ.setdefault("MESOFORGE_AUTOSAVE_DIR", tempfile.mkdtemp())
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv)
    print(f"# bench_window on {platform.machine()} {platform.system()}, Python {platform.python_version()}")
    for name in args.examples:
        print(f"\n## {name}")
        for label, value in bench(name, args.frames):
            print(f"{label:<52} {value:>12}")
    app.processEvents()


if __name__ == "__main__":
    main()
