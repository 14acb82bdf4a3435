"""Density grids for ``mesoforge homogenize INPUT``: readers, checks, memory.

:func:`load_voxel_grid` turns a file into a float64 density grid in [0, 1]
(1 = solid, 0 = void):

* ``.npy`` -- the array itself; 2D gives ``"pixels"``, 3D ``"voxels"``.
  Bool and integer arrays are converted; anything else (complex, object,
  1D, 4D) is refused.
* ``.vti`` -- VTK ImageData read by pyvista. The array is the one named by
  ``array``, else the first cell array, else the first point array.
  Cell data give one voxel per cell; point data are read as voxel-centre
  samples, one voxel per point (the usual layout of an image written from a
  numpy array). Flat VTK order (x fastest) becomes ``[x, y, z]`` indexing.
  An image one cell / point thick in z is returned as pixels.
* ``.png`` -- solid where the luminance (ITU-R 601 weights, alpha
  composited over white) is below 0.5: dark ink on light paper. ``invert``
  swaps solid and void (for every format).
* ``.stl``, ``.obj``, ``.ply``, ``.3mf`` -- a closed triangle mesh,
  voxelized on ``res``^3 voxel centres over its bounding box (or ``bounds``),
  which is taken as one periodic cell; see :func:`voxelize_mesh`.

Index conventions. Voxels: ``grid[i, j, k]`` is ``(x, y, z)`` as in
:mod:`engine.geometry.sdf_lines`. Pixels: ``grid[row, col]`` as an image is
stored, row 0 at the *top*; x runs along columns and y grows *upwards*, i.e.
with decreasing row (a 2D .vti is flipped to match). A solver that instead
takes rows as +y sees the mirror image: ``E_x, E_y, nu, G`` are unchanged,
the xx-xy and yy-xy couplings change sign.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from engine.memory import MemoryLimitError, available_memory_bytes, memory_budget

from engine.progress import run_chunked

__all__ = ["load_voxel_grid", "voxelize_mesh", "validate_density", "memory_estimate_bytes",
           "check_memory", "available_memory_bytes", "GridTooLarge", "INPUT_SUFFIXES", "grid_shape_of"]

MESH_SUFFIXES = (".stl", ".obj", ".ply", ".3mf")
INPUT_SUFFIXES = (".npy", ".vti", ".png") + MESH_SUFFIXES
# Voxels per axis when a mesh is read without ``res`` (section 8.2.1 of
# "Procedural Metamaterials" voxelizes at 100^3).
DEFAULT_MESH_RES = 100
MAX_RES = 2048
LUMINANCE_THRESHOLD = 0.5

# Memory model of the homogenization solver (see memory_estimate_bytes). A
# guess on the safe side, to be calibrated against the solver's peak.
BYTES_PER_DOF = 2000
BYTES_PER_CELL = 64
# The solver's all-solid peak per degree of freedom, from the calibrated model
# of engine.physics.periodic_fe (~2.6 kB per voxel in 3D, ~0.9 kB per pixel in
# 2D, i.e. at most 870 B per dof): what `mesoforge homogenize` and the Material
# Matrix node check against the budget.
SOLVER_BYTES_PER_DOF = 900


class GridTooLarge(MemoryLimitError):
    """The solver would need more memory than the budget (:mod:`engine.memory`)."""


# ----------------------------------------------------------------- checks

def _first_bad_index(mask):
    return tuple(int(i) for i in np.argwhere(mask)[0])


def _check_values(grid, name="grid"):
    """Shape, dtype, NaN and range checks; returns float64."""
    a = np.asarray(grid)
    if a.ndim not in (2, 3):
        raise ValueError(f"{name} must be 2D (pixels) or 3D (voxels); got ndim {a.ndim}, shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"{name} has no cells; got shape {a.shape}")
    if not (a.dtype == np.bool_ or np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise ValueError(f"{name} must hold bool, integer or real numbers; got dtype {a.dtype}")
    a = a.astype(np.float64, copy=False)
    nan = np.isnan(a)
    if nan.any():
        raise ValueError(f"{name} contains NaN at index {_first_bad_index(nan)} "
                         f"({int(nan.sum())} NaN cells in all)")
    lo, hi = float(a.min()), float(a.max())
    if lo < 0 or hi > 1:
        raise ValueError(f"{name} values must lie in [0, 1] (1 = solid); got min {lo:g}, max {hi:g}")
    return a


def validate_density(grid, *, cubic=False):
    """Refuse a density grid the solvers cannot use.

    Parameters
    ----------
    grid : (nx, ny) or (nx, ny, nz) array_like
        Bool, integer or float densities.
    cubic : bool
        Also require equal sides (square in 2D).

    Returns
    -------
    numpy.ndarray, float64, same shape (the input itself when already float64)

    Raises
    ------
    ValueError
        Naming the problem: wrong ndim or dtype, no cells, NaN (with the
        first index), values outside [0, 1] (with min and max), no solid at
        all, or unequal sides when ``cubic``.
    """
    a = _check_values(grid)
    if not a.any():
        raise ValueError(f"grid is empty: every one of its {a.size} cells is 0 (no solid)")
    if cubic and len(set(a.shape)) != 1:
        word = "cubic" if a.ndim == 3 else "square"
        raise ValueError(f"grid must be {word} (equal sides) for this solver; got shape {a.shape}")
    return a


# ------------------------------------------------------------------ memory

def _check_shape(shape):
    try:
        s = tuple(int(n) for n in shape)
    except (TypeError, ValueError):
        raise ValueError(f"shape must be a tuple of 2 or 3 positive integers; got {shape!r}") from None
    if len(s) not in (2, 3) or min(s) < 1:
        raise ValueError(f"shape must be a tuple of 2 or 3 positive integers; got {shape!r}")
    return s


def memory_estimate_bytes(shape, *, per_dof_bytes=BYTES_PER_DOF, solid_fraction=1.0):
    """Conservative peak memory of homogenizing a grid of this shape.

    ``bytes = d * cells * solid_fraction * per_dof_bytes + 64 * cells`` with
    ``d`` = 2 or 3 displacement components per periodic node (one node per
    cell). ``per_dof_bytes`` covers per degree of freedom: the fine-level
    element data or assembled rows (81 non-zeros per row for trilinear hexes,
    ~1 kB in CSR), six load cases times a handful of Krylov vectors
    (~250 B), the coarse levels (+1/7 per level) and assembly temporaries.
    The 64 B per cell hold the grid and its masks. Pass the grid's solid
    fraction when the solver drops void cells; the default assumes none is
    dropped. The default 2000 B is an envelope to calibrate against the
    solver's measured peak.

    Parameters
    ----------
    shape : tuple of 2 or 3 int
    per_dof_bytes : float > 0
    solid_fraction : float in [0, 1]

    Returns
    -------
    int, bytes
    """
    s = _check_shape(shape)
    per_dof = float(per_dof_bytes)
    if not per_dof > 0 or not math.isfinite(per_dof):
        raise ValueError(f"per_dof_bytes must be a finite number > 0; got {per_dof_bytes!r}")
    frac = float(solid_fraction)
    if not 0 <= frac <= 1:
        raise ValueError(f"solid_fraction must lie in [0, 1]; got {solid_fraction!r}")
    cells = math.prod(s)
    return int(math.ceil(len(s) * cells * frac * per_dof + cells * BYTES_PER_CELL))


def _shape_text(s):
    if len(set(s)) == 1:
        return f"{s[0]}^{len(s)}"
    return "x".join(str(n) for n in s)


def _gb(n):
    return f"{n / 1e9:.3g} GB"


def check_memory(shape, *, limit_bytes=None, per_dof_bytes=BYTES_PER_DOF, solid_fraction=1.0):
    """Refuse a grid whose homogenization would not fit in memory.

    Parameters
    ----------
    shape : tuple of 2 or 3 int
    limit_bytes : int, optional
        Defaults to :func:`engine.memory.memory_budget` (the available
        memory or ``MESOFORGE_MEMORY_LIMIT``); when that is unknown the
        check passes.
    per_dof_bytes, solid_fraction : see :func:`memory_estimate_bytes`

    Returns
    -------
    int
        The estimate in bytes.

    Raises
    ------
    GridTooLarge
        (a ValueError) "a 300^3 grid needs about X GB, more than the Y GB
        available".
    """
    need = memory_estimate_bytes(shape, per_dof_bytes=per_dof_bytes, solid_fraction=solid_fraction)
    limit = memory_budget() if limit_bytes is None else int(limit_bytes)
    if limit is not None and need > limit:
        raise GridTooLarge(f"a {_shape_text(_check_shape(shape))} grid needs about {_gb(need)}, "
                           f"more than the {_gb(limit)} available; use a coarser resolution",
                           need=need, budget=limit, lower="the resolution", where="resolution")
    return need


# ------------------------------------------------------------ voxelization

@njit(cache=True, nogil=True)
def _edge_value(u, v, p, q, x, y):
    """Edge function of p -> q at (x, y), always evaluated from the lower vertex id.

    Evaluating a shared edge the same way in both of its triangles makes the
    two values exact negatives, so a column through the edge is counted
    exactly once (with the tie rule below).
    """
    if p < q:
        return (u[q] - u[p]) * (y - v[p]) - (v[q] - v[p]) * (x - u[p])
    return -((u[p] - u[q]) * (y - v[q]) - (v[p] - v[q]) * (x - u[q]))


@njit(cache=True, nogil=True)
def _owns_boundary(u, v, p, q, sgn):
    """Top-left rule on the edge p -> q of a triangle oriented by sgn."""
    dx = sgn * (u[q] - u[p])
    dy = sgn * (v[q] - v[p])
    return dy < 0 or (dy == 0 and dx < 0)


@njit(cache=True, nogil=True)
def _scan_triangles(u, v, w, faces, start, stop, diff):
    """Add each triangle's signed crossings of the z-columns to ``diff``.

    ``u, v, w`` are vertex coordinates in voxel-index units (centre of voxel
    i at i). A column (i, j) that crosses a triangle at height ``w_hit``
    gets ``-sign(n_z)`` added at the first centre at or above the hit, so a
    cumulative sum along z is the winding number of each centre.
    """
    nx, ny, nz1 = diff.shape
    for t in range(start, stop):
        a, b, c = faces[t, 0], faces[t, 1], faces[t, 2]
        area2 = (u[b] - u[a]) * (v[c] - v[a]) - (v[b] - v[a]) * (u[c] - u[a])
        if area2 == 0.0:
            continue  # vertical in z: no column crosses it transversally
        sgn = 1.0 if area2 > 0 else -1.0
        i0 = max(0, int(math.ceil(min(u[a], u[b], u[c]))))
        i1 = min(nx - 1, int(math.floor(max(u[a], u[b], u[c]))))
        j0 = max(0, int(math.ceil(min(v[a], v[b], v[c]))))
        j1 = min(ny - 1, int(math.floor(max(v[a], v[b], v[c]))))
        own_ab = _owns_boundary(u, v, a, b, sgn)
        own_bc = _owns_boundary(u, v, b, c, sgn)
        own_ca = _owns_boundary(u, v, c, a, sgn)
        for i in range(i0, i1 + 1):
            x = float(i)
            for j in range(j0, j1 + 1):
                y = float(j)
                wc = sgn * _edge_value(u, v, a, b, x, y)
                if wc < 0 or (wc == 0 and not own_ab):
                    continue
                wa = sgn * _edge_value(u, v, b, c, x, y)
                if wa < 0 or (wa == 0 and not own_bc):
                    continue
                wb = sgn * _edge_value(u, v, c, a, x, y)
                if wb < 0 or (wb == 0 and not own_ca):
                    continue
                total = wa + wb + wc
                if total <= 0:
                    continue
                hit = (wa * w[a] + wb * w[b] + wc * w[c]) / total
                k = int(math.ceil(hit))
                k = 0 if k < 0 else (nz1 - 1 if k > nz1 - 1 else k)
                diff[i, j, k] -= int(sgn)


def _check_res(res):
    if isinstance(res, bool) or not isinstance(res, (int, np.integer)) or not 2 <= res <= MAX_RES:
        raise ValueError(f"res must be an integer in [2, {MAX_RES}] (voxels per axis); got {res!r}")
    return int(res)


def _check_bounds(bounds, vertices):
    if bounds is None:
        b = np.array([vertices.min(axis=0), vertices.max(axis=0)])
    else:
        b = np.asarray(bounds, dtype=np.float64)
        if b.shape != (2, 3) or not np.all(np.isfinite(b)):
            raise ValueError(f"bounds must be finite ((xmin, ymin, zmin), (xmax, ymax, zmax)); "
                             f"got {bounds!r}")
    if np.any(b[1] <= b[0]):
        raise ValueError(f"the cell box must have positive extent on every axis; got min "
                         f"{b[0].tolist()}, max {b[1].tolist()} (a flat mesh?)")
    return b


def voxelize_mesh(vertices, faces, *, res, bounds=None, progress=None):
    """Solid voxels of a closed mesh by the non-zero winding rule along z.

    Voxel ``(i, j, k)`` has its centre at ``lo + (i + 1/2, j + 1/2, k + 1/2) * h``
    with ``h = (hi - lo) / res`` per axis, ``(lo, hi)`` the mesh's bounding
    box or ``bounds``. For each (i, j) column of centres the triangles it
    crosses are found by a 2D point-in-triangle test, and the winding number
    of each centre is the signed count of crossings below it; a centre is
    solid when that number is non-zero, so overlapping closed shells count
    as their union. Columns through shared edges or vertices are counted
    once (top-left rule on exactly antisymmetric edge functions).

    Parameters
    ----------
    vertices : (v, 3) float
    faces : (f, 3) int
        A closed, consistently wound surface (orientation either way).
    res : int in [2, 2048]
        Voxels per axis.
    bounds : ((3,), (3,)) float, optional
        The periodic cell box; voxels outside the mesh are void.
    progress : callable(done, total) -> bool, optional
        Called between chunks of triangles; False raises Cancelled.

    Returns
    -------
    grid : (res, res, res) float64
        1.0 inside, 0.0 outside, ``[x, y, z]`` order.
    """
    res = _check_res(res)
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3 or v.shape[0] == 0 or not np.all(np.isfinite(v)):
        raise ValueError(f"vertices must be a finite, non-empty (v, 3) array; got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be an integer (f, 3) array; got shape {f.shape}, dtype {f.dtype}")
    f = np.ascontiguousarray(f, dtype=np.int64)
    if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
        raise ValueError(f"faces must index vertices 0..{v.shape[0] - 1}; got {f.min()}..{f.max()}")
    b = _check_bounds(bounds, v)
    # Index-space coordinates, computed once per vertex so that every
    # triangle sharing a vertex sees bit-identical numbers.
    idx = (v - b[0]) / ((b[1] - b[0]) / res) - 0.5
    u, vv, w = (np.ascontiguousarray(idx[:, a]) for a in range(3))
    diff = np.zeros((res, res, res + 1), dtype=np.int32)

    def work(start, stop):
        _scan_triangles(u, vv, w, f, start, stop, diff)

    run_chunked(work, f.shape[0], progress, first_chunk=256)
    winding = np.cumsum(diff[:, :, :res], axis=2, dtype=np.int32)
    return (winding != 0).astype(np.float64)


# ----------------------------------------------------------------- readers

def _read_npy(path):
    try:
        a = np.load(path, allow_pickle=False)
    except Exception as exc:  # noqa: BLE001 - any parse failure is a bad file
        raise ValueError(f"could not read {path.name} as a .npy array: {exc}") from None
    if not isinstance(a, np.ndarray):
        raise ValueError(f"{path.name} must hold a single array; got {type(a).__name__}")
    return _check_values(a), {}


def _pick_array(img, array):
    cell, point = list(img.cell_data.keys()), list(img.point_data.keys())
    if array is not None:
        if array in cell:
            return "cell", array
        if array in point:
            return "point", array
        raise ValueError(f"array {array!r} is not in the image; cell arrays {cell}, point arrays {point}")
    if cell:
        return "cell", cell[0]
    if point:
        return "point", point[0]
    raise ValueError("the .vti image holds no point or cell arrays")


def _read_vti(path, array):
    import pyvista as pv

    try:
        img = pv.read(str(path))
    except Exception as exc:  # noqa: BLE001 - VTK raises assorted types
        raise ValueError(f"could not read {path.name} as VTK ImageData: {exc}") from None
    if not isinstance(img, pv.ImageData):
        raise ValueError(f"{path.name} must hold VTK ImageData; got {type(img).__name__}")
    assoc, name = _pick_array(img, array)
    dims = tuple(int(d) for d in img.dimensions)
    data = np.asarray(img.cell_data[name] if assoc == "cell" else img.point_data[name])
    if data.ndim != 1:
        raise ValueError(f"array {name!r} has {data.shape[1]} components per {assoc}; need one (a scalar)")
    shape = tuple(max(d - 1, 1) for d in dims) if assoc == "cell" else dims
    a = _check_values(data.reshape(shape, order="F"), f"array {name!r}")
    info = {"array": name, "association": assoc, "spacing": tuple(float(s) for s in img.spacing),
            "origin": tuple(float(o) for o in img.origin)}
    if a.shape[2] == 1:
        a = np.ascontiguousarray(a[:, :, 0].T[::-1, :])  # [x, y] -> [row, col], row 0 = top
    return a, info


def _read_png(path):
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            im.load()
            mode = im.mode
            if mode.startswith("I"):
                lum = np.asarray(im, dtype=np.float64) / 65535.0  # 16-bit grey
            else:
                rgba = np.asarray(im.convert("RGBA"), dtype=np.float64) / 255.0
                grey = rgba[..., 0] * 0.299 + rgba[..., 1] * 0.587 + rgba[..., 2] * 0.114
                alpha = rgba[..., 3]
                lum = alpha * grey + (1.0 - alpha)  # transparent reads as white paper
    except (UnidentifiedImageError, OSError) as exc:
        raise ValueError(f"could not read {path.name} as a PNG image: {exc}") from None
    grid = (lum < LUMINANCE_THRESHOLD).astype(np.float64)
    return grid, {"mode": mode, "solid_rule": f"luminance < {LUMINANCE_THRESHOLD}",
                  "orientation": "grid[row, col], row 0 = top of the image, x = column"}


def _read_mesh(path, res, bounds, progress):
    import trimesh

    from .mesh_io import load_mesh

    try:
        vertices, faces = load_mesh(path)
    except ValueError:
        raise
    except Exception as exc:  # noqa: BLE001 - trimesh raises assorted types
        raise ValueError(f"could not read {path.name} as a mesh: {exc}") from None
    if faces.shape[0] == 0:
        raise ValueError(f"mesh {path.name} has no triangles")
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    if not mesh.is_watertight:
        edges = np.sort(mesh.edges, axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        raise ValueError(f"mesh {path.name} is not watertight: {int(np.sum(counts != 2))} edges are not "
                         "shared by exactly two triangles; voxelizing needs a closed surface, "
                         "so repair it (fill holes, merge vertices) first")
    if not mesh.is_winding_consistent:
        raise ValueError(f"mesh {path.name} is closed but its triangles are not consistently "
                         "oriented; fix the normals first")
    res = DEFAULT_MESH_RES if res is None else res
    grid = voxelize_mesh(vertices, faces, res=res, bounds=bounds, progress=progress)
    b = _check_bounds(bounds, vertices)
    box = float(np.prod(b[1] - b[0]))
    info = {"res": int(res), "bounds": (tuple(b[0].tolist()), tuple(b[1].tolist())),
            "voxel_size": tuple(((b[1] - b[0]) / res).tolist()),
            "mesh_volume": abs(float(mesh.volume)),
            "mesh_volume_fraction": abs(float(mesh.volume)) / box}
    return grid, info


def _npy_shape(path):
    try:
        return tuple(np.load(path, mmap_mode="r", allow_pickle=False).shape)
    except Exception:  # noqa: BLE001 - object arrays, bad headers: the reader says why
        return None


def _vti_shape(path):
    import re

    with open(path, "rb") as fh:
        head = fh.read(1 << 16).decode("latin-1")
    m = re.search(r'WholeExtent\s*=\s*"([^"]*)"', head)
    try:
        ext = [int(v) for v in m.group(1).split()] if m else []
    except ValueError:
        return None
    if len(ext) != 6:
        return None
    dims = tuple(ext[2 * a + 1] - ext[2 * a] + 1 for a in range(3))  # points: the larger reading
    return dims if dims[2] > 1 else (dims[1], dims[0])


def _png_shape(path):
    from PIL import Image

    try:
        with Image.open(path) as im:
            return (int(im.size[1]), int(im.size[0]))
    except Exception:  # noqa: BLE001 - the reader says why
        return None


def grid_shape_of(path, *, res=None):
    """The grid shape :func:`load_voxel_grid` would return, read from the file's
    header (nothing is loaded), so that a grid too large for memory is refused
    first; None when the header cannot tell (the reader then reports the file).

    ``.npy``: the array's shape; ``.vti``: the point dimensions of
    ``WholeExtent`` (one voxel per point, the larger of the two readings);
    ``.png``: (rows, columns); meshes: ``(res,) * 3`` (default 100).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if not p.is_file():
        return None
    if suffix in MESH_SUFFIXES:
        n = DEFAULT_MESH_RES if res is None else int(res)
        return (n, n, n)
    try:
        reader = {".npy": _npy_shape, ".vti": _vti_shape, ".png": _png_shape}.get(suffix)
        return None if reader is None else reader(p)
    except OSError:
        return None


