"""Effective elastic properties of a grown tiling (Liu, Sun & Daraio 2022, Figs. 3-6).

2D: the tiling is drawn as a binary pixel image (``tiling_image``, the paper
maps each block to 20 x 20 pixels) and homogenized in plane stress with
periodic boundary conditions on bilinear quads (``homogenize_pixels``), as
in the paper's "FEM simulations" section.

3D: the paper homogenizes the beam network with 6-dof frame elements. We
voxelize the beams instead (``tiling_voxels``: beams of radius ``radius``
block units, ``resolution`` voxels per block edge) and homogenize the voxel
cell with trilinear hexes (``homogenize_voxels``). Joints are resolved as
solid material rather than rigid frame nodes, so stubby members come out a
little stiffer than with frame elements; both converge to the continuum.

Bounded (non-periodic) tilings are homogenized the same way, with periodic
boundary conditions on the grown patch: this is the statistical volume
element (SVE) approach of the paper, which grows 20 x 20 samples and treats
each as an SVE. Members that end on a boundary face whose opposite face has
no matching member are then dangling and carry no load, so a bounded SVE is
a little softer than the bulk; ``"periodic_cell"`` in the result says which
case applies.

Axes: ``C`` is expressed in the tiling's own axes -- ``x`` along the last
grid axis, ``y`` along the one before (row index, downward on screen), ``z``
along the first in 3D -- the frame of the tile-set block coordinates and of
``tiling_beams``. Engineering constants follow eqs. 1-8 of the paper (see
``engine.physics.elastic.engineering_constants``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from engine.physics.elastic import is_singular

from .hints import realised_probabilities
from .render import tiling_image, tiling_voxels
from .tiling import Tiling

__all__ = ["homogenize_tiling", "tiling_properties", "check_options", "constants_of",
           "constant_names", "is_singular", "directional_young_in_plane", "VOID_MODES",
           "SOFT_VOID_MODULUS"]

VOID_MODES = ("removed", "soft")
# The paper models voids as a soft material E_v = 1e-3 E_s, nu_v = 0.
SOFT_VOID_MODULUS = 1e-3
# A stiffness whose smallest eigenvalue is below this fraction of its largest
# is a mechanism (the tiling does not connect along some direction).
DEFAULT_RESOLUTION = {2: 20, 3: 10}


def _check_options(tiling, tileset, resolution, line_width, radius, void):
    if not isinstance(tiling, Tiling):
        raise ValueError(f"tiling must be a Tiling; got {type(tiling).__name__}")
    if tiling.tileset_name != tileset.name:
        raise ValueError(f"tiling was grown from tile set {tiling.tileset_name!r}, "
                         f"not {tileset.name!r}")
    return check_options(tiling.shape, resolution=resolution, line_width=line_width,
                         radius=radius, void=void)


def check_options(shape, *, resolution=None, line_width=None, radius=0.2, void="removed"):
    """Validate the rendering / solver options for a grid ``shape``.

    Returns
    -------
    (resolution, line_width, radius) with the defaults filled in.

    Raises
    ------
    ValueError naming the option, its value and what was expected.
    """
    if void not in VOID_MODES:
        raise ValueError(f"void must be one of {VOID_MODES}; got {void!r}")
    ndim = len(shape)
    if resolution is None:
        resolution = DEFAULT_RESOLUTION[ndim]
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) \
            or not 2 <= resolution <= 200:
        raise ValueError(f"resolution must be an integer number of pixels / voxels per block "
                         f"edge in [2, 200]; got {resolution!r}")
    if line_width is None:
        line_width = resolution / 5.0          # 4 px at the paper's 20 px per block
    if not (isinstance(line_width, (int, float, np.number)) and math.isfinite(line_width)
            and 0 < line_width <= resolution):
        raise ValueError(f"line_width must be a pixel width in (0, resolution={resolution}]; "
                         f"got {line_width!r}")
    if not (isinstance(radius, (int, float, np.number)) and math.isfinite(radius)
            and 0 < radius <= 0.5):
        raise ValueError(f"radius must be a beam radius in block units in (0, 0.5]; "
                         f"got {radius!r}")
    if ndim == 3 and len(set(shape)) != 1:
        raise ValueError(f"3D homogenization needs a cubic tiling (nx == ny == nz); "
                         f"got shape {tuple(shape)}")
    return int(resolution), float(line_width), float(radius)


def homogenize_tiling(tiling: Tiling, tileset, *, E: float = 1.0, nu: float = 0.46,
                      resolution: int | None = None, line_width: float | None = None,
                      radius: float = 0.2, void: str = "removed", tol: float = 1e-6,
                      threads: int | None = None, progress=None):
    """Homogenized stiffness of a tiling (periodic boundary conditions).

    Parameters
    ----------
    tiling : Tiling, 2D or 3D (3D: cubic grid)
    tileset : TileSet it was grown from
    E : float > 0, Young's modulus of the solid (1 gives ``E / E_s``)
    nu : float in (-1, 0.5), Poisson ratio of the solid (paper: 0.46, Semiflex)
    resolution : int, optional
        Pixels (2D, default 20 as in the paper) or voxels (3D, default 10)
        per block edge.
    line_width : float, optional
        2D member width in pixels; default ``resolution / 5`` (4 px of 20).
    radius : float
        3D beam radius in block units (paper: 1 mm in 5 mm cubes -> 0.2).
    void : {"removed", "soft"}
        ``"removed"``: void carries nothing, floating islands are dropped
        (reported as ``dropped_fraction``). ``"soft"``: the paper's soft
        void, ``E_v = 1e-3 E``, ``nu_v = 0``.
    tol : float
        Relative accuracy of the solver on the diagonal of ``C``.
    threads : int, optional
        numba threads for the solve (batch runs use 1 per worker).
    progress : callable ``(done, total) -> bool``, optional

    Returns
    -------
    HomogenizationResult
        ``C`` (3, 3) plane stress or (6, 6), Voigt with engineering shear, in
        the tiling's axes (module docstring).

    Raises
    ------
    ValueError
        Bad options, or no material percolates (``void="removed"``).
    """
    resolution, line_width, radius = _check_options(tiling, tileset, resolution, line_width,
                                                    radius, void)
    vm = SOFT_VOID_MODULUS if void == "soft" else 0.0
    if tiling.tiles.ndim == 2:
        from engine.physics.homogenize2d import homogenize_pixels
        img = tiling_image(tiling, tileset, resolution=resolution, line_width=line_width)
        # homogenize_pixels reads row 0 as the top with y pointing up the rows;
        # flipping the rows makes its y the tiling's y (increasing row index).
        return homogenize_pixels(np.ascontiguousarray(img[::-1], dtype=np.float64), E=E, nu=nu,
                                 void_modulus=vm, tol=tol, threads=threads, progress=progress)
    from engine.physics.homogenize3d import homogenize_voxels
    vox = tiling_voxels(tiling, tileset, resolution=resolution, radius=radius)
    # tiling_voxels is indexed [z, y, x]; homogenize_voxels wants [x, y, z].
    grid = np.ascontiguousarray(vox.transpose(2, 1, 0), dtype=np.float64)
    return homogenize_voxels(grid, E=E, nu=nu, void_modulus=vm, tol=tol, threads=threads,
                             progress=progress)


def constant_names(ndim: int) -> tuple:
    if ndim == 2:
        return ("E_x", "E_y", "nu_xy", "nu_yx", "G", "E_avg", "nu_avg")
    return ("E_x", "E_y", "E_z", "nu_xy", "nu_yx", "nu_yz", "nu_zy", "nu_xz", "nu_zx",
            "G_xy", "G_yz", "G_xz", "E_avg", "nu_avg")


def constants_of(C, ndim: int) -> dict:
    """Engineering constants of eqs. 1-8 (NaN for a singular ``C``)."""
    from engine.physics.elastic import engineering_constants
    names = constant_names(ndim)
    if is_singular(C):
        return {k: math.nan for k in names}
    c = engineering_constants(C)
    return {k: float(c[k]) for k in names}


def directional_young_in_plane(C, angles) -> np.ndarray:
    """Young's modulus along ``(cos t, sin t[, 0])``: in the xy plane in 3D."""
    from engine.physics.elastic import directional_young, directional_young_polar
    angles = np.asarray(angles, dtype=np.float64)
    if is_singular(C):
        return np.full(angles.shape, np.nan)
    if np.shape(C) == (3, 3):
        return np.asarray(directional_young_polar(C, angles), dtype=np.float64)
    d = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
    return np.asarray(directional_young(C, d), dtype=np.float64).reshape(angles.shape)


