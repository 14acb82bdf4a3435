"""Typed values that travel on ports.  Immutable once produced.

Arrays inside are set read-only on construction so a downstream node cannot
change a cached upstream result by accident.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _frozen(a, dtype=np.float64) -> np.ndarray:
    arr = np.array(a, dtype=dtype, copy=True)
    arr.setflags(write=False)
    return arr


def _read_only(a, dtype) -> np.ndarray:
    """Like `_frozen`, but an array that is already read-only is kept, not copied."""
    arr = np.asarray(a, dtype=dtype)
    return arr if not arr.flags.writeable else _frozen(arr, dtype)


@dataclass(frozen=True)
class Point:
    """A vertex position, unit-cell coordinates."""

    xyz: np.ndarray  # (3,) float64

    def __post_init__(self):
        object.__setattr__(self, "xyz", _frozen(self.xyz).reshape(3))


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
        object.__setattr__(self, "points", _frozen(self.points).reshape(-1, 3))
        if self.period is not None:
            object.__setattr__(self, "period", _frozen(self.period).reshape(3))


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
        object.__setattr__(self, "polyline", _frozen(self.polyline).reshape(-1, 3))
        object.__setattr__(self, "thickness", _frozen(self.thickness).reshape(-1))
        object.__setattr__(self, "control_points", _frozen(self.control_points).reshape(-1, 3))
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
        object.__setattr__(self, "vertices", _frozen(self.vertices).reshape(-1, 3))
        object.__setattr__(self, "faces", _frozen(self.faces, np.int64).reshape(-1, 3))
        object.__setattr__(self, "thickness", _frozen(self.thickness).reshape(-1))
        object.__setattr__(self, "boundary", _frozen(self.boundary).reshape(-1, 3))

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
    """

    sdf: np.ndarray
    vertices: np.ndarray
    faces: np.ndarray
    cell_size: float = 1.0
    periodic: bool = True
    cell: tuple = (1.0, 1.0, 1.0)

    def __post_init__(self):
        object.__setattr__(self, "sdf", _frozen(self.sdf, np.float32))
        object.__setattr__(self, "vertices", _frozen(self.vertices).reshape(-1, 3))
        object.__setattr__(self, "faces", _frozen(self.faces, np.int64).reshape(-1, 3))
        cell = tuple(float(v) for v in self.cell)
        if len(cell) != 3 or not all(np.isfinite(v) and v > 0 for v in cell):
            raise ValueError(f"Solid: cell must be three box edges > 0; got {self.cell!r}")
        object.__setattr__(self, "cell", cell)

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
        object.__setattr__(self, "occupancy", _frozen(self.occupancy, bool))

    @property
    def volume_fraction(self) -> float:
        return float(self.occupancy.mean())


@dataclass(frozen=True)
class Stiffness:
    """Homogenized elastic stiffness of a periodic cell (paper 6.6).

    C : (6, 6) Voigt stiffness, engineering shear strains, order
        (xx, yy, zz, yz, xz, xy); (3, 3) (xx, yy, xy) for 2D plane stress.
    E, nu, rho : base material; density : solid volume fraction of the cell;
    constants : engineering constants (E_x ... nu_avg, eqs. 1-8 of Liu et al.);
    symmetry : detected symmetry class; zener : Zener ratio (cubic only, else None);
    dropped_fraction : material removed as disconnected islands (fraction of the cell).
    resolution : voxels along the longest cell edge of the solve.
    grid_shape : (nx, ny, nz) voxels of the solve, or None (``resolution``^3).
    cell : (Lx, Ly, Lz) box the solve covered (cell units), or None (the unit cube).
    """

    C: np.ndarray
    E: float
    nu: float
    rho: float
    density: float
    constants: dict
    symmetry: str
    zener: float | None
    dropped_fraction: float
    iterations: int
    resolution: int
    grid_shape: tuple | None = None
    cell: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "C", _frozen(self.C))

    @property
    def S(self) -> np.ndarray:
        return np.linalg.inv(self.C)

    @property
    def effective_density(self) -> float:
        """Mass per cell volume (kg/m^3): base density times solid fraction."""
        return self.rho * self.density

    def summary(self) -> dict:
        return {"C": self.C.tolist(), "density": self.density, "effective_density": self.effective_density,
                "symmetry": self.symmetry, "zener": self.zener, "dropped_fraction": self.dropped_fraction,
                "iterations": self.iterations, "resolution": self.resolution, "E": self.E, "nu": self.nu,
                "rho": self.rho, **self.constants,
                **({} if self.grid_shape is None else {"grid_shape": list(self.grid_shape)}),
                **({} if self.cell is None else {"cell": list(self.cell)})}


