"""Exemplars for reconstruction: signed distances sampled on a regular grid.

An `Exemplar` is what parameter fitting (paper 004, section 6.1) matches:
points (n, 3) mm, one per node of a regular (nx, ny, nz) grid in C order
(index (i, j, k) at row ``(i * ny + j) * nz + k``), and the signed distance
there (mm, negative inside).  The grid order is what the Fourier loss
transforms, so `grid()` reshapes the distances to `shape`.

Sources:

* `Exemplar.from_sdf` — eq. 37, the synthetic data: equidistant points on
  the slices of a cube (the paper samples slices of a unit sphere; a cube of
  edge `size` keeps the grid regular for the DFT), optionally rotated about
  its centre, with Gaussian noise on the point positions, the SDF evaluated
  at the perturbed points;
* `Exemplar.from_voxels` — a voxel grid, array index (i, j, k) at
  ``origin + spacing * (i, j, k)``;
* `load_exemplar` — a .npy, .vti or .tif / .tiff file.

An occupancy grid (bool, or only the values 0 and 1; unsigned integers with
only 0 and 255, as binary TIFF masks store them) is turned into a signed
distance with `scipy.ndimage.distance_transform_edt`: for a solid voxel
minus its distance to the nearest empty voxel, for an empty voxel its
distance to the nearest solid one, each reduced by half the smallest
spacing so that the surface lies midway between voxel centres (exact for a
plane through the voxel faces along an axis, within half a voxel otherwise).
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .values import SDF, as_points

__all__ = ["Exemplar", "load_exemplar", "occupancy_to_sdf", "MIN_SAMPLES"]

MIN_SAMPLES = 4        # samples per axis at least


def _vec3(name: str, value, positive: bool = False) -> np.ndarray:
    v = np.array(value, dtype=np.float64)
    if v.ndim == 0:
        v = np.full(3, float(v))
    if v.shape != (3,) or not np.all(np.isfinite(v)) or (positive and np.any(v <= 0)):
        what = "> 0" if positive else "finite"
        raise ValueError(f"{name} must be a {what} number or three, got {value!r}")
    return v


def _check_grid(array, source: str) -> np.ndarray:
    a = np.asarray(array)
    if a.ndim != 3:
        raise ValueError(f"{source}: a voxel grid must be 3D, got shape {a.shape}")
    if min(a.shape) < MIN_SAMPLES:
        raise ValueError(f"{source}: at least {MIN_SAMPLES} samples per axis are needed, got shape {a.shape}")
    if a.dtype.kind not in "biuf":
        raise ValueError(f"{source}: voxels must be numbers or booleans, got dtype {a.dtype}")
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        raise ValueError(f"{source}: voxels hold NaN or infinite values")
    return a


def _is_occupancy(a: np.ndarray) -> bool:
    if a.dtype == np.bool_:
        return True
    values = np.unique(a)
    if values.size > 2:
        return False
    if set(values.tolist()) <= {0, 1}:
        return True
    return a.dtype.kind == "u" and set(values.tolist()) <= {0, 255}


def occupancy_to_sdf(occupied: np.ndarray, spacing=1.0) -> np.ndarray:
    """A signed distance (mm, float64, negative in solid voxels) from a 3D occupancy grid.

    Raises
    ------
    ValueError
        If the grid is all solid or all empty (no surface to measure from).
    """
    from scipy.ndimage import distance_transform_edt
    occ = np.asarray(occupied) != 0
    h = _vec3("spacing", spacing, positive=True)
    if occ.all() or not occ.any():
        raise ValueError("occupancy grid is all " + ("solid" if occ.all() else "empty")
                         + ": it has no surface to measure a signed distance from")
    inside = distance_transform_edt(occ, sampling=h)
    outside = distance_transform_edt(~occ, sampling=h)
    half = 0.5 * float(h.min())
    return np.where(occ, -(inside - half), outside - half)


@dataclass(frozen=True, eq=False)
class Exemplar:
    """Signed distances sampled on a regular grid of points.

    points : (n, 3) float64 mm, the grid nodes in C order of `shape` (possibly
        rotated and perturbed); distances : (n,) float64 mm; shape : (nx, ny, nz),
        n = nx * ny * nz, each >= `MIN_SAMPLES`.

    Raises
    ------
    ValueError
        If the shapes disagree, an axis has fewer than `MIN_SAMPLES` samples, or a
        value is NaN / infinite.
    """

    points: np.ndarray
    distances: np.ndarray
    shape: tuple

    def __post_init__(self):
        shape = tuple(int(s) for s in np.atleast_1d(self.shape))
        if len(shape) != 3 or min(shape) < MIN_SAMPLES:
            raise ValueError(f"shape must be three axes of >= {MIN_SAMPLES} samples, got {self.shape!r}")
        p = as_points(self.points)
        d = np.ascontiguousarray(self.distances, dtype=np.float64).reshape(-1)
        n = int(np.prod(shape))
        if p.shape[0] != n or d.shape[0] != n:
            raise ValueError(f"points {p.shape} and distances {d.shape} must both have "
                             f"{n} = prod(shape {shape}) rows")
        if not np.all(np.isfinite(d)):
            raise ValueError("distances hold NaN or infinite values")
        p.setflags(write=False)
        d.setflags(write=False)
        for k, v in (("points", p), ("distances", d), ("shape", shape)):
            object.__setattr__(self, k, v)

    def grid(self) -> np.ndarray:
        """The distances as a `shape` array (what the Fourier loss compares)."""
        return self.distances.reshape(self.shape)

    @classmethod
    def from_sdf(cls, sdf: SDF, centre, size: float, resolution, noise_sd: float = 0.0,
                 rotation=None, seed: int = 0) -> "Exemplar":
        """Eq. 37: `sdf.distance` on an equidistant grid through a cube.

        Parameters
        ----------
        sdf : SDF.
        centre : (3,) mm, the cube's centre.
        size : float > 0, mm, the cube's edge; nodes at ``centre + R (-size/2 + size * i /
            (res - 1))`` per axis (the faces included).
        resolution : int or three ints >= `MIN_SAMPLES`, nodes per axis.
        noise_sd : float >= 0, mm, standard deviation of the Gaussian noise added to each
            point coordinate (`numpy.random.default_rng(seed)`).
        rotation : (3, 3) rotation matrix (orthonormal, det +1) or None.
        seed : int >= 0.

        Raises
        ------
        ValueError
            Naming the parameter out of range.
        """
        if not isinstance(sdf, SDF):
            raise ValueError(f"sdf must be an SDF, got {type(sdf).__name__}")
        c = _vec3("centre", centre)
        s = float(size)
        if not (np.isfinite(s) and s > 0):
            raise ValueError(f"size (the cube's edge) must be > 0 mm, got {size!r}")
        res = np.array(resolution).reshape(-1)
        if res.size == 1:
            res = np.repeat(res, 3)
        if res.shape != (3,) or res.dtype.kind not in "iu" or np.any(res < MIN_SAMPLES):
            raise ValueError(f"resolution must be an int or three ints >= {MIN_SAMPLES}, got {resolution!r}")
        sd = float(noise_sd)
        if not (np.isfinite(sd) and sd >= 0):
            raise ValueError(f"noise_sd must be >= 0 mm, got {noise_sd!r}")
        if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ValueError(f"seed must be an int >= 0, got {seed!r}")
        axes = [np.linspace(-0.5 * s, 0.5 * s, int(n)) for n in res]
        local = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        if rotation is not None:
            r = np.array(rotation, dtype=np.float64)
            if (r.shape != (3, 3) or not np.all(np.isfinite(r))
                    or not np.allclose(r @ r.T, np.eye(3), atol=1e-6) or np.linalg.det(r) < 0):
                raise ValueError(f"rotation must be a (3, 3) rotation matrix (orthonormal, det +1), "
                                 f"got {rotation!r}")
            local = local @ r.T
        pts = c + local
        if sd > 0:
            pts = pts + np.random.default_rng(int(seed)).normal(0.0, sd, pts.shape)
        return cls(pts, sdf.distance(pts), tuple(int(n) for n in res))

    @classmethod
    def from_voxels(cls, array, spacing=1.0, origin=(0.0, 0.0, 0.0), *,
                    source: str = "voxel grid") -> "Exemplar":
        """An exemplar from a 3D grid: voxel (i, j, k) at ``origin + spacing * (i, j, k)`` mm.

        array : (nx, ny, nz), signed distances in mm (float), or an occupancy grid (see the
            module docstring), converted with `occupancy_to_sdf`.
        spacing : float or (3,) > 0 mm; origin : (3,) mm.
        source : named in error messages (the file it came from).

        Raises
        ------
        ValueError
            If the array is not 3D, has fewer than `MIN_SAMPLES` samples on an axis,
            holds NaN, or is an occupancy grid without a surface; or on a bad spacing /
            origin.
        """
        a = _check_grid(array, source)
        h = _vec3("spacing", spacing, positive=True)
        o = _vec3("origin", origin)
        if _is_occupancy(a):
            try:
                d = occupancy_to_sdf(a, h)
            except ValueError as exc:
                raise ValueError(f"{source}: {exc}") from None
        else:
            d = a.astype(np.float64)
        axes = [o[i] + h[i] * np.arange(a.shape[i]) for i in range(3)]
        pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        return cls(pts, d.reshape(-1), a.shape)


def _read_npy(path: Path):
    array = np.load(path, allow_pickle=False)
    side = path.with_suffix(".json")
    spacing, origin = 1.0, (0.0, 0.0, 0.0)
    if side.exists():
        meta = json.loads(side.read_text())
        spacing = meta.get("spacing", spacing)
        origin = meta.get("origin", origin)
    return array, spacing, origin


def _read_vti(path: Path):
    import pyvista
    with warnings.catch_warnings(record=True) as caught:   # VTK reports a bad file as a warning
        warnings.simplefilter("always")
        grid = pyvista.read(str(path))
    if not isinstance(grid, pyvista.ImageData) or grid.n_points == 0:
        why = "; ".join(str(w.message).strip() for w in caught)[:300]
        raise ValueError(f"{path}: cannot read VTK image data from it" + (f" ({why})" if why else ""))
    dims = tuple(int(d) for d in grid.dimensions)
    spacing, origin = tuple(grid.spacing), tuple(grid.origin)
    if grid.point_data.keys():
        data = grid.point_data.active_scalars
        if data is None:
            data = grid.point_data[grid.point_data.keys()[0]]
    elif grid.cell_data.keys():
        data = grid.cell_data.active_scalars
        if data is None:
            data = grid.cell_data[grid.cell_data.keys()[0]]
        dims = tuple(max(d - 1, 1) for d in dims)
        origin = tuple(np.add(origin, 0.5 * np.asarray(spacing)))
    else:
        raise ValueError(f"{path}: the image holds no point or cell array")
    data = np.asarray(data)
    if data.ndim != 1:
        raise ValueError(f"{path}: the voxel array must be scalar, got {data.shape[1:]} components")
    return data.reshape(dims, order="F"), spacing, origin   # VTK runs x fastest


def _read_tif(path: Path):
    import tifffile
    stack = np.asarray(tifffile.imread(str(path)))
    if stack.ndim != 3:
        raise ValueError(f"{path}: a TIFF stack must be 3D (pages, rows, columns), got shape {stack.shape}")
    side = path.with_suffix(".json")
    spacing, origin = 1.0, (0.0, 0.0, 0.0)
    if side.exists():
        meta = json.loads(side.read_text())
        spacing = meta.get("spacing", spacing)
        origin = meta.get("origin", origin)
    return np.transpose(stack, (2, 1, 0)), spacing, origin   # (z, y, x) pages -> (x, y, z)


_READERS = {".npy": _read_npy, ".vti": _read_vti, ".tif": _read_tif, ".tiff": _read_tif}


def load_exemplar(path) -> Exemplar:
    """An `Exemplar` from a voxel file.

    * ``.npy``: a 3D array (x, y, z); spacing and origin from a sidecar ``<stem>.json``
      (``{"spacing": h or [hx, hy, hz], "origin": [x, y, z]}``, mm), else 1 and 0;
    * ``.vti``: VTK image data (pyvista), its spacing and origin, the active (else first)
      point array, or a cell array at the cell centres;
    * ``.tif`` / ``.tiff``: a stack of pages (z, y, x), transposed to (x, y, z); spacing
      and origin from a ``<stem>.json`` sidecar as for .npy.

    Signed distances or occupancy grids (see the module docstring).

    Raises
    ------
    ValueError
        Naming the file: an unknown suffix, a missing or unreadable file, a grid that is
        not 3D, fewer than `MIN_SAMPLES` samples per axis, NaN values.
    """
    p = Path(path)
    reader = _READERS.get(p.suffix.lower())
    if reader is None:
        raise ValueError(f"{p}: unknown exemplar format {p.suffix!r}, expected one of {sorted(_READERS)}")
    if not p.is_file():
        raise ValueError(f"{p}: no such file")
    try:
        array, spacing, origin = reader(p)
    except ValueError as exc:
        msg = str(exc)
        raise ValueError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None
    except Exception as exc:          # a corrupt file: name it, keep the reader's reason
        raise ValueError(f"{p}: cannot read it ({type(exc).__name__}: {exc})") from None
    try:
        return Exemplar.from_voxels(array, spacing, origin, source=str(p))
    except ValueError as exc:
        msg = str(exc)
        raise ValueError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None
