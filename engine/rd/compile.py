"""Structure compilation: filter the grown patterns, combine them, extract the shape (paper section 5).

Inputs are the per-direction grown structures ``s_i = 1 - u_i`` normalised to
[0, 1] (one per principal direction, all on the RD grid). The steps:

Pattern rescaling (5.1)
    Eq. 15 clamps ``s_i`` to ``[1 - mu_i - delta_i, 1 - mu_i + delta_i]``:
    its 0.5-iso after the clamp is the ``1 - mu_i`` iso of ``s_i``, so a
    larger relative thickness ``mu_i`` widens the members, and ``delta``
    keeps the transition smooth. :func:`rescale_pattern` returns the clamp
    mapped affinely onto [0, 1], ``clip((s - (1 - mu - delta)) / (2 delta),
    0, 1)``, so that every direction's member boundary is at 0.5 and the
    Boolean operations of eq. 18 compare like with like (the paper's
    unnormalised values would have different ranges per direction). With a
    field ``mu(x)`` this is the variable-thickness filter of eq. 17, a
    smoothed ``H(mu - (1 - s))``; ``delta = 0`` gives the Heaviside exactly.
Minimum member size (eq. 16)
    ``mu_i = h_i / l`` with ``l`` the pattern wavelength (cells per period),
    so a minimum width of ``h_min`` cells means ``mu_i >= h_min / l``;
    :func:`pattern_wavelength` measures ``l`` from the power spectrum when it
    is not given.
Boolean combination (5.2, eq. 18)
    2D: ``max(s1, s2)``; 3D lattice: ``max_{i<j} min(s_i, s_j)`` (the bars
    where two families of membranes cross). The membrane option (Fig. 22l)
    keeps the chosen membrane families whole and adds them to the lattice:
    ``max(lattice, max_{i in membranes} s_i)``. With ``membranes=(0, 1)``
    (default) the walls normal to ``v1`` and ``v2`` run through the part
    and the transverse direction is lattice; ``membranes=(2,)`` keeps the
    sheets normal to ``v3`` (parallel to a plane-stress plane) joined by the
    bars along ``v3``. The paper shows the figure without a formula; both
    readings are available.
Solid regions and the infill space
    Cells with ``Gamma >= gamma_level`` are made solid (a ramp of width
    ``2 delta`` in Gamma); the result is then cut to the infill space
    ``rho >= iso``, optionally with a solid skin ``shell_thickness`` cells
    thick inside its boundary.

The compiled density lies in [0, 1]; the solid is ``density > 0.5``.
:func:`structure_contours` and :func:`structure_mesh` extract it (cell
``[j, i]`` is centred at ``((i + 0.5) h, (j + 0.5) h)``, so the grid box
is ``[0, n h]`` per axis); both pad with zeros so the shape is closed
where it meets the box.
"""

from __future__ import annotations

import io
from typing import NamedTuple

import numpy as np

from engine.fileio import write_atomic
from engine.progress import report

__all__ = ["CompiledStructure", "rescale_pattern", "minimum_relative_thickness", "pattern_wavelength",
           "combine_structures", "infill_signed_distance", "compile_structure", "structure_contours",
           "structure_mesh", "save_structure_png", "save_structure_stl", "LEVEL"]

#: Iso-value of the compiled density: the solid is ``density > LEVEL``.
LEVEL = 0.5
# Values this far outside [0, 1] are round-off and are clipped; further out they are refused.
_RANGE_TOL = 1e-6


class CompiledStructure(NamedTuple):
    """Result of :func:`compile_structure`.

    density : (ny, nx) or (nz, ny, nx) float64 in [0, 1]
        Solid where ``> LEVEL``.
    filtered : tuple of d arrays, grid shape, float64 in [0, 1]
        The rescaled per-direction fields before the Boolean step.
    mu : tuple of d floats or grid arrays
        Relative thicknesses used (after the minimum-size clamp).
    mu_min : float or None
        ``h_min / wavelength`` when a minimum member size was asked for.
    wavelength : float or None
        Pattern period in cells (given or measured) when ``h_min`` was set.
    """

    density: np.ndarray
    filtered: tuple
    mu: tuple
    mu_min: float | None
    wavelength: float | None


