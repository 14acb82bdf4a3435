"""Built-in problems of the reaction-diffusion paper (Garnier, Schmidt & Rohmer 2022).

Every preset takes ``res``, the number of cells across the domain height
(y), and builds the grid, supports and loads from resolution-independent
numbers: positions are fractions of the domain, forces are totals (spread
over the nodes they act on), the filter radius is a fraction of the height
with a floor of 1.5 cells. Coordinates are ``(x, y[, z])`` with y up.

=====================  =================================================================
name                   problem
=====================  =================================================================
``cantilever_2d``      2:1 plate clamped on the left edge, unit downward load at the
                       middle of the right edge; volfrac 0.4 (paper Fig. 4)
``mbb_2d``             half MBB beam (3:1 modelled half of a 6:1 beam): symmetry at
                       x = 0, roller at the bottom right, load at the top left; 0.5
``lbeam_2d``           L-bracket: unit square minus the top-right 0.6 x 0.6 (passive
                       void), clamped along the top of the vertical arm, unit downward
                       load spread over the top 8 % of the right end of the horizontal
                       arm; volfrac 0.4 of the L; compliance (paper Fig. 18 top)
``lbeam_stress_2d``    the same problem with ``objective="stress"`` (compliance plus a
                       p-norm von Mises term; :mod:`stress_aware`)
``mbb_3d``             MBB beam in 3D (paper Fig. 22): by default the half with a
                       symmetry plane at x = 0 (``half=False`` models the whole beam);
                       length 4 x height for the whole beam, depth 0.25 x height, line
                       load across the depth at the top middle, line rollers (y, z held)
                       across the depth at the bottom ends; volfrac 0.3
``bridge_2d_single``   3:2 plate, pinned at the two bottom corners (2 % patches), five
                       unit downward loads on the top edge at x = 1/6 .. 5/6, all in one
                       load case; volfrac 0.3; ``objective="orientation"`` (eq. 19)
``bridge_2d_multi``    the same five loads as five load cases (paper Fig. 19b)
=====================  =================================================================
"""

from __future__ import annotations

import numpy as np

from .problem import Problem, nearest_node, node_shape, nodes_in_box

__all__ = ["PRESETS", "preset", "cantilever_2d", "mbb_2d", "lbeam_2d", "mbb_3d", "bridge_2d"]


def _empty(shape):
    ns = node_shape(shape)
    dim = len(shape)
    return np.zeros(ns + (dim,), bool), np.zeros((1,) + ns + (dim,))


def _radius(res, fraction):
    return max(1.5, fraction * res)


def _cells(res, ratio, name):
    n = int(round(res * ratio))
    if n < 1:
        raise ValueError(f"{name}: res {res} x {ratio} gives no cells")
    return n


def _check_res(res, minimum=2):
    if int(res) != res or res < minimum:
        raise ValueError(f"res must be an integer >= {minimum} (cells across the height); got {res!r}")
    return int(res)


def cantilever_2d(res=40, *, aspect=2.0, volfrac=0.4, rmin_fraction=0.05, **kw):
    """Cantilever plate: ``res`` cells high, ``aspect * res`` long."""
    res = _check_res(res)
    shape = (res, _cells(res, aspect, "aspect"))
    fixed, loads = _empty(shape)
    fixed[:, 0, :] = True
    loads[(0,) + nearest_node(shape, (1.0, 0.5)) + (1,)] = -1.0
    return Problem(shape=shape, fixed=fixed, loads=loads, volfrac=volfrac,
                   rmin=_radius(res, rmin_fraction), name="cantilever_2d", **kw)


def mbb_2d(res=20, *, aspect=3.0, volfrac=0.5, rmin_fraction=0.075, half=True, **kw):
    """MBB beam in 2D; ``aspect`` is the modelled length over the height."""
    return _mbb((res,), aspect, volfrac, rmin_fraction, half, "mbb_2d", kw)


def mbb_3d(res=16, *, aspect=2.0, depth=0.25, volfrac=0.3, rmin_fraction=0.1, half=True, **kw):
    """MBB beam in 3D, ``res`` cells high.

    ``aspect`` is the modelled length over the height (the half beam when
    ``half``), ``depth`` the depth over the height.
    """
    res = _check_res(res)
    nz = max(1, int(round(res * depth)))
    return _mbb((res, nz), aspect, volfrac, rmin_fraction, half, "mbb_3d", kw)