@dataclass(frozen=True)
class TilingValue:
    """A grown tiling with the tile set it came from (port type "Tiling").

    tiling : engine.growth.Tiling (tile indices read-only); tileset :
    engine.growth.TileSet. Both are immutable; downstream nodes render or
    homogenize the tiling without knowing where the set was loaded from.

    How this evaluation made it, for replaying the growth (both None when the
    tiling was restored from a project file or loaded):

    steps : (n_events, 2) int32, read-only, or None
        ``[flat cell index, tile]`` in the order cells were decided; the flat
        index is row-major over ``tiling.tiles`` and tile -1 marks a defect
        forming (``Tiling.steps``).
    start_tiles : int32 array of the grid shape, read-only, or None
        The grid before this growth's first step: all UNASSIGNED (-2) for a
        fresh growth; for a local regrowth the previous tiling with the
        regrown cells (painted region plus margin) set to UNASSIGNED.
        Writing each step's tile into a copy of it gives ``tiling.tiles``.
    """

    tiling: object
    tileset: object
    steps: np.ndarray | None = None
    start_tiles: np.ndarray | None = None

    def __post_init__(self):
        if self.steps is not None:
            object.__setattr__(self, "steps", _read_only(self.steps, np.int32).reshape(-1, 2))
        if self.start_tiles is not None:
            start = _read_only(self.start_tiles, np.int32)
            if start.shape != self.tiling.tiles.shape:
                raise ValueError(f"TilingValue: start_tiles has shape {start.shape}, the tiling "
                                 f"{self.tiling.tiles.shape}")
            object.__setattr__(self, "start_tiles", start)

    @property
    def ndim(self) -> int:
        return int(self.tiling.tiles.ndim)


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
        object.__setattr__(self, "values", _frozen(self.values))
        object.__setattr__(self, "lo", _frozen(self.lo).reshape(-1))
        object.__setattr__(self, "hi", _frozen(self.hi).reshape(-1))
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
        object.__setattr__(self, "vertices", _read_only(self.vertices, np.float64).reshape(-1, 3))
        object.__setattr__(self, "faces", _read_only(self.faces, np.int64).reshape(-1, 3))

    @property
    def bounds(self) -> tuple:
        """(lo, hi) (3,) float64 mm, the bounding box."""
        return self.vertices.min(axis=0), self.vertices.max(axis=0)


@dataclass(frozen=True, eq=False)
class PhasorFieldsValue:
    """Painted control fields of phasor infill (port type "PhasorFields").

    fields : engine.phasor.PhasorFields, D, F, Gamma on an (nz, ny, nx) grid
        over the box ``fields.lo .. fields.hi`` (mm).
    domain : MeshValue or None, the part to fill (None: the whole box).
    changed : (slice, slice, slice) or None
        ``[z, y, x]`` cells that differ from this node's previous result
        (all three ``slice(0, 0)`` when none do); None when there is no
        previous result to compare with (everything is new).
    n_strokes : int, brush strokes painted over the initial fields.
    """

    fields: object
    domain: MeshValue | None = None
    changed: tuple | None = None
    n_strokes: int = 0


@dataclass(frozen=True)
class SliceEnergy:
    """Singularity energy of one slice (port type "Energy"; Tricard et al. eq. 10).

    value : float, F_S(q), the fraction of the slice's part pixels where the
        singularity measure S(x) of p_v or of p_w exceeds q (NaN when no
        pixel of the slice lies inside the part).
    v, w : float, F_S(q) of p_v alone and of p_w alone.
    q : float, the threshold.
    pixels : int, pixels counted (|Omega|: inside the part, off the slice border).
    state : str, which noise was measured ("raw", "aligned", "aligned+filtered").
    engine : str, the evaluator of the slice ("gpu" or "numpy").
    """

    value: float
    v: float
    w: float
    q: float
    pixels: int
    state: str
    engine: str = ""

    def summary(self) -> dict:
        return {"F_S": self.value, "F_S_v": self.v, "F_S_w": self.w, "q": self.q,
                "pixels": self.pixels, "state": self.state, "engine": self.engine}


# ---------------------------------------------------------------- reaction-diffusion growth
# (Garnier, Schmidt & Rohmer 2022).  Grids are indexed [y, x] / [z, y, x];
# tensor and rotation components are ordered (x, y[, z]).


