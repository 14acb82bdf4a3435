"""Screenshots of the real window for the docs: the start page, a tiled TPMS and each dock.

Run (a display is needed; Xvfb is enough):

    xvfb-run -s "-screen 0 1920x1080x24" .venv/bin/python tools/make_screenshots.py [--out docs/screenshots]

Each shot opens a shipped example in a real MainWindow (as an untitled copy),
evaluates it, raises the dock it shows and grabs the window.  Qt cannot grab
the VTK viewport's OpenGL surface, so the viewport's own render is painted
into the window grab at its place.  Writes PNGs only into ``--out``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from PySide6 import QtCore, QtGui, QtWidgets  # noqa: E402

WINDOW_SIZE = (1600, 1000)
SHOT_WIDTH = 1280
# (file name, example to open, dock to raise (its title), tiling 1 or 3, node type to select or None)
SHOTS = (
    ("tiled_tpms.png", "tpms_schwarz_p", "Surfaces", 3, None),
    ("inspector.png", "octet", "Inspector", 1, "Object"),
    ("virtual_growth.png", "growth_tl_hints", "Virtual Growth", 1, "Grow"),
    ("tile_sets.png", "growth_tl_hints", "Tile Sets", 1, "TileSet"),
    ("studies.png", "growth_tl_hints", "Studies", 1, None),
    ("phasor_infill.png", "phasor_slab", "Phasor Infill", 1, "PhasorSlice"),
    ("reaction_diffusion.png", "rd_cantilever", "Reaction Diffusion", 1, "RDGrow"),
    ("material_sphere.png", "octet_stiffness", "Inspector", 1, "MaterialMatrix"),
    ("surfaces.png", "tpms_gyroid", "Surfaces", 1, "Surface"),
    ("implicit_media.png", "implicit_suspension_octet", "Implicit Media", 1, "SDFBoolean"),
)


def grab(window) -> QtGui.QImage:
    """The window as a user sees it: the Qt widgets plus the VTK viewport's own render."""
    image = window.grab().toImage()
    viewport = window.viewport
    shot = viewport.plotter.screenshot(return_img=True)
    if shot is not None:
        h, w = shot.shape[:2]
        frame = QtGui.QImage(shot.copy().data, w, h, 3 * w, QtGui.QImage.Format.Format_RGB888).copy()
        top_left = viewport.mapTo(window, QtCore.QPoint(0, 0))
        size = viewport.size() * window.devicePixelRatioF()
        painter = QtGui.QPainter(image)
        painter.drawImage(QtCore.QRect(top_left, size.toSize() if hasattr(size, "toSize") else size), frame)
        painter.end()
    return image


def save(image: QtGui.QImage, path: Path) -> Path:
    """Write `image` as a PNG at most SHOT_WIDTH wide, in 256 colours (small files for the repo)."""
    from PIL import Image

    image.save(str(path))
    shot = Image.open(path).convert("RGB")
    if shot.width > SHOT_WIDTH:
        shot = shot.resize((SHOT_WIDTH, round(shot.height * SHOT_WIDTH / shot.width)), Image.LANCZOS)
    shot.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(path, optimize=True)
    return path


def wait(app, done, timeout_s: float = 600.0) -> bool:
    timer = QtCore.QElapsedTimer()
    timer.start()
    while not done():
        app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 50)
        if timer.elapsed() > timeout_s * 1000:
            return False
    return True


def settle(app, ms: int = 400) -> None:
    timer = QtCore.QElapsedTimer()
    timer.start()
    while timer.elapsed() < ms:
        app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 20)


def open_and_evaluate(app, window, example: Path) -> None:
    after = window.eval_count
    window.open_example(example, ask=False)
    window.evaluate_now()
    wait(app, lambda: window.eval_count > after and window.evaluation_idle)
    wait(app, lambda: window.viewport.is_ready)


def dock_titled(window, title: str):
    for dock in window.findChildren(QtWidgets.QDockWidget):
        if dock.windowTitle() == title:
            return dock
    raise SystemExit(f"no dock titled {title!r}; docks: "
                     f"{sorted(d.windowTitle() for d in window.findChildren(QtWidgets.QDockWidget))}")


def start_page(app, window, out: Path) -> Path:
    """The example gallery (the start page), thumbnails loaded."""
    from ui.example_gallery import show_gallery

    dialog = show_gallery(window)
    settle(app, 1500)
    path = save(dialog.grab().toImage(), out / "start_page.png")
    dialog.close()
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "screenshots")
    ap.add_argument("--only", nargs="*", help="file names of the shots to take (default: all)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    from app.gui import apply_dark_theme, create_main_window
    from ui.main_window import EXAMPLES_DIR

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    apply_dark_theme(app)
    window = create_main_window(autosave_dir=tempfile.mkdtemp())
    window.resize(*WINDOW_SIZE)
    window.show()
    settle(app, 800)
    written = []
    if not args.only or "start_page.png" in args.only:
        written.append(start_page(app, window, args.out))
    for name, example, dock, tiles, select in SHOTS:
        if args.only and name not in args.only:
            continue
        path = EXAMPLES_DIR / f"{example}.json"
        if not path.is_file():
            print(f"skipped {name}: no example {path.name}", file=sys.stderr)
            continue
        window.act_tiling.setChecked(False)
        open_and_evaluate(app, window, path)
        if select is not None:
            window.editor.select(next(nid for nid, n in window.doc.nodes.items() if n.type_name == select))
        dock_titled(window, dock).raise_()
        window.act_tiling.setChecked(tiles == 3)
        window.viewport.reset_camera()
        wait(app, lambda: window.viewport.is_ready, 300)
        panel = window.implicit_panel
        wait(app, lambda: panel.view.frames_shown > 0 and not panel.traces.is_busy or panel.node_id is None, 300)
        settle(app, 1200)
        written.append(save(grab(window), args.out / name))
    for p in written:
        if p is not None:
            print(p)
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
