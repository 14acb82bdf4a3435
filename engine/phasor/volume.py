"""The diamond cells of a phasor infill in 3D, on a sub-box (Tricard et al., 3.3).

A print only ever needs slices, but the designer checks the structure in 3D
on a small box.  The black diamond cells are where the indicator

    d(x) = |1/2 - p_v(x)| + |1/2 - p_w(x)| - 1/2

is negative (the test :func:`engine.phasor.noise.diamond_mask` applies to
slices).  ``|1/2 - p|`` equals 1/2 on both sides of the sawtooth's wrap
(p = 0 and p -> 1), so d is continuous wherever the noises have a phase,
and marching cubes on d draws the cell walls rather than the wraps; it only
jumps at singularities, where the phase itself does.

:func:`diamond_volume` samples d on the nodes of a voxel grid, one z plane
at a time through :func:`engine.phasor.infill.slice_noise`: the GPU shader
is the faster evaluator (measured on the development machine, 2 cores and
a software EGL renderer: a 101 x 101 plane of the filtered noise in ~50 ms
against ~290 ms for the numba loop, ~14 ms against ~24 ms unfiltered), and
a plane is a natural unit for progress and cancel.
Outside the part the nodes take :data:`OUTSIDE`.  :func:`diamond_surface`
meshes the sampled volume, capped on the sub-box's faces so the surface is
closed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from engine.progress import report

__all__ = ["MAX_VOXELS", "OUTSIDE", "DiamondVolume", "diamond_indicator", "voxel_counts",
           "check_sub_box", "diamond_volume", "diamond_surface"]

MAX_VOXELS = 256 ** 3
# Given to nodes outside the part: the indicator's largest value, so the
# part's boundary cuts the cells halfway between an inside and an outside node.
OUTSIDE = 0.5


@dataclass(frozen=True, eq=False)
class DiamondVolume:
    """The diamond indicator sampled on the nodes of a sub-box.

    Attributes
    ----------
    indicator : (nx + 1, ny + 1, nz + 1) float32, [x, y, z] order, read-only
        d at node ``lo + (i, j, k) * spacing``; negative inside the black
        diamond cells within the part.
    lo, hi : (3,) float64, mm, the sub-box (the outermost nodes lie on its faces)
    state : str, the noise state evaluated (:data:`engine.phasor.infill.STATES`)
    engine : str, "gpu" or "numpy": what evaluated the last plane
    """

    indicator: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    state: str
    engine: str

    def __post_init__(self):
        for name, dtype in (("indicator", np.float32), ("lo", np.float64), ("hi", np.float64)):
            a = np.array(getattr(self, name), dtype=dtype)
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    @property
    def spacing(self) -> np.ndarray:
        """(3,) float64, mm between neighbouring nodes along x, y, z."""
        return (self.hi - self.lo) / (np.array(self.indicator.shape) - 1)

    @property
    def volume_fraction(self) -> float:
        """Fraction of the nodes inside diamond cells."""
        return float(np.count_nonzero(self.indicator < 0) / self.indicator.size)


def diamond_indicator(p_v, p_w) -> np.ndarray:
    """``|1/2 - p_v| + |1/2 - p_w| - 1/2`` (float64, the shape of the inputs):
    negative inside black diamond cells, in [-1/2, 1/2]."""
    return np.abs(0.5 - np.asarray(p_v, np.float64)) + np.abs(0.5 - np.asarray(p_w, np.float64)) - 0.5


def _vec3(name, value) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected three finite numbers (mm), got {value!r}")
    return a


def check_sub_box(fields, lo, hi) -> tuple:
    """(lo, hi) (3,) float64 of a non-empty sub-box inside the fields' box.

    Raises ValueError whose message starts with the refused corner's name
    ("lo" or "hi") and gives the box.
    """
    lo, hi = _vec3("lo", lo), _vec3("hi", hi)
    axis = "xyz"
    box = (f"the fields' box is ({', '.join(f'{v:.4g}' for v in fields.lo)}) .. "
           f"({', '.join(f'{v:.4g}' for v in fields.hi)}) mm")
    for a in range(3):
        if not hi[a] > lo[a]:
            raise ValueError(f"hi: the sub-box is empty along {axis[a]} (lo {lo[a]:.4g} mm, hi {hi[a]:.4g} mm); "
                             f"expected hi > lo on every axis")
    tol = 1e-9 * max(1.0, float(np.abs(fields.hi - fields.lo).max()))
    for name, corner in (("lo", lo), ("hi", hi)):
        out = np.flatnonzero((corner < fields.lo - tol) | (corner > fields.hi + tol))
        if out.size:
            a = int(out[0])
            raise ValueError(f"{name}: {axis[a]} = {corner[a]:.4g} mm lies outside the fields' box; {box}")
    return np.clip(lo, fields.lo, fields.hi), np.clip(hi, fields.lo, fields.hi)


def voxel_counts(lo, hi, voxel, *, max_voxels: int = MAX_VOXELS) -> np.ndarray:
    """(3,) int64 voxels along x, y, z of the sub-box at about ``voxel`` mm each.

    The counts are ``round(extent / voxel)`` (at least 1), so the voxels
    tile the sub-box exactly and are within half a voxel of the size asked.
    Raises ValueError ("voxel: ...") for a non-positive size or more than
    ``max_voxels`` voxels in all.
    """
    if isinstance(voxel, bool) or not isinstance(voxel, (int, float, np.floating)) \
            or not math.isfinite(voxel) or voxel <= 0:
        raise ValueError(f"voxel: expected a positive length in mm, got {voxel!r}")
    ext = np.asarray(hi, np.float64) - np.asarray(lo, np.float64)
    n = np.maximum(1, np.round(ext / float(voxel))).astype(np.int64)
    total = int(np.prod(n))
    if total > max_voxels:
        side = round(max_voxels ** (1 / 3))
        raise ValueError(f"voxel: {voxel:g} mm needs {n[0]} x {n[1]} x {n[2]} = {total:,} voxels over the "
                         f"sub-box, more than the limit of {max_voxels:,} ({side}^3); use a voxel of at least "
                         f"{float(np.cbrt(np.prod(ext) / max_voxels)):.3g} mm or a smaller sub-box")
    return n


def _plane(lo, spacing, counts, z):
    """The SlicePlane whose pixel centres are the nodes of one z plane."""
    from engine.gpu.slice_plane import SlicePlane

    nodes = counts[:2] + 1
    origin = np.array([lo[0] - 0.5 * spacing[0], lo[1] - 0.5 * spacing[1], z])
    return SlicePlane(origin, (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), nodes * spacing[:2], nodes)


def diamond_volume(infill, lo, hi, *, voxel: float = 0.1, state: str | None = None, engine: str = "gpu",
                   progress=None) -> DiamondVolume:
    """Sample the diamond indicator on the nodes of the sub-box ``lo..hi``.

    Parameters
    ----------
    infill : engine.phasor.infill.PhasorInfill
    lo, hi : (3,) float, mm, the sub-box; it must lie in the fields' box
    voxel : float, mm, about the node spacing (:func:`voxel_counts`); it must
        resolve the fields' highest frequency like a slice pixel
        (:func:`engine.phasor.infill.check_pixel`)
    state : noise state (:data:`engine.phasor.infill.STATES`) or None for the
        infill's own (the filtered kernels when the infill filters)
    engine : "gpu" (the slice shader; numpy when no EGL context can be made)
        or "numpy"
    progress : callable(done, total) -> bool or None, in nodes evaluated;
        False cancels (engine.progress.Cancelled) within one chunk of
        one plane

    Returns
    -------
    DiamondVolume

    Raises
    ------
    ValueError
        Whose message starts with the refused argument: "lo", "hi", "voxel".
    """
    from .domain import slice_domain
    from .infill import check_pixel, slice_noise
    from .noise import sawtooth

    lo, hi = check_sub_box(infill.fields, lo, hi)
    counts = voxel_counts(lo, hi, voxel)
    try:
        check_pixel(infill.fields, voxel)
    except ValueError as exc:
        raise ValueError("voxel: " + str(exc).replace("pixel", "voxel")) from None
    spacing = (hi - lo) / counts
    nx, ny, nz = (int(c) + 1 for c in counts)
    per_plane = nx * ny
    total = per_plane * nz
    out = np.empty((nx, ny, nz), np.float32)
    used = engine
    report(progress, 0, total)
    for k in range(nz):
        z = lo[2] + k * spacing[2] if k < nz - 1 else hi[2]
        inner = None if progress is None else _offset(progress, k * per_plane, per_plane, total)
        g_v, g_w, used = slice_noise(infill, _plane(lo, spacing, counts, z), state=state, engine=engine,
                                     progress=inner)
        d = diamond_indicator(sawtooth(np.asarray(g_v, np.complex128)), sawtooth(np.asarray(g_w, np.complex128)))
        if infill.domain is not None:
            inside = slice_domain(infill.domain, "z", float(z), lo=lo[:2] - 0.5 * spacing[:2],
                                  hi=lo[:2] + (counts[:2] + 0.5) * spacing[:2], shape=(ny, nx))
            d[~inside] = OUTSIDE
        out[:, :, k] = d.T                    # rows run along y, columns along x
        report(progress, (k + 1) * per_plane, total)
    return DiamondVolume(out, lo, hi, infill.state if state is None else state, used)


def _offset(progress, start, span, total):
    """A plane's progress callback reporting into the whole volume's count."""
    def inner(done, of):
        return progress(start + int(span * done / max(of, 1)), total)
    return inner


def diamond_surface(volume: DiamondVolume, *, progress=None) -> tuple:
    """The surface of the diamond cells, closed by caps on the sub-box's faces.

    Marching cubes (scikit-image, Lewiner) runs slab by slab through
    :mod:`engine.geometry.marching`, so ``progress(done, total) -> bool``
    is called between slabs and False cancels.

    Returns
    -------
    vertices : (v, 3) float64, mm, part coordinates inside ``lo..hi``
    faces : (f, 3) int64, counter-clockwise seen from outside the cells;
        empty when no node lies in a cell
    """
    from engine.geometry.marching import slab_marching_cubes, weld_clipped, drop_specks

    f = np.array(volume.indicator, dtype=np.float32)
    # A node exactly on the level would put several vertices at one point and
    # break the surface's topology when they are merged: nudge it off.
    eps = np.float32(1e-7)
    near = np.abs(f) < eps
    f[near] = np.where(f[near] < 0, -eps, eps)
    if not (f < 0).any():
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    # One layer of clearly-outside nodes all round; the crossings into it are
    # clipped back onto the sub-box's faces, which caps the cells there.
    grid = np.full(np.add(f.shape, 2), np.float32(10.0), dtype=np.float32)
    grid[1:-1, 1:-1, 1:-1] = f
    verts, faces = slab_marching_cubes(grid, 0.0, progress)
    spacing = volume.spacing
    extent = (np.array(f.shape) - 1) * spacing
    verts = np.clip((verts.astype(np.float64) - 1.0) * spacing, 0.0, extent)
    verts, faces = weld_clipped(verts, faces.astype(np.int64), extent)
    verts, faces = drop_specks(verts, faces, 0.5 * float(np.prod(spacing)))
    return verts + volume.lo, faces