@dataclass(frozen=True, eq=False)
class DesignValue:
    """A topology-optimised design (port type "Design").

    rho : grid_shape float64, read-only, element densities in [0, 1].
    sigma : (n_cases,) + grid_shape + (d, d) float64, read-only, element
        stress tensors per load case (components (x, y[, z])).
    sigma_combined : grid_shape + (d, d) float64, read-only, the tensor that
        orients the growth (the single case's stress, or the load cases
        combined / the optimised orientation for several cases).
    rotation : grid_shape + (d, d) float64, read-only, columns = principal
        directions sorted by |sigma_i| descending.
    principal : grid_shape + (d,) float64, read-only, the principal values
        of ``sigma_combined`` along the columns of ``rotation``.
    problem : the engine's topology-optimisation problem (JSON-able).
    result : the optimiser's own result object (history, compliance, timing).
    lo, hi : (d,) float64, the design box in element units, (x, y[, z]).
    seconds : float, wall time of the optimisation.
    """

    rho: np.ndarray
    sigma: np.ndarray
    sigma_combined: np.ndarray
    rotation: np.ndarray
    principal: np.ndarray
    problem: object
    result: object = None
    lo: np.ndarray | None = None
    hi: np.ndarray | None = None
    seconds: float = 0.0

    def __post_init__(self):
        for name in ("rho", "sigma", "sigma_combined", "rotation", "principal"):
            object.__setattr__(self, name, _read_only(getattr(self, name), np.float64))
        d = self.rho.ndim
        lo = np.zeros(d) if self.lo is None else self.lo
        hi = np.array(self.rho.shape[::-1], float) if self.hi is None else self.hi
        object.__setattr__(self, "lo", _frozen(lo).reshape(d))
        object.__setattr__(self, "hi", _frozen(hi).reshape(d))

    @property
    def ndim(self) -> int:
        return int(self.rho.ndim)

    @property
    def grid_shape(self) -> tuple:
        return tuple(self.rho.shape)


@dataclass(frozen=True, eq=False)
class RDFieldsValue:
    """Inputs of reaction-diffusion growth (port type "RDFields").

    rho : grid_shape float64, read-only, infill-space density in [0, 1].
    rotation : grid_shape + (d, d) float64, read-only, principal directions
        as columns (x, y[, z]), sorted by |sigma_i| descending.
    gamma : grid_shape float64, read-only, infill map Gamma in [0, 1]
        (1 = fill with solid material).
    lo, hi : (d,) float64, the box the grid covers, (x, y[, z]).
    sigma : grid_shape + (d, d) float64 or None, the tensor the rotation came
        from (for display).
    gamma_sigma : grid_shape float64 or None, the coherence part of Gamma.
    magnitude : grid_shape + (d,) float64 or None, |principal value| along
        each column of ``rotation`` (None when only directions were given).
    source : RDFieldsValue or None, the fields these were upsampled from
        (None: these are the fields as made).
    """

    rho: np.ndarray
    rotation: np.ndarray
    gamma: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    sigma: np.ndarray | None = None
    gamma_sigma: np.ndarray | None = None
    magnitude: np.ndarray | None = None
    source: "RDFieldsValue | None" = None

    def __post_init__(self):
        for name in ("rho", "rotation", "gamma", "sigma", "gamma_sigma", "magnitude"):
            a = getattr(self, name)
            if a is not None:
                object.__setattr__(self, name, _read_only(a, np.float64))
        object.__setattr__(self, "lo", _frozen(self.lo).reshape(-1))
        object.__setattr__(self, "hi", _frozen(self.hi).reshape(-1))
        d = self.rho.ndim
        if self.rotation.shape != self.rho.shape + (d, d) or self.gamma.shape != self.rho.shape \
                or self.lo.size != d or self.hi.size != d:
            raise ValueError(f"RDFieldsValue: rho {self.rho.shape}, rotation {self.rotation.shape}, "
                             f"gamma {self.gamma.shape} and a {self.lo.size}D box do not fit together")

    @property
    def ndim(self) -> int:
        return int(self.rho.ndim)

    @property
    def grid_shape(self) -> tuple:
        return tuple(self.rho.shape)

    def source_of(self) -> "RDFieldsValue":
        """The fields as made (before any upsampling)."""
        return self if self.source is None else self.source

    def same_as(self, other: "RDFieldsValue") -> bool:
        """Whether ``other`` holds the same rho, rotation and Gamma on the same box."""
        if other is self:
            return True
        return (other is not None and self.grid_shape == other.grid_shape
                and all(np.array_equal(getattr(self, n), getattr(other, n))
                        for n in ("rho", "rotation", "gamma", "lo", "hi")))