def _unit_field(a, name, shape=None):
    f = np.asarray(a, dtype=np.float64)
    if shape is not None and f.shape != shape:
        raise ValueError(f"{name} must have the grid shape {shape}; got {f.shape}")
    if not np.isfinite(f).all():
        raise ValueError(f"{name} must be finite; got NaN or infinite values")
    if f.size and (f.min() < -_RANGE_TOL or f.max() > 1 + _RANGE_TOL):
        raise ValueError(f"{name} must lie in [0, 1]; got values in [{f.min():.6g}, {f.max():.6g}]")
    return np.clip(f, 0.0, 1.0)


def _check_delta(delta):
    dl = float(delta)
    if not np.isfinite(dl) or dl < 0 or dl >= 0.5:
        raise ValueError(f"delta must be a number in [0, 0.5); got {delta!r}")
    return dl


def rescale_pattern(s, *, mu, delta=0.01):
    """The thickness filter of eq. 15 (constant ``mu``) or eq. 17 (field ``mu``).

    Parameters
    ----------
    s : (...) float in [0, 1]
        A normalised grown pattern.
    mu : float or (...) float, in [0, 1]
        Relative member thickness: the member is where ``s > 1 - mu``.
    delta : float in [0, 0.5)
        Half-width of the smooth transition in ``s`` units; 0 gives the
        Heaviside of eq. 17.

    Returns
    -------
    (...) float64 in [0, 1]
        ``clip((s - (1 - mu - delta)) / (2 delta), 0, 1)``: eq. 15's clamp
        mapped onto [0, 1]; its 0.5 iso is ``s = 1 - mu``.
    """
    f = _unit_field(s, "s")
    m = _unit_field(mu, "mu")
    if m.ndim and m.shape != f.shape:
        raise ValueError(f"mu must be a number or have the pattern's shape {f.shape}; got {m.shape}")
    dl = _check_delta(delta)
    x = f - (1.0 - m)
    if dl == 0.0:
        return np.heaviside(x, 0.5)
    return np.clip((x + dl) / (2.0 * dl), 0.0, 1.0)


def minimum_relative_thickness(h_min, wavelength):
    """``mu_min = h_min / l`` (eq. 16): both in cells; returns a float."""
    h, l = float(h_min), float(wavelength)
    if not np.isfinite(h) or h < 0:
        raise ValueError(f"h_min must be a width in cells >= 0; got {h_min!r}")
    if not np.isfinite(l) or l <= 0:
        raise ValueError(f"wavelength must be a period in cells > 0; got {wavelength!r}")
    return h / l


def pattern_wavelength(s, *, mask=None):
    """Dominant period of a pattern, in cells, from its radially averaged power spectrum.

    Parameters
    ----------
    s : (ny, nx) or (nz, ny, nx) float
        A grown pattern.
    mask : same shape, bool, optional
        Where the pattern lives (e.g. the infill space); outside is ignored
        (set to the mean inside before the transform).

    Returns
    -------
    float
        ``1 / |k|`` at the spectral peak, |k| interpolated between shells
        (parabola through the peak shell and its neighbours).
    """
    f = np.asarray(s, dtype=np.float64)
    if f.ndim not in (2, 3) or min(f.shape) < 4 or not np.isfinite(f).all():
        raise ValueError(f"s must be a finite 2D or 3D grid of at least 4 cells per axis; got shape {f.shape}")
    m = np.ones(f.shape, bool) if mask is None else np.asarray(mask, dtype=bool)
    if m.shape != f.shape or not m.any():
        raise ValueError(f"mask must have shape {f.shape} and select some cells")
    f = np.where(m, f - f[m].mean(), 0.0)
    power = np.abs(np.fft.fftn(f)) ** 2
    freqs = np.meshgrid(*[np.fft.fftfreq(n) for n in f.shape], indexing="ij")
    k = np.sqrt(sum(q * q for q in freqs))
    dk = 1.0 / max(f.shape)
    shell = np.rint(k / dk).astype(np.int64)
    nshell = int(min(0.5 / dk, shell.max())) + 1
    sums = np.bincount(shell.ravel(), power.ravel(), minlength=nshell)[:nshell]
    counts = np.bincount(shell.ravel(), minlength=nshell)[:nshell]
    prof = np.where(counts > 0, sums / np.maximum(counts, 1), 0.0)
    prof[0] = 0.0
    p = int(np.argmax(prof))
    if prof[p] <= 0:
        raise ValueError("s has no pattern (constant inside the mask)")
    off = 0.0
    if 1 <= p < nshell - 1:
        a, b, c = prof[p - 1], prof[p], prof[p + 1]
        den = a - 2 * b + c
        off = 0.5 * (a - c) / den if den < 0 else 0.0
    return 1.0 / ((p + off) * dk)


