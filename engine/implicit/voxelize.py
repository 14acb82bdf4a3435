"""An SDF over a box as a `Solid`: node samples, then marching cubes.

The grid over the box ``[lo, hi]`` (mm) has ``n_i`` intervals per axis
(`engine.geometry.box_cell.box_grid_shape`: `resolution` along the longest
edge), nodes at ``lo + i * (hi - lo) / n``:

* periodic (the medium repeats with the box, e.g. a periodic function whose
  cell divides the box): the ``n`` nodes ``i = 0 .. n - 1`` are one period, the
  mesh tiles (`periodic_mesh`);
* otherwise the ``n + 1`` nodes ``i = 0 .. n`` cover both faces and the mesh is
  capped where the medium meets the box (`box_mesh`).

The `Solid` keeps the first ``n`` nodes per axis (its contract: node samples
``i * L / n`` in cell units, distance in cell units), with ``cell_size`` the
box's longest edge and ``cell`` its edges over that, so the Material Matrix,
export and the viewport take it like any unit cell.  Its mesh starts at the
origin (the box's corner `lo` is the caller's to keep).

`sample_nodes` is the numpy evaluation (float64, in x planes with progress
and cancel); `engine.gpu.sdf_voxels` evaluates the same nodes on the GPU.
"""

from __future__ import annotations

import numpy as np

from engine.geometry.box_cell import box_grid_shape
from engine.geometry.marching import box_mesh, periodic_mesh
from engine.geometry.values import Solid
from engine.progress import report

from .values import SDF

__all__ = ["grid_nodes", "sample_nodes", "solid_from_samples", "check_box", "BYTES_PER_NODE", "SAMPLE_POINTS",
           "CHUNK_BYTES"]

BYTES_PER_NODE = 40      # float32 samples, the float32 marching grid and the mesh (measured 36-39 B at 161^3)
SAMPLE_POINTS = 262_144  # points per numpy evaluation chunk
CHUNK_BYTES = 600        # peak bytes per chunk point of a numpy evaluation (a suspension: 550 measured)


def check_box(lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) as (3,) float64 arrays.

    Raises
    ------
    ValueError
        Unless both are three finite coordinates (mm) with hi > lo on every axis.
    """
    a = np.asarray(lo, dtype=np.float64).reshape(-1)
    b = np.asarray(hi, dtype=np.float64).reshape(-1)
    if a.shape != (3,) or b.shape != (3,) or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError(f"box corners must be three finite coordinates (mm), got {lo!r} and {hi!r}")
    if np.any(b <= a):
        raise ValueError(f"box: every edge must be > 0 mm, got lo={a.tolist()}, hi={b.tolist()}")
    return a, b


def grid_nodes(lo, hi, resolution: int, periodic: bool) -> tuple[np.ndarray, np.ndarray, tuple]:
    """(origin, spacing, node counts) of the box's grid (see the module docstring)."""
    a, b = check_box(lo, hi)
    edges = b - a
    intervals = np.array(box_grid_shape(tuple(edges / edges.max()), int(resolution)))
    spacing = edges / intervals
    counts = tuple(int(n) for n in (intervals if periodic else intervals + 1))
    return a, spacing, counts


def sample_nodes(sdf: SDF, origin, spacing, counts, *, progress=None) -> np.ndarray:
    """``sdf.distance`` at the nodes ``origin + (i, j, k) * spacing``: (nx, ny, nz) float32.

    Evaluated a few x planes at a time (about `SAMPLE_POINTS` points), `progress(done, total)`
    told after each; False raises `engine.progress.Cancelled`.
    """
    o = np.asarray(origin, dtype=np.float64)
    h = np.asarray(spacing, dtype=np.float64)
    nx, ny, nz = (int(n) for n in counts)
    out = np.empty((nx, ny, nz), dtype=np.float32)
    y, z = np.meshgrid(o[1] + np.arange(ny) * h[1], o[2] + np.arange(nz) * h[2], indexing="ij")
    planes = max(1, SAMPLE_POINTS // (ny * nz))
    report(progress, 0, nx)
    for x0 in range(0, nx, planes):
        m = min(planes, nx - x0)
        x = o[0] + np.arange(x0, x0 + m) * h[0]
        pts = np.empty((m, ny, nz, 3))
        pts[..., 0] = x[:, None, None]
        pts[..., 1] = y[None]
        pts[..., 2] = z[None]
        out[x0:x0 + m] = sdf.distance(pts.reshape(-1, 3)).reshape(m, ny, nz)
        report(progress, x0 + m, nx)
    return out


def solid_from_samples(samples: np.ndarray, lo, hi, periodic: bool, *, progress=None) -> Solid:
    """The `Solid` of node samples over the box (a grid from `grid_nodes`).

    Raises
    ------
    ValueError
        If nothing, or everything, of the box lies inside (no surface to mesh), or the
        samples do not fit the box's grid.
    """
    a, b = check_box(lo, hi)
    edges = b - a
    size = float(edges.max())
    s = np.asarray(samples, dtype=np.float32)
    cells = np.array(s.shape) - (0 if periodic else 1)
    if s.ndim != 3 or np.any(cells < 2):
        raise ValueError(f"samples of shape {s.shape} do not make a grid over the box")
    # samples on (or within a hair of) the surface moved 1 % of a spacing off it: marching
    # cubes would put a vertex on the node, and where that node is on the box face the cap's
    # vertex lands on the same point (welded: a non-manifold edge).  Periodic functions at
    # level 0 are exactly zero on whole lines of nodes.
    hair = np.float32(0.01 * float((edges / cells).min()))
    s = np.where(np.abs(s) < hair, np.where(s < 0, -hair, hair), s).astype(np.float32)
    inside = s < 0
    if not inside.any():
        raise ValueError("nothing of the medium lies in the box: no sample is inside")
    if inside.all():
        raise ValueError("the medium fills the whole box: no surface to mesh")
    if periodic:
        verts, faces = periodic_mesh(s, cell_size=size, cell=tuple(edges / size), progress=progress)
        kept = s
    else:
        verts, faces = box_mesh(s, spacing=edges / cells, progress=progress)
        kept = s[:-1, :-1, :-1]
    return Solid(kept / size, verts, faces, size, periodic=bool(periodic), cell=tuple(edges / size),
                 origin=tuple(a))