@dataclass(frozen=True, eq=False)
class RDStructuresValue:
    """Per-direction structures grown by anisotropic Gray-Scott (port type "RDStructures").

    s : (n,) + grid_shape float32, read-only, s_i = 1 - u_i for each grown
        direction (in ``directions`` order).
    directions : tuple of int, the principal direction of each structure.
    fields : RDFieldsValue on the growth grid (rho, rotation, Gamma upsampled;
        ``fields.source_of()`` is the node's input).
    iso : float, the infill space is ``fields.rho >= iso``.
    steps : tuple of int, steps of each direction's state (regrowth included).
    stop_reasons : tuple of str, why each direction's last run stopped
        ("converged", "max_steps", "cancelled").
    stop_steps : tuple of int, where each direction's last run stopped: steps
        from the seeds (a growth) or from the brush (a regrowth).
    g_history : tuple of (m, 2) float64 arrays, (step, G^t) of eq. 14 of each
        direction's last run (steps counted as in ``stop_steps``).
    seconds : tuple of float, wall time of each direction's last run.
    cell_updates_per_second : float, cells x steps / seconds over the last
        runs: the whole grid for a growth (the kernel skips cells the pattern
        has not reached, so this is an effective rate), the regrown windows
        for a regrowth.
    states : tuple, per direction the resumable kernel state
        (``engine.rd.growth.RDState``), or None.
    edits : tuple of dict, the brush edits applied so far.
    regrown : bool, the last evaluation regrew locally after edits.
    changed : tuple of (start, stop) per grid axis or None, the box the last
        evaluation could change (None: everything).
    """

    s: np.ndarray
    directions: tuple
    fields: RDFieldsValue
    iso: float = 0.5
    steps: tuple = ()
    stop_reasons: tuple = ()
    stop_steps: tuple = ()
    g_history: tuple = ()
    seconds: tuple = ()
    cell_updates_per_second: float = 0.0
    states: tuple | None = None
    edits: tuple = ()
    regrown: bool = False
    changed: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "s", _read_only(self.s, np.float32))
        object.__setattr__(self, "g_history", tuple(_read_only(g, np.float64).reshape(-1, 2)
                                                    for g in self.g_history))
        if self.s.shape[1:] != self.fields.grid_shape or self.s.shape[0] != len(self.directions):
            raise ValueError(f"RDStructuresValue: s {self.s.shape} does not fit {len(self.directions)} "
                             f"directions on grid {self.fields.grid_shape}")

    @property
    def ndim(self) -> int:
        return self.fields.ndim

    def summary(self) -> dict:
        """JSON-able facts of the growth, per direction."""
        return {"grid": list(self.fields.grid_shape[::-1]), "directions": list(self.directions),
                "steps": list(self.steps), "stop_reasons": list(self.stop_reasons),
                "stop_steps": list(self.stop_steps), "seconds": list(self.seconds),
                "final_g": [float(g[-1, 1]) if len(g) else None for g in self.g_history],
                "cell_updates_per_second": self.cell_updates_per_second,
                "regrown": self.regrown, "edits": len(self.edits)}


@dataclass(frozen=True)
class ContourValue:
    """2D iso-contours of a compiled lattice (port type "Contour").

    polylines : tuple of (m, 2) float64 arrays, read-only, points (x, y) in
        the box's units; a closed loop repeats its first point.
    lo, hi : (2,) float64, the box.
    iso : float, the level contoured.
    """

    polylines: tuple
    lo: np.ndarray
    hi: np.ndarray
    iso: float = 0.5

    def __post_init__(self):
        object.__setattr__(self, "polylines", tuple(_frozen(p).reshape(-1, 2) for p in self.polylines))
        object.__setattr__(self, "lo", _frozen(self.lo).reshape(2))
        object.__setattr__(self, "hi", _frozen(self.hi).reshape(2))


@dataclass(frozen=True)
class SurfaceReport:
    """How a Surface node solved its patch (port type "SurfaceReport").

    solver : "direct" (thin shell), "mixed_minimal" or "conjugate".
    iterations : solver steps (L-BFGS iterations, flow steps, Nelder-Mead
        iterations of the edge-length search).
    energy : final value of the solver's energy: the shell energy
        (in-plane + alpha * bending, dimensionless), the area (cell units^2)
        or the conjugate contour energy (dimensionless).
    area : patch area (cell units^2); max_abs_H, mean_abs_H : mean curvature
        over interior vertices (1 / cell units), the mean area-weighted.
    seconds : wall time of the solve (thickness profile included).
    converged : the solver met its tolerance within max_iter.
    warning : why the result may be unreliable ("" when converged).
    details : further JSON-able facts (FBV, sliding planes, vertex count...).
    """

    solver: str
    iterations: int
    energy: float
    area: float
    max_abs_H: float
    mean_abs_H: float
    seconds: float
    converged: bool = True
    warning: str = ""
    details: dict = field(default_factory=dict, compare=False)

    def summary(self) -> dict:
        return {"solver": self.solver, "iterations": self.iterations, "energy": self.energy,
                "area": self.area, "max_abs_H": self.max_abs_H, "mean_abs_H": self.mean_abs_H,
                "seconds": self.seconds, "converged": self.converged, "warning": self.warning,
                "details": dict(self.details)}