def combine_structures(filtered, *, combination="lattice", membranes=(0, 1)):
    """Boolean combination of eq. 18 on fields whose solid is ``> 0.5``.

    Parameters
    ----------
    filtered : sequence of d arrays, same grid shape, float in [0, 1]
        d = 2 for 2D grids, 3 for 3D grids.
    combination : {"lattice", "membrane"}
        3D only: pairwise intersections then union, or that plus the
        ``membranes`` families whole (Fig. 22l). 2D is always the union.
    membranes : tuple of int
        Direction indices (0-based) kept as membranes in "membrane" mode.

    Returns
    -------
    grid-shaped float64 in [0, 1]
    """
    fs = [np.asarray(f, dtype=np.float64) for f in filtered]
    if combination not in ("lattice", "membrane"):
        raise ValueError(f"combination must be 'lattice' or 'membrane'; got {combination!r}")
    d = len(fs)
    if d not in (2, 3) or any(f.shape != fs[0].shape for f in fs) or fs[0].ndim != d:
        raise ValueError(f"filtered must hold one field per grid dimension, all of one 2D or 3D shape; "
                         f"got {d} fields of shapes {[f.shape for f in fs]}")
    if d == 2:
        if combination == "membrane":
            raise ValueError("combination 'membrane' needs 3D structures; 2D is the union of eq. 18")
        return np.maximum(fs[0], fs[1])
    out = np.maximum(np.maximum(np.minimum(fs[0], fs[1]), np.minimum(fs[0], fs[2])), np.minimum(fs[1], fs[2]))
    if combination == "membrane":
        ms = tuple(membranes)
        if not ms or any(int(i) != i or not 0 <= i < 3 for i in ms):
            raise ValueError(f"membranes must be direction indices in 0..2; got {membranes!r}")
        for i in set(int(i) for i in ms):
            out = np.maximum(out, fs[i])
    return out


def infill_signed_distance(rho, *, iso=0.5):
    """Signed distance to the infill-space boundary ``rho = iso``, in cells (> 0 inside).

    Away from the boundary it is the Euclidean distance transform of the
    mask ``rho >= iso``; within a cell of it the first-order estimate
    ``(rho - iso) / |grad rho|`` is used, so a smooth ``rho`` gives a smooth
    sub-cell boundary rather than a staircase.

    Parameters
    ----------
    rho : (ny, nx) or (nz, ny, nx) float in [0, 1]
    iso : float in (0, 1)

    Returns
    -------
    grid-shaped float64
    """
    from scipy.ndimage import distance_transform_edt

    r = _unit_field(rho, "rho")
    lv = float(iso)
    if not 0.0 < lv < 1.0:
        raise ValueError(f"iso must lie in (0, 1); got {iso!r}")
    inside = r >= lv
    if inside.all() or not inside.any():
        big = float(sum(r.shape))
        return np.full(r.shape, big if inside.all() else -big)
    sd = np.where(inside, distance_transform_edt(inside) - 0.5, 0.5 - distance_transform_edt(~inside))
    grad = np.sqrt(sum(g * g for g in np.gradient(r)))
    near = (np.abs(sd) <= 1.0) & (grad > 1e-6)
    est = np.clip((r - lv) / np.where(near, grad, 1.0), -1.5, 1.5)
    return np.where(near, est, sd)


def _solid_ramp(field, level, width):
    """0 below ``level - width``, 1 above ``level + width``, linear between."""
    if width == 0.0:
        return (field >= level).astype(np.float64)
    return np.clip((field - level + width) / (2.0 * width), 0.0, 1.0)


def _check_mu(mu, d, shape):
    items = list(mu) if isinstance(mu, (list, tuple)) else [mu] * d
    if isinstance(mu, np.ndarray) and mu.ndim == 1 and mu.shape[0] == d:
        items = list(mu)
    if len(items) != d:
        raise ValueError(f"mu must be one number, or {d} numbers / grid fields (one per direction); "
                         f"got {len(items)}")
    out = []
    for i, m in enumerate(items):
        a = _unit_field(m, f"mu[{i}]")
        if a.ndim and a.shape != shape:
            raise ValueError(f"mu[{i}] must be a number or a field of the grid shape {shape}; got {a.shape}")
        out.append(a if a.ndim else float(a))
    return out


