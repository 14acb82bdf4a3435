"""Levels of detail of a solid's cell mesh, and which one a view draws.

The software renderer (llvmpipe) spends about a microsecond a triangle, so
a frame's cost is set by the triangles drawn.  A cell is drawn as copies of
one mesh (`ui.solid_actors`), so a 3x3x3 tiling draws 27 times the cell's
triangles; at that size a cell spans ~150 pixels and its full mesh has
several triangles per pixel, invisible detail.  So each solid gets a ladder
of decimated cell meshes, built once off the GUI thread (`build_levels`),
and every frame draws the level `pick_level` chooses from the cell's size
on screen, the number of copies and whether the camera is moving:

* enough detail: the coarsest level with at least `TRIANGLES_PER_PIXEL`
  triangles per pixel of the cell's projected square; with the camera
  still and a single cell in view, the coarsest level whose measured
  deviation from the full mesh (`surface_deviation`, two-sided, in mm) is
  under `STILL_ERROR_PIXELS` on screen: a difference no pixel can show.  So a
  large cell framed whole draws a decimated mesh, and zooming in until the
  deviation would show brings the full mesh back;
* within budget: the copies in view together draw at most `STILL_BUDGET`
  triangles (a single cell in view is exempt: its full mesh is always
  allowed, and the deviation rule keeps it to what shows) or, while the
  camera moves, `MOVING_BUDGET`;
* a translucent solid (drawn faint behind the skeleton it was made from)
  keeps to `MOVING_BUDGET` even when still: its facets cannot be told apart
  through the blending, and a blended frame costs more per triangle.

A new solid's ladder starts with the level a still single cell draws (the
moving budget's, decimated from the full mesh), published together with the
full mesh when the full mesh is over `SINGLE_FRAME_BUDGET`: the first frame
of a new large solid then costs tens of milliseconds, not a few hundred; the
coarser levels are decimated from it.

Plain numpy / pyvista, no Qt and no render window.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable, Iterator, Sequence

import numpy as np
import pyvista as pv

from engine.geometry.mesh_deviation import mesh_deviation

from .scene_prep import PreparedCell, prepare_cell

STILL_BUDGET = 84_000         # triangles a still tiled view draws at most (~85 ms a frame on llvmpipe)
MOVING_BUDGET = 40_000        # triangles drawn while the camera moves (>= 10 frames/s)
TRIANGLES_PER_PIXEL = 1.0     # detail wanted: triangles per pixel of the cell's projected square
STILL_ERROR_PIXELS = 0.5      # a still single cell draws the coarsest level deviating less than this on screen
SINGLE_FRAME_BUDGET = 60_000  # a full mesh over this is first shown with its moving-budget level (~30 ms a frame)
MIN_LEVEL_TRIANGLES = 400     # no level coarser than this
LEVEL_GAP = 0.8               # a level is only made if it has fewer than this fraction of the finer one's triangles
TILE_COPIES = 27              # the tiled view (3x3x3) the ladder is made for
CLOSE_COPIES = 8              # tiles in view when the camera is close to a tiled block


def level_targets(full: int, copies: int = TILE_COPIES) -> list[int]:
    """Triangle counts of the ladder for a cell of `full` triangles, in build order:
    the full mesh, then what a single cell can afford while moving (also the level
    a still single cell draws when it deviates by under half a pixel), a close
    tiled view, a still tiled view and a moving tiled view, each only if clearly
    coarser than the previous."""
    wanted = [max(MIN_LEVEL_TRIANGLES, int(t)) for t in
              (MOVING_BUDGET, STILL_BUDGET // CLOSE_COPIES, STILL_BUDGET // copies, MOVING_BUDGET // copies)]
    kept = [int(full)]
    for t in sorted(set(wanted), reverse=True):
        if t < LEVEL_GAP * kept[-1]:
            kept.append(t)
    return kept


def surface_deviation(a: PreparedCell, b: PreparedCell, check: Callable[[], None] | None = None) -> float:
    """The two-sided deviation (mm) of two cell meshes, an upper bound of the largest
    distance from a vertex of either to the other's surface
    (`engine.geometry.mesh_deviation`; it holds the GIL only briefly, so the GUI
    thread keeps drawing while a worker measures)."""
    return mesh_deviation(a.vertices, a.faces, b.vertices, b.faces, check=check)


def decimated(cell: PreparedCell, target: int, reference: PreparedCell | None = None) -> PreparedCell:
    """`cell` reduced to about `target` triangles by quadric decimation, with fresh normals
    and its deviation from `reference` (the full mesh; `cell` itself if None) measured."""
    m = len(cell.faces)
    if target >= m:
        return cell
    mesh = pv.PolyData.from_regular_faces(cell.vertices, cell.faces)
    coarse = mesh.decimate(1.0 - target / float(m), boundary_constraints=True)
    faces = np.asarray(coarse.regular_faces, dtype=np.int64)
    if not len(faces):
        return cell
    out = prepare_cell(np.asarray(coarse.points), faces)
    return replace(out, error=surface_deviation(reference if reference is not None else cell, out))


def build_levels(vertices: np.ndarray, faces: np.ndarray, check: Callable[[], None] | None = None
                 ) -> Iterator[tuple[PreparedCell, ...]]:
    """Yield the growing ladder (a tuple of PreparedCell, in build order): first the
    full cell (with its first decimated level if the full mesh is over
    `SINGLE_FRAME_BUDGET`), then one more decimated level each time.  Each level
    is decimated from the one before it; every level's `error` is measured against
    the full mesh.  `check` runs between levels."""
    full = prepare_cell(vertices, faces)
    levels = [full]
    targets = level_targets(len(full.faces))[1:]
    if len(full.faces) <= SINGLE_FRAME_BUDGET or not targets:
        yield tuple(levels)                  # small enough to show at once
    for target in targets:
        if check is not None:
            check()
        levels.append(decimated(levels[-1], target, reference=full))
        yield tuple(levels)


def pick_level(counts: Sequence[int], copies: int, cell_pixels: float, moving: bool,
               translucent: bool = False, error_pixels: Sequence[float] | None = None) -> tuple[int, bool]:
    """(index into `counts`, fits): the level to draw.

    counts : triangles of each available level (any order)
    copies : cells in view (of 1 or 27 drawn)
    cell_pixels : the cell's longest edge on screen, pixels
    translucent : the solid is blended (opacity < 1): kept to the moving budget
    error_pixels : each level's deviation from the full mesh on screen, pixels (None:
        unknown, so a still single cell draws the finest level)
    fits : False if even the coarsest level is over the budget (the caller may then
        draw fewer copies until a coarser level is made)."""
    order = sorted(range(len(counts)), key=lambda i: counts[i])      # coarse -> fine
    wanted = TRIANGLES_PER_PIXEL * max(cell_pixels, 1.0) ** 2
    enough = next((i for i in order if counts[i] >= wanted), order[-1])
    if copies == 1 and not moving:           # one cell in view, camera still: no visible difference
        errors = error_pixels if error_pixels is not None else [0.0 if i == order[-1] else math.inf
                                                                 for i in range(len(counts))]
        enough = next((i for i in order if errors[i] < STILL_ERROR_PIXELS), order[-1])
    if moving or translucent:
        budget = MOVING_BUDGET
    else:
        budget = math.inf if copies == 1 else STILL_BUDGET
    allowed = [i for i in order if copies * counts[i] <= budget and counts[i] <= counts[enough]]
    if allowed:
        return allowed[-1], True
    return order[0], False


def pixels_per_mm(height_px: int, distance: float, view_angle_deg: float,
                  parallel: bool = False, parallel_scale: float = 1.0) -> float:
    """Screen pixels per mm at `distance` from a camera with vertical view angle
    `view_angle_deg` (or a parallel projection of half-height `parallel_scale` mm)."""
    if parallel:
        return height_px / max(2.0 * parallel_scale, 1e-12)
    return height_px / max(2.0 * distance * math.tan(math.radians(view_angle_deg) / 2.0), 1e-12)