def _mbb(res_dims, aspect, volfrac, rmin_fraction, half, name, kw):
    res = _check_res(res_dims[0])
    nx = _cells(res, aspect, "aspect")
    if not half and nx % 2:
        nx += 1                                 # the load line needs a node at mid-span
    shape = (res, nx) if len(res_dims) == 1 else (res_dims[1], res, nx)
    dim = len(shape)
    fixed, loads = _empty(shape)
    z_all = () if dim == 2 else (0.0,)
    z_all_hi = () if dim == 2 else (1.0,)
    held = [1] if dim == 2 else [1, 2]          # y (and z across the depth) at the rollers
    right = nodes_in_box(shape, (1.0, 0.0) + z_all, (1.0, 0.0) + z_all_hi)
    for a in held:
        fixed[..., a] |= right
    if half:
        fixed[..., 0] |= nodes_in_box(shape, (0.0, 0.0) + z_all, (0.0, 1.0) + z_all_hi)
        top = nodes_in_box(shape, (0.0, 1.0) + z_all, (0.0, 1.0) + z_all_hi)
        force = 0.5
    else:
        left = nodes_in_box(shape, (0.0, 0.0) + z_all, (0.0, 0.0) + z_all_hi)
        for a in held:
            fixed[..., a] |= left
        top = nodes_in_box(shape, (0.5, 1.0) + z_all, (0.5, 1.0) + z_all_hi)
        fixed[..., 0] |= top
        force = 1.0
    loads[0, ..., 1] = -force * _line_weights(top, shape)
    return Problem(shape=shape, fixed=fixed, loads=loads, volfrac=volfrac,
                   rmin=_radius(res, rmin_fraction), name=name, **kw)


def _line_weights(mask, shape):
    """Consistent nodal weights (sum 1) of a uniform load along a line of nodes.

    In 3D the line runs across the depth (z): end nodes get half a share.
    """
    w = mask.astype(np.float64)
    if len(shape) == 3 and shape[0] > 0:
        w[0] *= 0.5
        w[-1] *= 0.5
    return w / w.sum()


def lbeam_2d(res=40, *, volfrac=0.4, cut=0.6, load_span=0.08, rmin_fraction=0.03,
             objective="compliance", **kw):
    """L-bracket on a ``res x res`` grid; the top-right ``cut x cut`` square is void."""
    res = _check_res(res, 5)
    shape = (res, res)
    passive = np.zeros(shape, np.int8)
    arm = 1.0 - cut
    c = int(round(res * arm))
    passive[c:, c:] = -1                        # rows are y: rows >= c are above the horizontal arm
    arm = c / res                               # snap the arm width to whole cells
    fixed, loads = _empty(shape)
    fixed |= nodes_in_box(shape, (0.0, 1.0), (arm, 1.0))[..., None]
    band = nodes_in_box(shape, (1.0, arm - load_span), (1.0, arm))
    loads[0, ..., 1] = -band.astype(float) / band.sum()
    name = "lbeam_2d" if objective == "compliance" else "lbeam_stress_2d"
    return Problem(shape=shape, fixed=fixed, loads=loads, passive=passive, volfrac=volfrac,
                   rmin=_radius(res, rmin_fraction), objective=objective, name=name, **kw)


def bridge_2d(res=40, *, multi=True, aspect=1.5, volfrac=0.3, n_loads=5, support=0.02,
              rmin_fraction=0.03, objective="orientation", **kw):
    """Bridge with ``n_loads`` unit loads on the top edge; ``multi`` makes each its own case."""
    res = _check_res(res)
    shape = (res, _cells(res, aspect, "aspect"))
    fixed, loads = _empty(shape)
    for x0, x1 in ((0.0, support), (1.0 - support, 1.0)):
        fixed |= nodes_in_box(shape, (x0, 0.0), (x1, 0.0))[..., None]
    cases = []
    for k in range(n_loads):
        f = np.zeros(loads.shape[1:])
        f[nearest_node(shape, ((k + 1) / (n_loads + 1), 1.0)) + (1,)] = -1.0
        cases.append(f)
    loads = np.stack(cases) if multi else np.sum(cases, axis=0)[None]
    name = "bridge_2d_multi" if multi else "bridge_2d_single"
    return Problem(shape=shape, fixed=fixed, loads=loads, volfrac=volfrac,
                   rmin=_radius(res, rmin_fraction), objective=objective, name=name, **kw)


PRESETS = {
    "cantilever_2d": cantilever_2d,
    "mbb_2d": mbb_2d,
    "lbeam_2d": lbeam_2d,
    "lbeam_stress_2d": lambda res=40, **kw: lbeam_2d(res, objective="stress", **kw),
    "mbb_3d": mbb_3d,
    "bridge_2d_single": lambda res=40, **kw: bridge_2d(res, multi=False, **kw),
    "bridge_2d_multi": lambda res=40, **kw: bridge_2d(res, multi=True, **kw),
}


def preset(name, res=None, **overrides):
    """Build the preset ``name`` at ``res`` cells across the height.

    Parameters
    ----------
    name : str, one of :data:`PRESETS`
    res : int, optional (each preset has a default)
    **overrides : keyword parameters of the preset (``volfrac``, ``aspect``,
        ``half``, ...) or :class:`Problem` fields (``penal``, ``young``...).
    """
    if name not in PRESETS:
        raise ValueError(f"preset: unknown name {name!r}; expected one of {sorted(PRESETS)}")
    fn = PRESETS[name]
    return fn(**overrides) if res is None else fn(res, **overrides)
