"""The topology-optimisation problem on a regular pixel / voxel grid.

Grid convention (shared with the growth kernels that consume the results)
--------------------------------------------------------------------------
* Cell arrays are indexed ``[y, x]`` (2D) or ``[z, y, x]`` (3D); the physical
  coordinate along an axis grows with the index (row 0 is ``y = 0``; draw
  with the origin at the lower left).
* Node arrays have one more entry per axis, ``(nely + 1, nelx + 1)`` etc.;
  node ``[iy, ix]`` sits at ``(ix h, iy h)``.
* Vector and tensor components come last, in ``(x, y[, z])`` order:
  ``fixed[iy, ix, 0]`` is the x dof of that node.

A :class:`Problem` is immutable and validated on construction; every
message names the field at fault. ``to_dict`` / ``from_dict`` give a plain
JSON form in which nodes are written ``[ix, iy(, iz)]`` (x first).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace

import numpy as np

__all__ = [
    "Problem", "OBJECTIVES", "node_shape", "nodes_in_box", "nearest_node", "rigid_modes",
]

OBJECTIVES = ("compliance", "stress", "orientation")
AXES = "xyz"


def node_shape(shape):
    """Node-grid shape of a cell grid: one more node than cells per axis."""
    return tuple(int(n) + 1 for n in shape)


def _node_coords(shape):
    """(n_nodes, dim) normalised node coordinates in (x, y[, z]) order, nodes row-major."""
    grids = np.meshgrid(*[np.linspace(0.0, 1.0, n + 1) for n in shape], indexing="ij")
    # grids are in array-axis order (.., y, x); reverse to component order.
    return np.stack([g.ravel() for g in grids[::-1]], axis=1)


def nodes_in_box(shape, lo, hi):
    """Nodes inside a box given in normalised domain coordinates.

    Parameters
    ----------
    shape : tuple of int
        Cell grid ``(nely, nelx)`` or ``(nelz, nely, nelx)``.
    lo, hi : sequence of float, length dim
        Box corners in ``(x, y[, z])`` order, each coordinate in ``[0, 1]``
        (the whole domain is the unit square / cube). A box thinner than a
        cell still catches the nearest grid line.

    Returns
    -------
    mask : bool array of the node-grid shape.
    """
    dim = len(shape)
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    if lo.shape != (dim,) or hi.shape != (dim,):
        raise ValueError(f"lo and hi must have {dim} coordinates (x, y[, z]); got {lo.shape}, {hi.shape}")
    steps = 1.0 / np.asarray(shape[::-1], dtype=np.float64)         # (x, y[, z]) cell size
    # Widen a degenerate box to half a cell so it snaps onto the nearest line.
    half = np.where(hi - lo < steps, 0.5 * steps, 1e-9)
    c = _node_coords(shape)
    inside = np.all((c >= lo - half) & (c <= hi + half), axis=1)
    return inside.reshape(node_shape(shape))


def nearest_node(shape, point):
    """Array index (``[iy, ix]`` or ``[iz, iy, ix]``) of the node nearest a normalised point.

    ``point`` is in ``(x, y[, z])`` order, each coordinate in ``[0, 1]``.
    """
    p = np.asarray(point, dtype=np.float64)
    if p.shape != (len(shape),):
        raise ValueError(f"point must have {len(shape)} coordinates (x, y[, z]); got {p.shape}")
    return tuple(int(round(v * n)) for v, n in zip(p[::-1], shape))


def rigid_modes(shape, h=1.0):
    """Rigid-body displacement fields of the node grid.

    Returns
    -------
    R : (n_dofs, 3) in 2D or (n_dofs, 6) in 3D, float64: translations then
        infinitesimal rotations, dof order as in the node arrays.
    """
    dim = len(shape)
    x = _node_coords(shape) * np.asarray(shape[::-1], dtype=np.float64) * h
    x -= x.mean(axis=0)
    modes = []
    for a in range(dim):
        t = np.zeros_like(x)
        t[:, a] = 1.0
        modes.append(t.ravel())
    for a, b in ([(0, 1)] if dim == 2 else [(0, 1), (0, 2), (1, 2)]):
        r = np.zeros_like(x)
        r[:, a], r[:, b] = -x[:, b], x[:, a]
        modes.append(r.ravel())
    return np.stack(modes, axis=1)


def _freeze(a):
    a = np.array(a)                        # own copy: callers' arrays stay theirs
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class Problem:
    """Density-based topology optimisation on a regular grid.

    Parameters
    ----------
    shape : tuple of int
        Cells ``(nely, nelx)`` or ``(nelz, nely, nelx)``.
    fixed : bool array, node-grid shape + (dim,)
        Supported (zero-displacement) dofs.
    loads : float array, (n_cases,) + node-grid shape + (dim,)
        Nodal forces of each load case.
    volfrac : float in (0, 1)
        Allowed material volume as a fraction of the design domain (all cells
        that are not passive void; passive solid counts).
    passive : int8 cell array or None
        0 design, 1 solid, -1 void (e.g. the L-beam cut-out).
    penal : float >= 1
        SIMP penalty ``p`` in ``E = E_min + rho^p (E - E_min)``.
    rmin : float > 0
        Density-filter radius in cells (cone weights ``max(0, rmin - d)``).
    h : float > 0
        Cell edge length (physical units).
    young, poisson : float
        Solid material; 2D is plane stress of unit thickness.
    young_min : float in (0, 1)
        Void stiffness relative to ``young``.
    objective : {"compliance", "stress", "orientation"}
        Which optimiser :func:`engine.topopt.optimise` runs.
    name : str
        Preset name or a user label.
    """

    shape: tuple
    fixed: np.ndarray
    loads: np.ndarray
    volfrac: float
    passive: np.ndarray = None
    penal: float = 3.0
    rmin: float = 1.5
    h: float = 1.0
    young: float = 1.0
    poisson: float = 0.3
    young_min: float = 1e-9
    objective: str = "compliance"
    name: str = ""
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        shape = tuple(int(n) for n in np.atleast_1d(self.shape))
        if len(shape) not in (2, 3) or min(shape) < 1:
            raise ValueError(f"shape must be (nely, nelx) or (nelz, nely, nelx) of positive ints; got {self.shape!r}")
        object.__setattr__(self, "shape", shape)
        dim = len(shape)
        nshape = node_shape(shape)
        fixed = np.asarray(self.fixed)
        if fixed.shape != nshape + (dim,):
            raise ValueError(f"fixed must have shape {nshape + (dim,)} (nodes, components); got {fixed.shape}")
        object.__setattr__(self, "fixed", _freeze(fixed.astype(bool)))
        loads = np.asarray(self.loads, dtype=np.float64)
        if loads.shape == nshape + (dim,):
            loads = loads[None]
        if loads.ndim != dim + 2 or loads.shape[1:] != nshape + (dim,) or loads.shape[0] < 1:
            raise ValueError(f"loads must have shape (n_cases,) + {nshape + (dim,)}; got {loads.shape}")
        object.__setattr__(self, "loads", _freeze(loads))
        passive = np.zeros(shape, np.int8) if self.passive is None else np.asarray(self.passive)
        if passive.shape != shape:
            raise ValueError(f"passive must have the cell shape {shape}; got {passive.shape}")
        if not np.isin(passive, (-1, 0, 1)).all():
            raise ValueError("passive must hold only -1 (void), 0 (design) or 1 (solid)")
        object.__setattr__(self, "passive", _freeze(passive.astype(np.int8)))
        for name in ("volfrac", "penal", "rmin", "h", "young", "poisson", "young_min"):
            object.__setattr__(self, name, float(getattr(self, name)))
        self._check_scalars()
        self._check_supports()
        self._check_loads()

    # ------------------------------------------------------------ validation
    def _check_scalars(self):
        checks = [
            ("volfrac", 0.0 < self.volfrac < 1.0, "in the open interval (0, 1)"),
            ("penal", self.penal >= 1.0, ">= 1"),
            ("rmin", self.rmin > 0.0, "> 0 (cells)"),
            ("h", self.h > 0.0, "> 0"),
            ("young", self.young > 0.0, "> 0"),
            ("poisson", -1.0 < self.poisson < (0.5 if self.dim == 3 else 1.0),
             "in (-1, 0.5) in 3D, (-1, 1) in plane stress"),
            ("young_min", 0.0 < self.young_min < 1.0, "in (0, 1), relative to young"),
        ]
        for name, ok, expected in checks:
            if not (ok and math.isfinite(getattr(self, name))):
                raise ValueError(f"{name} must be {expected}; got {getattr(self, name)!r}")
        if self.objective not in OBJECTIVES:
            raise ValueError(f"objective must be one of {OBJECTIVES}; got {self.objective!r}")
        n_design = int((self.passive == 0).sum())
        if n_design == 0:
            raise ValueError("passive: no design cells left (every cell is passive)")
        solid = float((self.passive == 1).sum()) / self.n_domain
        if solid >= self.volfrac:
            raise ValueError(f"volfrac {self.volfrac} leaves no material to place: passive solid cells "
                             f"already fill {solid:.3f} of the design domain")

    def _check_supports(self):
        fixed = self.fixed.reshape(-1)
        if not fixed.any():
            raise ValueError("fixed: no supported dof; the structure would move as a rigid body")
        R = rigid_modes(self.shape, self.h)[fixed]
        need = R.shape[1]
        if np.linalg.matrix_rank(R, tol=1e-9 * max(1.0, np.abs(R).max())) < need:
            raise ValueError(f"fixed: the {int(fixed.sum())} supported dof(s) do not stop every rigid-body "
                             f"motion ({need} translations and rotations in {self.dim}D)")

    def _check_loads(self):
        if not np.isfinite(self.loads).all():
            raise ValueError("loads: contains NaN or infinite forces")
        for k, case in enumerate(self.loads):
            if not np.any(case):
                raise ValueError(f"loads: case {k} applies no force")
            bad = (case != 0) & self.fixed
            if bad.any():
                where = np.argwhere(bad)[0]
                node = [int(i) for i in where[:-1][::-1]]
                raise ValueError(f"loads: case {k} puts a force on supported dof {AXES[where[-1]]} of node "
                                 f"{node} (x, y[, z]); move the load or free that dof")

    # ------------------------------------------------------------ properties
    @property
    def dim(self):
        return len(self.shape)

    @property
    def n_cells(self):
        return int(np.prod(self.shape))

    @property
    def n_cases(self):
        return int(self.loads.shape[0])

    @property
    def n_dofs(self):
        return int(np.prod(node_shape(self.shape))) * self.dim

    @property
    def n_domain(self):
        """Cells of the design domain (everything but passive void)."""
        return int((self.passive != -1).sum())

    def replace(self, **changes):
        """A new, validated problem with some fields changed."""
        return replace(self, **changes)

    def with_support(self, mask, axes="xyz", *, held=True):
        """A copy with the ``axes`` dofs of every node of ``mask`` held (or freed).

        Parameters
        ----------
        mask : bool array of the node-grid shape (e.g. from :func:`nodes_in_box`).
        axes : str, letters of ``"xyz"``.
        held : bool, False frees those dofs instead.
        """
        fixed = np.array(self.fixed)
        mask = np.asarray(mask, bool)
        for a in axes:
            if a not in AXES[: self.dim]:
                raise ValueError(f"axes: unknown axis {a!r}; expected letters of {AXES[: self.dim]!r}")
            fixed[..., AXES.index(a)][mask] = held
        return self.replace(fixed=fixed)

    def with_load(self, mask, force, case=0, *, add=True):
        """A copy with ``force`` (x, y[, z]) spread evenly over the nodes of ``mask``.

        ``case == n_cases`` appends a new load case; ``add=False`` replaces
        the force on those nodes (a zero force then removes the load).
        """
        loads = np.array(self.loads)
        if not 0 <= case <= loads.shape[0]:
            raise ValueError(f"case must be in [0, {loads.shape[0]}]; got {case!r}")
        if case == loads.shape[0]:
            loads = np.concatenate([loads, np.zeros_like(loads[:1])])
        mask = np.asarray(mask, bool)
        share = np.asarray(force, float).reshape(self.dim) / max(1, int(mask.sum()))
        loads[case][mask] = (loads[case][mask] if add else 0.0) + share
        return self.replace(loads=loads)

    # ------------------------------------------------------------ JSON form
    def to_dict(self):
        """Plain-data form (lists, numbers, strings) that :meth:`from_dict` reads back."""
        supports = [{"node": [int(i) for i in idx[::-1]], "dofs": "".join(AXES[a] for a in np.flatnonzero(row))}
                    for idx, row in _nonzero_nodes(self.fixed)]
        cases = [[{"node": [int(i) for i in idx[::-1]], "force": [float(f) for f in row]}
                  for idx, row in _nonzero_nodes(case)] for case in self.loads]
        flat = self.passive.ravel()
        edges = np.flatnonzero(np.diff(flat)) + 1
        starts = np.concatenate([[0], edges])
        runs = [[int(flat[s]), int(n)] for s, n in zip(starts, np.diff(np.concatenate([starts, [flat.size]])))]
        return {
            "shape": list(self.shape), "h": self.h, "volfrac": self.volfrac, "penal": self.penal,
            "rmin": self.rmin, "young": self.young, "poisson": self.poisson, "young_min": self.young_min,
            "objective": self.objective, "name": self.name,
            "supports": supports, "load_cases": cases, "passive_runs": runs,
        }

    def to_json(self, **kwargs):
        return json.dumps(self.to_dict(), **kwargs)

    @classmethod
    def from_dict(cls, d):
        """Inverse of :meth:`to_dict`; errors name the offending entry."""
        try:
            shape = tuple(int(n) for n in d["shape"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"shape: expected a list of 2 or 3 ints; got {d.get('shape')!r}") from exc
        dim = len(shape)
        nshape = node_shape(shape)
        fixed = np.zeros(nshape + (dim,), bool)
        for k, s in enumerate(d.get("supports", [])):
            idx = _node_index(s.get("node"), nshape, f"supports[{k}].node")
            for a in s.get("dofs", ""):
                if a not in AXES[:dim]:
                    raise ValueError(f"supports[{k}].dofs: unknown axis {a!r}; expected letters of {AXES[:dim]!r}")
                fixed[idx + (AXES.index(a),)] = True
        cases = d.get("load_cases", [])
        loads = np.zeros((max(1, len(cases)),) + nshape + (dim,))
        for c, case in enumerate(cases):
            for k, ld in enumerate(case):
                idx = _node_index(ld.get("node"), nshape, f"load_cases[{c}][{k}].node")
                force = np.asarray(ld.get("force"), float)
                if force.shape != (dim,):
                    raise ValueError(f"load_cases[{c}][{k}].force: expected {dim} numbers; got {ld.get('force')!r}")
                loads[(c,) + idx] += force
        passive = np.zeros(int(np.prod(shape)), np.int8)
        runs = d.get("passive_runs", [[0, passive.size]])
        values = np.array([int(v) for v, _ in runs], np.int8)
        counts = np.array([int(n) for _, n in runs])
        if counts.sum() != passive.size or (counts < 0).any():
            raise ValueError(f"passive_runs: run lengths add up to {int(counts.sum())}, expected {passive.size} cells")
        passive = np.repeat(values, counts).reshape(shape)
        keys = ("h", "volfrac", "penal", "rmin", "young", "poisson", "young_min", "objective", "name")
        return cls(shape=shape, fixed=fixed, loads=loads, passive=passive, **{k: d[k] for k in keys if k in d})

    @classmethod
    def from_json(cls, text):
        return cls.from_dict(json.loads(text))


def _nonzero_nodes(arr):
    """(node index tuple, component row) for each node with a nonzero component."""
    flat = arr.reshape(-1, arr.shape[-1])
    shape = arr.shape[:-1]
    for n in np.flatnonzero(np.any(flat != 0, axis=1)):
        yield np.unravel_index(n, shape), flat[n]


def _node_index(node, nshape, what):
    """Array index of a node written ``[ix, iy(, iz)]``."""
    try:
        xyz = [int(i) for i in node]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what}: expected {len(nshape)} ints (x, y[, z]); got {node!r}") from exc
    idx = tuple(xyz[::-1])
    if len(idx) != len(nshape) or any(not 0 <= i < n for i, n in zip(idx, nshape)):
        raise ValueError(f"{what}: node {node!r} lies outside the node grid "
                         f"{list(nshape[::-1])} (x, y[, z])")
    return idx
