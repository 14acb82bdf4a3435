"""Thumbnails of the example graphs, rendered headlessly (VTK through EGL).

What a thumbnail shows is the example's result: the solid the Voxel node
voxelizes (a unit cell, a shell), else the last 2D image a node makes (a
grown tiling, a phasor slice, a compiled reaction-diffusion structure), else
the last solid, else the last skeleton (beams drawn as lines). Object grids
and homogenization solves are lowered first: a 256 x 192 picture needs no
more, and the study-sized solves would only cost time.

``python -m app.thumbnails EXAMPLE.json OUT.png`` renders one thumbnail (the
example gallery runs this in a child process, so VTK never renders inside
the window's process off its GUI thread); ``tools/make_thumbnails.py`` renders
all of them into ``resources/examples/thumbnails``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

THUMBNAIL_SIZE = (256, 192)
PREVIEW_RESOLUTION = 48          # Object grid of a thumbnail
PREVIEW_SOLVE = 8                # Material Matrix solve grid of a thumbnail (the picture shows no C)
ROOT = Path(__file__).resolve().parents[1]


def _preview_document(path):
    from engine.graph import SetParam, UndoStack, load_project

    doc = load_project(path)
    stack = UndoStack(doc)
    for nid, node in doc.nodes.items():
        if node.type_name in ("Object", "SDFSolid") and node.params.get("resolution", 0) > PREVIEW_RESOLUTION:
            stack.push(SetParam(nid, "resolution", PREVIEW_RESOLUTION))
        elif node.type_name == "MaterialMatrix":
            stack.push(SetParam(nid, "resolution", PREVIEW_SOLVE))
    return doc


def thumbnail_subject(doc, report):
    """("solid", Solid) | ("image", (h, w) array) | ("skeleton", Skeleton) | None: what to draw."""
    from app.evaluation import solid_of
    from engine.geometry.values import Field, Skeleton, Solid, VoxelModel

    order = doc.topological_order()
    for nid in order:
        if doc.nodes[nid].type_name == "Voxel":
            (edge,) = doc.inputs_of(nid, "solid")
            solid = solid_of(report, edge.src)
            if solid is not None:
                return "solid", solid
    found = {}
    for nid in order:
        for value in (report.outputs.get(nid) or {}).values():
            if isinstance(value, Field) and value.kind == "scalar" and np.ndim(value.values) == 2:
                found["image"] = np.asarray(value.values)
            elif isinstance(value, (Solid, VoxelModel)):
                found["solid"] = value.solid if isinstance(value, VoxelModel) else value
            elif isinstance(value, Skeleton) and value.lines:
                found["skeleton"] = value
    for kind in ("image", "solid", "skeleton"):
        if kind in found:
            return kind, found[kind]
    return None


def _save_image(values: np.ndarray, png: Path, size) -> None:
    from PIL import Image

    v = np.asarray(values, float)
    lo, hi = np.nanmin(v), np.nanmax(v)
    grey = np.zeros_like(v) if hi <= lo else (v - lo) / (hi - lo)
    pixels = (255 * (1.0 - np.nan_to_num(grey))).astype(np.uint8)[::-1]   # row 0 is y = lo: flip
    img = Image.fromarray(pixels, mode="L").convert("RGB")
    img.thumbnail(size, Image.Resampling.LANCZOS)
    canvas = Image.new("RGB", size, "white")
    canvas.paste(img, ((size[0] - img.width) // 2, (size[1] - img.height) // 2))
    canvas.save(png, optimize=True)


def _save_skeleton(skeleton, png: Path, size) -> None:
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        plotter.set_background("white")
        for line in skeleton.lines:
            plotter.add_mesh(pv.lines_from_points(np.asarray(line.polyline)), color="#3d6fa8", line_width=3)
        plotter.camera_position = "iso"
        plotter.reset_camera()
        plotter.camera.zoom(1.3)
        plotter.screenshot(str(png))
    finally:
        plotter.close()


def compress_png(png: Path, colours: int = 64) -> None:
    """Rewrite `png` with an adaptive palette of `colours` (a thumbnail stays a few kB)."""
    from PIL import Image

    with Image.open(png) as img:
        small = img.convert("RGB").quantize(colours, method=Image.Quantize.MEDIANCUT)
    small.save(png, optimize=True)


def render_example_thumbnail(example: str | Path, png: str | Path, *, size=THUMBNAIL_SIZE) -> str:
    """Evaluate the example at preview resolution and write its thumbnail PNG;
    returns what it shows ("solid", "image" or "skeleton"). Raises ValueError when
    the example has nothing to show, OSError when no picture was written."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    from app.evaluation import evaluate_document
    from app.render import render_mesh_png

    png = Path(png)
    png.parent.mkdir(parents=True, exist_ok=True)
    doc = _preview_document(example)
    report = evaluate_document(doc)
    subject = thumbnail_subject(doc, report)
    if subject is None:
        raise ValueError(f"{example}: nothing to draw ({report.errors or 'no solid, image or skeleton'})")
    kind, value = subject
    tmp = png.with_name(png.stem + ".part.png")
    if kind == "solid":
        render_mesh_png(value.vertices, value.faces, str(tmp), size=size)
    elif kind == "image":
        _save_image(value, tmp, size)
    else:
        _save_skeleton(value, tmp, size)
    if not tmp.is_file():
        raise OSError(f"{png}: the renderer wrote no file")
    compress_png(tmp)
    os.replace(tmp, png)
    return kind


def render_in_child(example: str | Path, png: str | Path, should_stop=lambda: False, *,
                    timeout_s: float = 900.0) -> None:
    """`render_example_thumbnail` in a child Python process (what the gallery calls
    from its worker thread): stopped when ``should_stop()`` turns true. Raises
    RuntimeError with the child's last error line when it fails."""
    cmd = [sys.executable, "-m", "app.thumbnails", str(example), str(png)]
    proc = subprocess.Popen(cmd, cwd=str(ROOT), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    start = time.monotonic()
    try:
        while proc.poll() is None:
            if should_stop() or time.monotonic() - start > timeout_s:
                proc.terminate()
                proc.wait(10)
                raise RuntimeError(f"{Path(example).name}: thumbnail stopped")
            time.sleep(0.1)
    finally:
        if proc.poll() is None:
            proc.kill()
    err = proc.stderr.read().decode(errors="replace").strip().splitlines() if proc.stderr else []
    if proc.returncode != 0:
        raise RuntimeError(f"{Path(example).name}: {err[-1] if err else f'exit {proc.returncode}'}")


def main(argv=None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 2:
        print("usage: python -m app.thumbnails EXAMPLE.json OUT.png", file=sys.stderr)
        return 2
    try:
        render_example_thumbnail(args[0], args[1])
    except (ValueError, OSError) as exc:
        print(str(exc), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
