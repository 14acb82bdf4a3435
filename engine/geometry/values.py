"""Values of the geometry family that travel on graph ports: skeletons (points,
edge chains, line and surface elements), solids, voxel models, sampled fields
and meshes.  Immutable once produced.

Arrays inside are set read-only on construction so a downstream node cannot
change a cached upstream result by accident; :func:`frozen_array` and
:func:`read_only_array` do that for every family's values.  No graph import
here: the graph core knows no family (``engine.nodes.codecs`` registers how
values are kept in project files).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["frozen_array", "read_only_array", "Point", "EdgeChain", "LineElement", "SurfaceElement",
           "Skeleton", "Solid", "VoxelModel", "ImportedVoxels", "Field", "MeshValue"]


def frozen_array(a, dtype=np.float64) -> np.ndarray:
    """A read-only copy of ``a`` as ``dtype`` (the values' arrays cannot be changed downstream)."""
    arr = np.array(a, dtype=dtype, copy=True)
    arr.setflags(write=False)
    return arr


def read_only_array(a, dtype) -> np.ndarray:
    """Like `frozen_array`, but an array that is already read-only is kept, not copied."""
    arr = np.asarray(a, dtype=dtype)
    return arr if not arr.flags.writeable else frozen_array(arr, dtype)


@dataclass(frozen=True)
class Point:
    """A vertex position, unit-cell coordinates."""

    xyz: np.ndarray  # (3,) float64

    def __post_init__(self):
        object.__setattr__(self, "xyz", frozen_array(self.xyz).reshape(3))


@dataclass(frozen=True)
class EdgeChain:
    """An ordered vertex path with a smoothness flag (paper 6.1).

    points : (n, 3) float64; closed : the path returns to its first vertex;
    period : (3,) translation for curves that continue into the next cell, or None.
    """

    points: np.ndarray
    smooth: bool
    closed: bool = False
    period: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "points", frozen_array(self.points).reshape(-1, 3))
        if self.period is not None:
            object.__setattr__(self, "period", frozen_array(self.period).reshape(3))


@dataclass(frozen=True)
class LineElement:
    """A thickened-line skeleton element: dense polyline + thickness per vertex.

    polyline : (m, 3) float64, unit-cell coordinates.
    thickness : (m,) float64, diameter at each polyline vertex.
    control_points : (k, 3) float64, the user's vertices (for display).
    """

    polyline: np.ndarray
    thickness: np.ndarray
    control_points: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "polyline", frozen_array(self.polyline).reshape(-1, 3))
        object.__setattr__(self, "thickness", frozen_array(self.thickness).reshape(-1))
        object.__setattr__(self, "control_points", frozen_array(self.control_points).reshape(-1, 3))
        if len(self.thickness) != len(self.polyline):
            raise ValueError("LineElement: thickness must have one value per polyline vertex")

    def transformed(self, matrix: np.ndarray, offset: np.ndarray, scale: float) -> "LineElement":
        return LineElement(self.polyline @ matrix.T + offset, self.thickness * scale,
                           self.control_points @ matrix.T + offset)


@dataclass(frozen=True)
class SurfaceElement:
    """A thickened-surface skeleton element (triangle mesh + thickness per vertex)."""

    vertices: np.ndarray
    faces: np.ndarray
    thickness: np.ndarray
    boundary: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __post_init__(self):
        object.__setattr__(self, "vertices", frozen_array(self.vertices).reshape(-1, 3))
        object.__setattr__(self, "faces", frozen_array(self.faces, np.int64).reshape(-1, 3))
        object.__setattr__(self, "thickness", frozen_array(self.thickness).reshape(-1))
        object.__setattr__(self, "boundary", frozen_array(self.boundary).reshape(-1, 3))

    def transformed(self, matrix: np.ndarray, offset: np.ndarray, scale: float) -> "SurfaceElement":
        faces = self.faces if np.linalg.det(matrix) > 0 else self.faces[:, ::-1]
        return SurfaceElement(self.vertices @ matrix.T + offset, faces, self.thickness * scale,
                              self.boundary @ matrix.T + offset)


@dataclass(frozen=True)
class Skeleton:
    """A set of line and surface elements."""

    elements: tuple = ()

    @property
    def lines(self) -> list[LineElement]:
        return [e for e in self.elements if isinstance(e, LineElement)]

    @property
    def surfaces(self) -> list[SurfaceElement]:
        return [e for e in self.elements if isinstance(e, SurfaceElement)]

    def transformed(self, matrix, offset, scale=1.0) -> "Skeleton":
        m = np.asarray(matrix, float)
        o = np.asarray(offset, float)
        return Skeleton(tuple(e.transformed(m, o, float(scale)) for e in self.elements))

    def __add__(self, other: "Skeleton") -> "Skeleton":
        return Skeleton(self.elements + other.elements)