def compile_structure(structures, *, mu, delta=0.01, rho=None, iso=0.5, gamma=None, gamma_level=0.5,
                      combination="lattice", membranes=(0, 1), shell_thickness=0.0, h_min=None,
                      wavelength=None, progress=None):
    """Filter, combine and bound the grown structures (paper section 5).

    Parameters
    ----------
    structures : sequence of d arrays, (ny, nx) or (nz, ny, nx), float in [0, 1]
        ``s_i = 1 - u_i`` normalised, one per principal direction (d = 2 or 3).
    mu : float, or sequence of d floats / grid fields, in [0, 1]
        Relative thickness per structure (eq. 15-16); fields give the
        variable thickness of eq. 17.
    delta : float in [0, 0.5)
        Smoothness of the filter (paper: 0.01); 0 = Heaviside.
    rho : grid float in [0, 1], optional
        Density; the result is cut to the infill space ``rho >= iso``.
    iso : float in (0, 1)
    gamma : grid float in [0, 1], optional
        Infill map; ``gamma >= gamma_level`` becomes solid.
    gamma_level : float in (0, 1)
    combination, membranes
        See :func:`combine_structures`.
    shell_thickness : float >= 0
        Solid skin inside the infill-space boundary, in cells (needs ``rho``).
    h_min : float, optional
        Minimum member width in cells; raises every ``mu_i`` to at least
        ``h_min / wavelength``.
    wavelength : float, optional
        Pattern period in cells; measured with :func:`pattern_wavelength`
        (mean over the structures, inside the infill space) if None.
    progress : callable(done, total) -> bool, optional
        Called between the steps; False raises ``Cancelled``.

    Returns
    -------
    CompiledStructure
    """
    fs = [np.asarray(s) for s in structures]
    d = len(fs)
    if d not in (2, 3) or any(f.shape != fs[0].shape for f in fs) or fs[0].ndim != d:
        raise ValueError(f"structures must hold one field per grid dimension (2 in 2D, 3 in 3D), all of one "
                         f"shape; got {d} fields of shapes {[f.shape for f in fs]}")
    shape = fs[0].shape
    fs = [_unit_field(f, f"structures[{i}]") for i, f in enumerate(fs)]
    mus = _check_mu(mu, d, shape)
    dl = _check_delta(delta)
    r = None if rho is None else _unit_field(rho, "rho", shape)
    g = None if gamma is None else _unit_field(gamma, "gamma", shape)
    st = float(shell_thickness)
    if not np.isfinite(st) or st < 0 or (st > 0 and r is None):
        raise ValueError(f"shell_thickness must be >= 0 cells and needs rho; got {shell_thickness!r}")
    gl = float(gamma_level)
    if not 0.0 < gl < 1.0:
        raise ValueError(f"gamma_level must lie in (0, 1); got {gamma_level!r}")
    total = 4
    report(progress, 0, total)
    mu_min = lam = None
    if h_min is not None:
        if wavelength is None:
            mask = None if r is None or not (r >= iso).any() else r >= iso
            lam = float(np.mean([pattern_wavelength(f, mask=mask) for f in fs]))
        else:
            lam = float(wavelength)
        mu_min = minimum_relative_thickness(h_min, lam)
        mus = [np.maximum(m, mu_min) if isinstance(m, np.ndarray) else max(m, mu_min) for m in mus]
    report(progress, 1, total)
    filtered = tuple(rescale_pattern(f, mu=np.minimum(m, 1.0), delta=dl) for f, m in zip(fs, mus))
    report(progress, 2, total)
    out = combine_structures(filtered, combination=combination, membranes=membranes)
    if g is not None:
        out = np.maximum(out, _solid_ramp(g, gl, dl))
    report(progress, 3, total)
    if r is not None:
        sd = infill_signed_distance(r, iso=iso)
        inside = np.clip(sd + 0.5, 0.0, 1.0)
        if st > 0:
            out = np.maximum(out, np.clip(st - sd + 0.5, 0.0, 1.0))
        out = np.minimum(out, inside)
    report(progress, total, total)
    for f in filtered:
        f.flags.writeable = False
    return CompiledStructure(out, filtered, tuple(mus), mu_min, lam)


def _check_density(density, ndim):
    f = np.asarray(density, dtype=np.float64)
    if f.ndim != ndim or min(f.shape) < 1 or not np.isfinite(f).all():
        raise ValueError(f"density must be a finite {ndim}D grid; got shape {f.shape}")
    return f