def load_voxel_grid(path, *, res=None, invert=False, array=None, bounds=None, progress=None):
    """Read a density grid for homogenization from an image, array or mesh.

    Parameters
    ----------
    path : str or os.PathLike
        ``.npy``, ``.vti``, ``.png``, ``.stl``, ``.obj``, ``.ply`` or
        ``.3mf`` (any case); see the module docstring for each format.
    res : int, optional
        Meshes: voxels per axis (default 100). Arrays and images: must be
        None or equal to every side of the stored grid (no resampling).
    invert : bool
        Swap solid and void (``1 - grid``).
    array : str, optional
        ``.vti`` only: the array to read.
    bounds : ((3,), (3,)) float, optional
        Meshes only: the periodic cell box (default: the mesh's bounds).
    progress : callable(done, total) -> bool, optional
        Meshes only, see :func:`voxelize_mesh`.

    Returns
    -------
    grid : numpy.ndarray, float64, values in [0, 1], 1 = solid
        ``[x, y, z]`` voxels or ``[row, col]`` pixels (row 0 = top).
    kind : {"voxels", "pixels"}
    info : dict
        ``source``, ``format``, ``shape``, ``volume_fraction``, ``inverted``
        and per-format details (vti: ``array``, ``association``,
        ``spacing``, ``origin``; png: ``mode``, ``solid_rule``; meshes:
        ``res``, ``bounds``, ``voxel_size``, ``mesh_volume``,
        ``mesh_volume_fraction``).

    Raises
    ------
    ValueError
        Unsupported suffix, missing or unreadable file, non-watertight mesh,
        or a grid refused by :func:`validate_density`.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in INPUT_SUFFIXES:
        raise ValueError(f"path must end in one of {', '.join(INPUT_SUFFIXES)}; got {str(path)!r}")
    if not p.is_file():
        raise ValueError(f"path must be an existing file; got {str(path)!r}")
    if res is not None:
        _check_res(res)
    if array is not None and suffix != ".vti":
        raise ValueError(f"array applies to .vti files only; got {suffix} with array={array!r}")
    if bounds is not None and suffix not in MESH_SUFFIXES:
        raise ValueError(f"bounds applies to meshes only; got {suffix}")
    if suffix in MESH_SUFFIXES:
        grid, info = _read_mesh(p, res, bounds, progress)
    else:
        grid, info = {".npy": lambda: _read_npy(p), ".vti": lambda: _read_vti(p, array),
                      ".png": lambda: _read_png(p)}[suffix]()
        if res is not None and any(n != res for n in grid.shape):
            raise ValueError(f"res={res} applies to meshes; {p.name} already holds a grid of shape "
                             f"{grid.shape} and is not resampled")
    if invert:
        grid = 1.0 - grid
    grid = np.ascontiguousarray(validate_density(grid))
    kind = "voxels" if grid.ndim == 3 else "pixels"
    info = {"source": str(p), "format": suffix, "shape": grid.shape,
            "volume_fraction": float(grid.mean()), "inverted": bool(invert), **info}
    return grid, kind, info