@dataclass(frozen=True)
class Solid:
    """A tileable solid over the periodic box cell.

    sdf : (nx, ny, nz) float32 signed distance (negative inside) at nodes
        ``i * Lx / nx`` etc. (cell units), exactly periodic, so opposite
        faces agree by construction; (N, N, N) on the unit cube.
    vertices, faces : the single-cell mesh from marching cubes (closed), mm.
    cell_size : model units (mm) per cell unit: the edge of the unit cube.
    periodic : False for a solid that is not a tileable cell (a preview of a
        sub-box of a part): it is shown and exported once, never tiled.
    cell : (Lx, Ly, Lz) box edges in cell units (default the unit cube); the
        tile measures ``cell_size * cell`` mm (:attr:`box`).
    origin : (x, y, z) mm, where the box's low corner sits in the model: the
        grid and the mesh are box-local (``[0, box]``, what the viewport shows
        and tiling repeats); exports place the mesh at ``origin`` (a sub-box of
        an implicit medium keeps its place; a unit cell has origin 0).
    """

    sdf: np.ndarray
    vertices: np.ndarray
    faces: np.ndarray
    cell_size: float = 1.0
    periodic: bool = True
    cell: tuple = (1.0, 1.0, 1.0)
    origin: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "sdf", frozen_array(self.sdf, np.float32))
        object.__setattr__(self, "vertices", frozen_array(self.vertices).reshape(-1, 3))
        object.__setattr__(self, "faces", frozen_array(self.faces, np.int64).reshape(-1, 3))
        cell = tuple(float(v) for v in self.cell)
        if len(cell) != 3 or not all(np.isfinite(v) and v > 0 for v in cell):
            raise ValueError(f"Solid: cell must be three box edges > 0; got {self.cell!r}")
        object.__setattr__(self, "cell", cell)
        origin = tuple(float(v) for v in self.origin)
        if len(origin) != 3 or not all(np.isfinite(v) for v in origin):
            raise ValueError(f"Solid: origin must be three finite coordinates (mm); got {self.origin!r}")
        object.__setattr__(self, "origin", origin)

    @property
    def resolution(self) -> int:
        """Grid nodes along the longest box edge (N of an N x N x N unit-cube grid)."""
        return int(max(self.sdf.shape))

    @property
    def grid_shape(self) -> tuple:
        """(nx, ny, nz) grid nodes per axis."""
        return tuple(int(n) for n in self.sdf.shape)

    @property
    def is_unit_cube(self) -> bool:
        return self.cell == (1.0, 1.0, 1.0)

    @property
    def box(self) -> np.ndarray:
        """(3,) float64, the tile's edges in model units: ``cell_size * cell``."""
        return self.cell_size * np.array(self.cell, dtype=np.float64)

    @property
    def spacing(self) -> np.ndarray:
        """(3,) float64 node spacing in model units, ``box / grid_shape``."""
        return self.box / np.array(self.sdf.shape, dtype=np.float64)

    @property
    def volume_fraction(self) -> float:
        return float(np.count_nonzero(self.sdf < 0) / self.sdf.size)


@dataclass(frozen=True)
class VoxelModel:
    """Occupancy voxels of a solid plus its base material (paper 6.5 Voxel node).

    occupancy : (nx, ny, nz) bool, voxel (i, j, k) covers ``[i, i+1) * Lx / nx``
        etc. of the solid's box (``solid.cell``); (N, N, N) on the unit cube.
    E : Young's modulus (Pa), nu : Poisson's ratio, rho : density (kg/m^3).
    """

    occupancy: np.ndarray
    E: float
    nu: float
    rho: float
    solid: Solid

    def __post_init__(self):
        object.__setattr__(self, "occupancy", frozen_array(self.occupancy, bool))

    @property
    def volume_fraction(self) -> float:
        return float(self.occupancy.mean())