def _check_spacing(spacing):
    h = float(spacing)
    if not np.isfinite(h) or h <= 0:
        raise ValueError(f"spacing must be a cell size > 0; got {spacing!r}")
    return h


def structure_contours(density, *, level=LEVEL, spacing=1.0):
    """Boundary polylines of a 2D structure.

    Parameters
    ----------
    density : (ny, nx) float
        Solid where ``> level``.
    level : float
    spacing : float > 0
        Cell size; 1 gives cell units.

    Returns
    -------
    list of (n, 2) float64
        Closed polylines (first point repeated last) in (x, y), cell ``[j, i]``
        centred at ``((i + 0.5) h, (j + 0.5) h)``; outer boundaries wind
        counter-clockwise (x right, y up), holes clockwise. The grid is
        padded with zeros, so solid touching the box is closed along it.
    """
    from skimage.measure import find_contours

    f = _check_density(density, 2)
    h = _check_spacing(spacing)
    padded = np.pad(f, 1, constant_values=0.0)
    out = []
    for c in find_contours(padded, float(level), positive_orientation="low"):
        xy = np.column_stack([c[:, 1] - 0.5, c[:, 0] - 0.5]) * h
        out.append(xy)
    return out


def structure_mesh(density, *, level=LEVEL, spacing=1.0, progress=None):
    """Closed triangle mesh of a 3D structure (marching cubes).

    Parameters
    ----------
    density : (nz, ny, nx) float
        Solid where ``> level``.
    level : float
    spacing : float > 0
        Cell size; 1 gives cell units.
    progress : callable(done, total) -> bool, optional
        Called between slabs; False raises ``Cancelled``.

    Returns
    -------
    vertices : (v, 3) float64, (x, y, z), cell ``[k, j, i]`` centred at
        ``((i + 0.5) h, (j + 0.5) h, (k + 0.5) h)``
    faces : (f, 3) int64, counter-clockwise seen from outside; empty if no solid.
        Watertight: the grid is padded with zeros, so the solid is capped
        where it meets the box.
    """
    # Shared slab-wise marching cubes with cancel between slabs (inside is "< level").
    from engine.geometry.marching import slab_marching_cubes

    f = _check_density(density, 3)
    h = _check_spacing(spacing)
    lv = float(level)
    # [z, y, x] -> [x, y, z] so vertices come out in (x, y, z); negate so inside is "< level".
    grid = -np.pad(f, 1, constant_values=0.0).transpose(2, 1, 0).astype(np.float64)
    # A sample exactly on the level would put several vertices at one point.
    eps = 1e-7 * max(1.0, abs(lv))
    on = np.abs(grid + lv) < eps
    grid[on] = -lv + np.where(grid[on] + lv < 0, -eps, eps)
    if not (grid < -lv).any():
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    verts, faces = slab_marching_cubes(grid, -lv, progress)
    return (verts.astype(np.float64) - 0.5) * h, faces.astype(np.int64)


def save_structure_png(path, density, *, level=None):
    """Write a 2D structure as an 8-bit grey PNG (solid black, +y up), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Ends in .png.
    density : (ny, nx) float in [0, 1]
    level : float, optional
        If given, a black-and-white image of ``density > level``; otherwise
        grey levels ``255 (1 - density)``.
    """
    from PIL import Image

    if not str(path).lower().endswith(".png"):
        raise ValueError(f"path must end in .png; got {str(path)!r}")
    f = _unit_field(_check_density(density, 2), "density")
    if level is None:
        img = np.rint(255.0 * (1.0 - f)).astype(np.uint8)
    else:
        img = np.where(f > float(level), 0, 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(img[::-1])).save(buf, format="PNG")
    write_atomic(path, buf.getvalue())


def save_structure_stl(path, density, *, level=LEVEL, spacing=1.0, progress=None):
    """Mesh a 3D structure (:func:`structure_mesh`) and write it as binary STL, atomically.

    Raises
    ------
    ValueError
        If the structure has no solid (an empty STL is not written).
    """
    from engine.geometry.mesh_io import export_mesh

    verts, faces = structure_mesh(density, level=level, spacing=spacing, progress=progress)
    if faces.shape[0] == 0:
        raise ValueError(f"density has no solid above level {level}; nothing to write to {str(path)!r}")
    export_mesh(verts, faces, path)