def tiling_properties(tiling: Tiling, tileset, *, E: float = 1.0, nu: float = 0.46,
                      resolution: int | None = None, line_width: float | None = None,
                      radius: float = 0.2, void: str = "removed", n_angles: int = 72,
                      tol: float = 1e-6, threads: int | None = None, progress=None) -> dict:
    """Effective elastic properties of a tiling (paper eqs. 1-8, Figs. 3-6).

    Parameters are those of :func:`homogenize_tiling`, plus
    ``n_angles`` : int >= 1, directions of the directional Young's modulus
    over ``[0, 2 pi)``.

    Returns
    -------
    dict
        ``C`` : (3, 3) or (6, 6) float64, Voigt, engineering shear, tiling axes;
        ``E_x, E_y, nu_xy, nu_yx, G, E_avg, nu_avg`` (2D) or
        ``E_x ... E_z, nu_xy ... nu_zx, G_xy, G_yz, G_xz, E_avg, nu_avg`` (3D),
        in units of ``E`` (NaN when the tiling is a mechanism);
        ``E_avg/E_s`` : ``E_avg / E``;
        ``singular`` : bool, ``C`` not positive definite (a mechanism);
        ``symmetry`` : str (``engine.physics.elastic.symmetry_class``, tol 1e-3);
        ``angles`` : (n_angles,) radians; ``E_theta`` : (n_angles,) Young's
        modulus along ``(cos t, sin t)`` (3D: in the xy plane);
        ``realised_probabilities`` : dict block -> fraction of assigned cells;
        ``n_defects``, ``density`` (solid fraction), ``dropped_fraction``,
        ``iterations``, ``seconds``, ``periodic_cell`` (False: bounded SVE),
        and the options used (``E_s, nu_s, resolution, line_width`` or
        ``radius``, ``void``).
    """
    if isinstance(n_angles, bool) or not isinstance(n_angles, (int, np.integer)) or n_angles < 1:
        raise ValueError(f"n_angles must be an integer >= 1; got {n_angles!r}")
    t0 = time.perf_counter()
    resolution, line_width, radius = _check_options(tiling, tileset, resolution, line_width,
                                                    radius, void)
    result = homogenize_tiling(tiling, tileset, E=E, nu=nu, resolution=resolution,
                               line_width=line_width, radius=radius, void=void, tol=tol,
                               threads=threads, progress=progress)
    from engine.physics.elastic import symmetry_class
    C = np.array(result.C, dtype=np.float64)
    ndim = tiling.tiles.ndim
    singular = is_singular(C)
    out = {"C": C}
    out.update(constants_of(C, ndim))
    out["E_avg/E_s"] = out["E_avg"] / float(E)
    angles = np.arange(n_angles) * (2 * np.pi / n_angles)
    probs = realised_probabilities(tiling, tileset)
    out.update({
        "singular": singular,
        "symmetry": "singular" if singular else symmetry_class(C, tol=1e-3),
        "angles": angles,
        "E_theta": directional_young_in_plane(C, angles),
        "realised_probabilities": {b: float(p) for b, p in zip(tileset.block_names, probs)},
        "n_defects": tiling.n_defects,
        "density": float(result.density),
        "dropped_fraction": float(result.dropped_fraction),
        "iterations": int(result.iterations),
        "periodic_cell": bool(tiling.periodic),
        "E_s": float(E), "nu_s": float(nu), "resolution": resolution, "void": void,
    })
    out["line_width" if ndim == 2 else "radius"] = line_width if ndim == 2 else radius
    out["seconds"] = time.perf_counter() - t0
    return out