@dataclass(frozen=True)
class Field:
    """Samples on a regular grid over an axis-aligned box (port type "Field").

    values : grid_shape + component_shape float64, read-only; the grid is
        indexed like an image / voxel grid, ``[y, x]`` or ``[z, y, x]``, one
        sample per cell at the cell centre.
    lo, hi : (ndim,) float64, box corners in ``(x, y[, z])`` order.
    kind : "scalar", "vector" or "tensor" (trailing component axes 0, 1, 2).
    """

    values: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    kind: str = "scalar"

    def __post_init__(self):
        object.__setattr__(self, "values", frozen_array(self.values))
        object.__setattr__(self, "lo", frozen_array(self.lo).reshape(-1))
        object.__setattr__(self, "hi", frozen_array(self.hi).reshape(-1))
        extra = {"scalar": 0, "vector": 1, "tensor": 2}.get(self.kind)
        if extra is None:
            raise ValueError(f"Field: kind must be 'scalar', 'vector' or 'tensor'; got {self.kind!r}")
        if self.lo.shape != self.hi.shape or self.values.ndim != self.lo.size + extra \
                or np.any(self.hi <= self.lo):
            raise ValueError(f"Field: values {self.values.shape} ({self.kind}) do not fit a box "
                             f"lo={self.lo.tolist()}, hi={self.hi.tolist()} with hi > lo")

    @property
    def ndim(self) -> int:
        return int(self.lo.size)

    @property
    def grid_shape(self) -> tuple:
        return tuple(self.values.shape[:self.ndim])

    @property
    def spacing(self) -> np.ndarray:
        """(ndim,) cell size in ``(x, y[, z])`` order."""
        return (self.hi - self.lo) / np.array(self.grid_shape[::-1], dtype=np.float64)


@dataclass(frozen=True)
class MeshValue:
    """A closed triangle mesh read from a file (port type "Mesh"), in mm.

    vertices : (v, 3) float64, read-only
    faces : (f, 3) int64, read-only, outward (counter-clockwise) winding
    path : str, the file it was read from ("" when made in memory)

    Has ``vertices`` and ``faces`` like a trimesh, so the kernels of
    engine.phasor.domain take it as it is.
    """

    vertices: np.ndarray
    faces: np.ndarray
    path: str = ""

    def __post_init__(self):
        object.__setattr__(self, "vertices", read_only_array(self.vertices, np.float64).reshape(-1, 3))
        object.__setattr__(self, "faces", read_only_array(self.faces, np.int64).reshape(-1, 3))

    @property
    def bounds(self) -> tuple:
        """(lo, hi) (3,) float64 mm, the bounding box."""
        return self.vertices.min(axis=0), self.vertices.max(axis=0)


@dataclass(frozen=True)
class ImportedVoxels(VoxelModel):
    """Voxels read from a file (port type "Voxel").

    density : float64, read-only, values in [0, 1] (1 = solid), the grid as
        :func:`load_voxel_grid` returns it: ``[x, y, z]`` voxels (a cube) or
        ``[row, col]`` pixels (row 0 = top of the image); what is homogenized.
    kind : "voxels" (3D) or "pixels" (2D, plane stress).
    info : the reader's description of the file (source, format, shape,
        volume fraction, per-format details).

    ``occupancy`` (``density >= 0.5``) and ``solid`` (that level set, no mesh)
    are the `VoxelModel` view: ``[x, y, z]`` over the unit cube, or for pixels
    a one-pixel-thick ``(nx, ny, 1)`` slab of the box ``(nx, ny, 1) / max(nx, ny)``.
    """

    density: np.ndarray = None
    kind: str = "voxels"
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "density", read_only_array(self.density, np.float64))
        if self.kind not in ("voxels", "pixels") or self.density.ndim != (3 if self.kind == "voxels" else 2):
            raise ValueError(f"ImportedVoxels: a {self.kind!r} grid cannot have shape {self.density.shape}")

    @classmethod
    def from_grid(cls, grid, kind: str, info: dict, *, E: float, nu: float, rho: float) -> "ImportedVoxels":
        """The value of a grid read by `load_voxel_grid` (``grid`` is kept, made read-only)."""
        grid = np.asarray(grid, dtype=np.float64)
        grid.setflags(write=False)
        xyz = grid if kind == "voxels" else grid[::-1, :].T[:, :, None]     # [row, col] -> [x, y, 0]
        cell = (1.0, 1.0, 1.0) if kind == "voxels" else tuple(n / max(xyz.shape) for n in xyz.shape)
        empty = np.zeros((0, 3))
        solid = Solid((0.5 - xyz).astype(np.float32), empty, empty, cell=cell)
        return cls(xyz >= 0.5, E, nu, rho, solid, density=grid, kind=kind, info=dict(info))
