"""Fused explicit steps of the restricted, anisotropic Gray-Scott model (paper eqs. 9-13).

One step of eq. 13 on a regular grid of spacing ``dx``::

    u' = u + dt * ( (sigma grad) . grad u  +  gamma f(u, v) )
    v' = v + dt * ( (d / dim) lap v  +  gamma g(u, v) 1_Omega  -  lambda (1 - 1_Omega) v )
    f = -u v^2 + F (1 - u),    g = u v^2 - (k (1 - alpha Gamma) + F) v

``(sigma grad) . grad u = sum_ij sigma_ij d_i d_j u`` is discretised by
second-order central differences, the mixed terms by the four diagonal
neighbours, ``d_x d_y u ~ (u[+,+] - u[+,-] - u[-,+] + u[-,-]) / (4 dx^2)``:
a 9-point stencil in 2D, 19 points in 3D. ``sigma`` is trace-normalised
(eq. 11), so the isotropic tensor is ``I / dim``; ``v`` diffuses with the
same normalisation, ``d / dim`` per axis, so that ``d = D_v / D_u`` holds
for an isotropic ``u`` as the paper defines it (4.1). (With ``d`` applied
to the unnormalised Laplacian, ``D_v`` would exceed the slow diffusivity
of ``u`` and no pattern forms at the paper's ``d = 1/2``.)

Boundary: Neumann at the grid faces, by reading a cell outside the grid as
its mirror image across the face, i.e. the edge cell itself (cell-centred
grid), so ``du/dn = 0``. That is zero flux for ``v`` and for the diagonal
part of ``sigma``; the flux of a mixed term through a face is not exactly
zero (that would need ``n . sigma grad u = 0``). The paper grows inside
``Omega`` and absorbs ``v`` outside, so the grid faces normally lie in the
empty region where nothing flows.

``|v'| < TINY`` is stored as 0. The decaying tails ahead of a front and
outside ``Omega`` would otherwise pass through subnormal numbers, which
cost x86 cores ~100x per operation; 1e-150 keeps ``v^2`` normal and is
dynamically irrelevant (the empty state ``u = 1, v = 0`` is stable). It
also makes "empty" exact, which the growth driver uses to skip cells the
pattern cannot have reached.

Speed: the kernels are compiled by numba, vectorise the inner loop over
x and, for two or more steps, advance two steps per sweep through memory
(a rolling buffer of three rows or planes holds the intermediate level),
in bands of rows (2D) or planes (3D) run in parallel.

With the paper's anisotropy ``xi = 5`` every off-centre stencil weight of
the ``u`` operator is non-negative for any orientation (that holds while
``(xi - 1)^2 < 4 xi``, i.e. ``xi < 5.83``), so the diffusion part is
monotone.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numba
import numpy as np
from numba import njit, prange

from engine.progress import PARALLEL_LOCK

__all__ = ["RDParams", "TINY", "stability_limit", "default_dt", "resolve_params", "gray_scott_step",
           "operator_rate", "check_fields", "kill_rate", "Stepper"]

#: |v| below this is flushed to 0 after every step (see module docstring).
TINY = 1e-150
#: Fraction of the stability limits that the default time step uses.
STABILITY_MARGIN = 0.9


@dataclass(frozen=True)
class RDParams:
    """Parameters of eq. 12 / 13 (defaults: the paper's "Replication of Results").

    d : float, ratio D_v / D_u of diffusivities for an isotropic ``u`` (v diffuses
        with d / dim per axis, see the module notes)
    gamma : float, reaction speed; larger gamma, shorter wavelength (~ 1 / sqrt(gamma))
    F, k : float, feed and kill rates
    alpha : float in [0, 1], how strongly the infill map lowers the kill rate (eq. 10)
    xi : float >= 1, anisotropy of the diffusion tensors (eq. 11)
    lambda_ : float or None, absorption rate of ``v`` outside ``Omega`` (eq. 8);
        None: ``1 / dt``, the strongest absorption an explicit step keeps monotone
    dt : float or None, time step; None: :func:`default_dt`; above :func:`stability_limit` refused
    dx : float, grid spacing
    """

    d: float = 0.5
    gamma: float = 1.0
    F: float = 0.0395
    k: float = 0.0595
    alpha: float = 0.5
    xi: float = 5.0
    lambda_: float | None = None
    dt: float | None = None
    dx: float = 1.0

    def validated(self) -> "RDParams":
        """Return self after checking every value; the message names the bad one."""
        def positive(name, value, allow_none=False, allow_zero=False):
            if value is None and allow_none:
                return
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
                need = ">= 0" if allow_zero else "> 0"
                raise ValueError(f"RDParams.{name} must be a finite number {need}; got {value!r}")
        positive("d", self.d)
        positive("gamma", self.gamma)
        positive("F", self.F, allow_zero=True)
        positive("k", self.k, allow_zero=True)
        positive("alpha", self.alpha, allow_zero=True)
        positive("lambda_", self.lambda_, allow_none=True)
        positive("dt", self.dt, allow_none=True)
        positive("dx", self.dx)
        positive("xi", self.xi)
        if self.alpha > 1:
            raise ValueError(f"RDParams.alpha must lie in [0, 1]; got {self.alpha!r}")
        if self.xi < 1:
            raise ValueError(f"RDParams.xi must be >= 1 (main over secondary diffusivity); got {self.xi!r}")
        return self

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> "RDParams":
        names = set(cls.__dataclass_fields__)
        unknown = set(data) - names
        if unknown:
            raise ValueError(f"RDParams: unknown parameters {sorted(unknown)}; expected some of {sorted(names)}")
        return cls(**{k: (None if v is None else float(v)) for k, v in data.items()}).validated()


def _cell_name(index, ndim):
    axes = "yx" if ndim == 2 else "zyx"
    return "[" + ", ".join(f"{a}={int(i)}" for a, i in zip(axes, index)) + "]"


def check_fields(u, v, sigma, inside, gamma_map=None):
    """Validate the per-cell inputs of a step; return float64 / bool arrays.

    Parameters
    ----------
    u, v : (ny, nx) or (nz, ny, nx) float, concentrations
    sigma : grid + (dim, dim) float, symmetric diffusion tensors of ``u``,
        components in (x, y[, z]) order
    inside : grid bool, the infill space ``Omega``
    gamma_map : grid float in [0, 1] or None, the infill map ``Gamma``

    Raises
    ------
    ValueError naming the array, and the first bad cell where there is one.
    """
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    if u.ndim not in (2, 3):
        raise ValueError(f"u must be a 2D [y, x] or 3D [z, y, x] grid; got shape {u.shape}")
    shape, dim = u.shape, u.ndim
    for name, a in (("u", u), ("v", v)):
        if a.shape != shape:
            raise ValueError(f"{name} must have the grid shape {shape}; got {a.shape}")
        if not np.isfinite(a).all():
            raise ValueError(f"{name} has NaN or infinite values (first at cell "
                             f"{_cell_name(np.argwhere(~np.isfinite(a))[0], dim)})")
    sigma = np.asarray(sigma, dtype=np.float64)
    if sigma.shape != shape + (dim, dim):
        raise ValueError(f"sigma must have shape {shape + (dim, dim)} (grid + (d, d)); got {sigma.shape}")
    bad = ~np.isfinite(sigma).all(axis=(-2, -1))
    if bad.any():
        raise ValueError(f"sigma has a NaN or infinite tensor at cell {_cell_name(np.argwhere(bad)[0], dim)} "
                         f"({int(bad.sum())} such cells); expected finite symmetric tensors")
    asym = np.abs(sigma - np.swapaxes(sigma, -1, -2)).max(axis=(-2, -1))
    scale = np.abs(sigma).max(axis=(-2, -1))
    nonsym = asym > 1e-10 * np.maximum(scale, 1e-300)
    if nonsym.any():
        first = tuple(np.argwhere(nonsym)[0])
        raise ValueError(f"sigma is not symmetric at cell {_cell_name(first, dim)} (|s_ij - s_ji| = "
                         f"{asym[first]:.3g}); diffusion tensors must be symmetric")
    inside = np.asarray(inside)
    if inside.shape != shape:
        raise ValueError(f"inside (the infill space) must have the grid shape {shape}; got {inside.shape}")
    inside = inside.astype(bool)
    if gamma_map is None:
        gamma_map = np.zeros(shape)
    else:
        gamma_map = np.asarray(gamma_map, dtype=np.float64)
        if gamma_map.shape != shape:
            raise ValueError(f"gamma_map must have the grid shape {shape}; got {gamma_map.shape}")
        if not np.isfinite(gamma_map).all() or gamma_map.min() < 0 or gamma_map.max() > 1:
            raise ValueError("gamma_map (the infill map Gamma) must be finite and lie in [0, 1]")
    return u, v, sigma, inside, gamma_map


def kill_rate(gamma_map, params: RDParams) -> np.ndarray:
    """``k (1 - alpha Gamma)`` per cell (eq. 10)."""
    return params.k * (1.0 - params.alpha * np.asarray(gamma_map, dtype=np.float64))


def operator_rate(sigma, dx) -> np.ndarray:
    """Per-cell Gershgorin bound of the discrete ``(sigma grad) . grad`` operator.

    ``(4 tr(sigma) + 2 sum_{i<j} |sigma_ij|) / dx^2``: the centre weight plus
    the absolute off-centre weights of the stencil. Every eigenvalue of the
    operator has modulus at most this.
    """
    s = np.asarray(sigma, dtype=np.float64)
    dim = s.shape[-1]
    tr = np.trace(s, axis1=-2, axis2=-1)
    off = sum(np.abs(s[..., i, j]) for i in range(dim) for j in range(i + 1, dim))
    return (4.0 * tr + 2.0 * off) / dx ** 2


#: Largest gamma dt accepted. One explicit step at a seed (u = v = 1)
#: multiplies u by 1 - gamma dt, so u dips below 0 for gamma dt > 1; up to
#: ~1.35 the growth recovers, from ~1.4 on it diverges (measured on a disc,
#: xi = 5). The paper runs 1.05-1.35 (Table 3); the default stays at 0.9.
REACTION_LIMIT = 1.35


def stability_limit(sigma, params: RDParams) -> tuple[float, str]:
    """Largest accepted explicit time step and the term that sets it.

    Forward Euler on ``w' = -A w`` is stable while ``dt * rho(A) <= 2``. The
    linear parts are bounded by Gershgorin: ``u`` by :func:`operator_rate`
    (this is where the tensor's largest eigenvalue and orientation enter),
    ``v`` by ``4 d / dx^2`` plus the absorption ``lambda`` outside ``Omega``;
    ``lambda dt <= 1`` keeps the absorption from flipping the sign of ``v``.
    The reaction is stiffest at a seed: ``gamma dt <= REACTION_LIMIT``.

    The paper's rule of thumb ``dt / dx^2 < 1/8`` (4.6) is for its own
    stencil scaling: its Table 3 runs ``dt = 1.1`` at ``dx = 1.7``
    (``dt / dx^2 = 0.38``), which this bound accepts (0.43 dx^2 at
    ``xi = 5`` and 45 degrees).

    Returns
    -------
    dt_max : float, the largest ``dt`` accepted
    why : str, which term sets it (for messages)
    """
    return min(_limits(sigma, params))


def _limits(sigma, p):
    rate = operator_rate(sigma, p.dx)
    flat = int(np.argmax(rate))
    rho_u = float(rate.reshape(-1)[flat])
    where = _cell_name(np.unravel_index(flat, rate.shape), rate.ndim)
    rho_v = 4.0 * p.d / p.dx ** 2
    limits = [(2.0 / rho_u, f"diffusion of u (operator rate {rho_u:.4g} at cell {where})"),
              (REACTION_LIMIT / p.gamma, f"reaction: gamma dt <= {REACTION_LIMIT:g} (gamma = {p.gamma:g})")]
    if p.lambda_ is None:       # lambda = 1 / dt: dt (rho_v + 1/dt) <= 2
        limits.append((1.0 / rho_v, f"diffusion of v with lambda = 1/dt (rate {rho_v:.4g})"))
    else:
        limits.append((2.0 / (rho_v + p.lambda_), f"diffusion and absorption of v (rate {rho_v + p.lambda_:.4g})"))
        limits.append((1.0 / p.lambda_, f"absorption lambda = {p.lambda_:g} (lambda dt <= 1)"))
    return limits


def default_dt(sigma, params: RDParams) -> float:
    """The step used for ``dt=None``: :data:`STABILITY_MARGIN` of the linear
    limits, and ``gamma dt <= 1`` (``u`` stays non-negative at a seed)."""
    limits = [dt for dt, _ in _limits(sigma, params)]
    return STABILITY_MARGIN * min(limits[:1] + limits[2:] + [1.0 / params.gamma])


def resolve_params(sigma, params: RDParams) -> RDParams:
    """Fill in ``dt`` / ``lambda_`` left as None and refuse an unstable ``dt``."""
    p = params.validated()
    dt_max, why = stability_limit(sigma, p)
    if p.dt is None:
        p = replace(p, dt=default_dt(sigma, p))
    elif p.dt > dt_max * (1.0 + 1e-12):     # a resolved lambda = 1/dt may round a hair over
        raise ValueError(f"RDParams.dt = {p.dt:g} is unstable for this tensor field: the explicit step "
                         f"needs dt <= {dt_max:.4g} (dx = {p.dx:g}; limited by {why}); use a smaller dt "
                         f"or dt=None (here {default_dt(sigma, p):.4g})")
    if p.lambda_ is None:
        p = replace(p, lambda_=1.0 / p.dt)
    return p


# ------------------------------------------------------------------ kernels
#
# Layout. The state is one array ``w`` of shape (2,) + grid, ``w[0] = u``,
# ``w[1] = v``; the per-cell constants are one array ``P`` of shape
# (ncoef + 1,) + grid: the tensor coefficients pre-multiplied by
# dt / dx^2, (xx, yy, xy / 2) in 2D, (xx, yy, zz, xy / 2, xz / 2, yz / 2) in
# 3D, so that a mixed term is ``coef * (corner combination)``, then ``q``:
# dt gamma (k(x) + F) >= 0 inside Omega, -dt lambda < 0 outside (the sign
# says whether the u v^2 source is on). Few base arrays and affine indices
# let LLVM prove the loads and stores disjoint and vectorise the inner loop
# (8 doubles per AVX-512 instruction), so interior cells run through a
# slice-based loop and the two edge columns through the same arithmetic
# with clamped neighbours; both paths evaluate the identical expression,
# so a cell's result never depends on which path computed it.


@njit(cache=True, nogil=True, inline="always")
def _update(c, lu, vc, lv, q, dtg, dtgf, cv):
    uvv = c * vc * vc
    src = dtg * uvv if q >= 0.0 else 0.0
    un = c + lu - dtg * uvv + dtgf * (1.0 - c)
    vn = vc + cv * lv + src - abs(q) * vc
    return un, (vn if abs(vn) >= TINY else 0.0)


@njit(cache=True, nogil=True, inline="always")
def _lu_2d(c, ue, uw, un, us, une, unw, use, usw, cxx, cyy, cxy):
    return cxx * (ue + uw - 2.0 * c) + cyy * (un + us - 2.0 * c) + cxy * (une - unw - use + usw)


@njit(cache=True, nogil=True)
def _row_core_2d(uc, un, us, vc, vn, vs, cxx, cyy, cxy, q, uo, vo, x0, x1, dtg, dtgf, cv):
    """One row of one step from row views: centre ``c``, north ``n`` (y + 1), south ``s`` (y - 1)."""
    nx = uc.shape[0]
    # edge columns, neighbours clamped (zero flux)
    for x in (0, nx - 1):
        if x0 <= x < x1 and (x == 0 or nx > 1):
            xm = x - 1 if x > 0 else 0
            xp = x + 1 if x < nx - 1 else nx - 1
            lu = _lu_2d(uc[x], uc[xp], uc[xm], un[x], us[x], un[xp], un[xm], us[xp], us[xm],
                        cxx[x], cyy[x], cxy[x])
            lv = vc[xp] + vc[xm] + vn[x] + vs[x] - 4.0 * vc[x]
            uo[x], vo[x] = _update(uc[x], lu, vc[x], lv, q[x], dtg, dtgf, cv)
    lo, hi = max(x0, 1), min(x1, nx - 1)
    if hi <= lo:
        return
    a, b = lo - 1, hi - 1          # x - 1
    e, f = lo + 1, hi + 1          # x + 1
    uc0, ue, uw = uc[lo:hi], uc[e:f], uc[a:b]
    un0, une, unw = un[lo:hi], un[e:f], un[a:b]
    us0, use, usw = us[lo:hi], us[e:f], us[a:b]
    vc0, ve, vw, vn0, vs0 = vc[lo:hi], vc[e:f], vc[a:b], vn[lo:hi], vs[lo:hi]
    cxx0, cyy0, cxy0, q0 = cxx[lo:hi], cyy[lo:hi], cxy[lo:hi], q[lo:hi]
    uo0, vo0 = uo[lo:hi], vo[lo:hi]
    for i in range(hi - lo):
        c = uc0[i]
        lu = _lu_2d(c, ue[i], uw[i], un0[i], us0[i], une[i], unw[i], use[i], usw[i], cxx0[i], cyy0[i], cxy0[i])
        lv = ve[i] + vw[i] + vn0[i] + vs0[i] - 4.0 * vc0[i]
        uo0[i], vo0[i] = _update(c, lu, vc0[i], lv, q0[i], dtg, dtgf, cv)


@njit(cache=True, nogil=True)
def _row_2d(w, wo, P, y, x0, x1, dtg, dtgf, cv):
    ny = w.shape[1]
    ym = y - 1 if y > 0 else 0
    yp = y + 1 if y < ny - 1 else ny - 1
    _row_core_2d(w[0, y], w[0, yp], w[0, ym], w[1, y], w[1, yp], w[1, ym], P[0, y], P[1, y], P[2, y], P[3, y],
                 wo[0, y], wo[1, y], x0, x1, dtg, dtgf, cv)


@njit(cache=True, nogil=True)
def _band_2d(w, wo, P, ya, yb, y0, y1, x0, x1, dtg, dtgf, cv):
    """Two steps for the output rows [ya, yb) of the box [y0:y1, x0:x1], reading ``w``, writing ``wo``.

    The intermediate level lives in a rolling buffer of three rows (outside
    the box it is the frozen ``w``): once row ``r`` of the first step is
    made, row ``r - 1`` of the second has all it needs. Each cell comes
    from memory once for two steps, and a band needs nothing from the
    others (it recomputes one first-step row beyond each end), so bands run
    in parallel.
    """
    ny, nx = w.shape[1], w.shape[2]
    mid = np.empty((2, 3, nx))
    ra, rb = max(ya - 1, y0), min(yb + 1, y1)
    for r in range(ra, rb + 1):
        if r < rb:                      # first step, row r
            k = r % 3
            # the frozen columns around the box, read by the second step
            if x0 > 0:
                mid[0, k, x0 - 1] = w[0, r, x0 - 1]
                mid[1, k, x0 - 1] = w[1, r, x0 - 1]
            if x1 < nx:
                mid[0, k, x1] = w[0, r, x1]
                mid[1, k, x1] = w[1, r, x1]
            rm = r - 1 if r > 0 else 0
            rp = r + 1 if r < ny - 1 else ny - 1
            _row_core_2d(w[0, r], w[0, rp], w[0, rm], w[1, r], w[1, rp], w[1, rm],
                         P[0, r], P[1, r], P[2, r], P[3, r], mid[0, k], mid[1, k], x0, x1, dtg, dtgf, cv)
        y = r - 1                       # second step, row r - 1
        if ya <= y < yb:
            ym = y - 1 if y > 0 else 0
            yp = y + 1 if y < ny - 1 else ny - 1
            # 1D rows chosen one by one keep unit-stride types (vectorised loop)
            uc = mid[0, y % 3] if y0 <= y < y1 else w[0, y]
            vc = mid[1, y % 3] if y0 <= y < y1 else w[1, y]
            un = mid[0, yp % 3] if y0 <= yp < y1 else w[0, yp]
            vn = mid[1, yp % 3] if y0 <= yp < y1 else w[1, yp]
            us = mid[0, ym % 3] if y0 <= ym < y1 else w[0, ym]
            vs = mid[1, ym % 3] if y0 <= ym < y1 else w[1, ym]
            _row_core_2d(uc, un, us, vc, vn, vs, P[0, y], P[1, y], P[2, y], P[3, y], wo[0, y], wo[1, y],
                         x0, x1, dtg, dtgf, cv)


@njit(cache=True, nogil=True, parallel=True)
def _run_2d(w, w2, P, y0, y1, x0, x1, nsteps, dtg, dtgf, cv, nbands):
    """``nsteps`` steps on the window [y0:y1, x0:x1]; cells outside it are read, never written.

    Steps go in pairs (:func:`_band_2d`, ``nbands`` row bands in parallel),
    an odd last one alone. On return ``w`` holds the result; ``w2`` is
    scratch of the same shape.
    """
    ny, nx = w.shape[1], w.shape[2]
    # the scratch buffer must agree with w on the ring around the window
    ha, hb = max(y0 - 1, 0), min(y1 + 1, ny)
    wa, wb = max(x0 - 1, 0), min(x1 + 1, nx)
    for y in prange(ha, hb):
        w2[:, y, wa:wb] = w[:, y, wa:wb]
    rows = y1 - y0
    nb = max(1, min(nbands, rows // 8))
    flip = False                        # False: the current level is in w
    for _ in range(nsteps // 2):
        if flip:
            for b in prange(nb):
                _band_2d(w2, w, P, y0 + (rows * b) // nb, y0 + (rows * (b + 1)) // nb, y0, y1, x0, x1,
                         dtg, dtgf, cv)
        else:
            for b in prange(nb):
                _band_2d(w, w2, P, y0 + (rows * b) // nb, y0 + (rows * (b + 1)) // nb, y0, y1, x0, x1,
                         dtg, dtgf, cv)
        flip = not flip
    if nsteps % 2 == 1:
        if flip:
            for y in prange(y0, y1):
                _row_2d(w2, w, P, y, x0, x1, dtg, dtgf, cv)
        else:
            for y in prange(y0, y1):
                _row_2d(w, w2, P, y, x0, x1, dtg, dtgf, cv)
        flip = not flip
    if flip:
        for y in prange(y0, y1):
            w[:, y, x0:x1] = w2[:, y, x0:x1]


@njit(cache=True, nogil=True, inline="always")
def _lu_3d(c, ue, uw, un, us, uu, ud, une, unw, use, usw, uue, uuw, ude, udw, uun, uus, udn, uds,
           cxx, cyy, czz, cxy, cxz, cyz):
    # n/s: y +-1, u/d: z +-1, e/w: x +-1
    return (cxx * (ue + uw - 2.0 * c) + cyy * (un + us - 2.0 * c) + czz * (uu + ud - 2.0 * c)
            + cxy * (une - unw - use + usw) + cxz * (uue - uuw - ude + udw) + cyz * (uun - uus - udn + uds))


@njit(cache=True, nogil=True)
def _row_core_3d(uc, un, us, uu, ud, uun, uus, udn, uds, vc, vn, vs, vu, vd,
                 cxx, cyy, czz, cxy, cxz, cyz, q, uo, vo, x0, x1, dtg, dtgf, cv):
    """One row of one step from row views; n/s: y +- 1, u/d: z +- 1."""
    nx = uc.shape[0]
    for x in (0, nx - 1):
        if x0 <= x < x1 and (x == 0 or nx > 1):
            xm = x - 1 if x > 0 else 0
            xp = x + 1 if x < nx - 1 else nx - 1
            lu = _lu_3d(uc[x], uc[xp], uc[xm], un[x], us[x], uu[x], ud[x], un[xp], un[xm], us[xp], us[xm],
                        uu[xp], uu[xm], ud[xp], ud[xm], uun[x], uus[x], udn[x], uds[x],
                        cxx[x], cyy[x], czz[x], cxy[x], cxz[x], cyz[x])
            lv = vc[xp] + vc[xm] + vn[x] + vs[x] + vu[x] + vd[x] - 6.0 * vc[x]
            uo[x], vo[x] = _update(uc[x], lu, vc[x], lv, q[x], dtg, dtgf, cv)
    lo, hi = max(x0, 1), min(x1, nx - 1)
    if hi <= lo:
        return
    a, b = lo - 1, hi - 1
    e, f = lo + 1, hi + 1
    uc0, ue, uw = uc[lo:hi], uc[e:f], uc[a:b]
    un0, une, unw = un[lo:hi], un[e:f], un[a:b]
    us0, use, usw = us[lo:hi], us[e:f], us[a:b]
    uu0, uue, uuw = uu[lo:hi], uu[e:f], uu[a:b]
    ud0, ude, udw = ud[lo:hi], ud[e:f], ud[a:b]
    uun0, uus0, udn0, uds0 = uun[lo:hi], uus[lo:hi], udn[lo:hi], uds[lo:hi]
    vc0, ve, vw = vc[lo:hi], vc[e:f], vc[a:b]
    vn0, vs0, vu0, vd0 = vn[lo:hi], vs[lo:hi], vu[lo:hi], vd[lo:hi]
    cxx0, cyy0, czz0 = cxx[lo:hi], cyy[lo:hi], czz[lo:hi]
    cxy0, cxz0, cyz0, q0 = cxy[lo:hi], cxz[lo:hi], cyz[lo:hi], q[lo:hi]
    uo0, vo0 = uo[lo:hi], vo[lo:hi]
    for i in range(hi - lo):
        c = uc0[i]
        lu = _lu_3d(c, ue[i], uw[i], un0[i], us0[i], uu0[i], ud0[i], une[i], unw[i], use[i], usw[i],
                    uue[i], uuw[i], ude[i], udw[i], uun0[i], uus0[i], udn0[i], uds0[i],
                    cxx0[i], cyy0[i], czz0[i], cxy0[i], cxz0[i], cyz0[i])
        lv = ve[i] + vw[i] + vn0[i] + vs0[i] + vu0[i] + vd0[i] - 6.0 * vc0[i]
        uo0[i], vo0[i] = _update(c, lu, vc0[i], lv, q0[i], dtg, dtgf, cv)


@njit(cache=True, nogil=True)
def _plane_row_3d(uc, uu, ud, vc, vu, vd, P, z, y, uo, vo, x0, x1, dtg, dtgf, cv):
    """Row ``y`` of plane ``z`` from the (ny, nx) planes z (c), z + 1 (u), z - 1 (d)."""
    ny = uc.shape[0]
    ym = y - 1 if y > 0 else 0
    yp = y + 1 if y < ny - 1 else ny - 1
    _row_core_3d(uc[y], uc[yp], uc[ym], uu[y], ud[y], uu[yp], uu[ym], ud[yp], ud[ym],
                 vc[y], vc[yp], vc[ym], vu[y], vd[y],
                 P[0, z, y], P[1, z, y], P[2, z, y], P[3, z, y], P[4, z, y], P[5, z, y], P[6, z, y],
                 uo[y], vo[y], x0, x1, dtg, dtgf, cv)


@njit(cache=True, nogil=True)
def _row_3d(w, wo, P, z, y, x0, x1, dtg, dtgf, cv):
    nz = w.shape[1]
    zm = z - 1 if z > 0 else 0
    zp = z + 1 if z < nz - 1 else nz - 1
    _plane_row_3d(w[0, z], w[0, zp], w[0, zm], w[1, z], w[1, zp], w[1, zm], P, z, y, wo[0, z], wo[1, z],
                  x0, x1, dtg, dtgf, cv)


@njit(cache=True, nogil=True)
def _band_3d(w, wo, P, za, zb, z0, z1, y0, y1, x0, x1, dtg, dtgf, cv):
    """Two steps for the output planes [za, zb) of the box; the 3D twin of :func:`_band_2d`
    with a rolling buffer of three (ny, nx) planes."""
    nz, ny, nx = w.shape[1], w.shape[2], w.shape[3]
    mid = np.empty((2, 3, ny, nx))
    wa, wb = max(x0 - 1, 0), min(x1 + 1, nx)
    ra, rb = max(za - 1, z0), min(zb + 1, z1)
    for r in range(ra, rb + 1):
        if r < rb:                      # first step, plane r
            k = r % 3
            # the frozen ring around the box in this plane, read by the second step
            if y0 > 0:
                mid[:, k, y0 - 1, wa:wb] = w[:, r, y0 - 1, wa:wb]
            if y1 < ny:
                mid[:, k, y1, wa:wb] = w[:, r, y1, wa:wb]
            if x0 > 0:
                mid[:, k, y0:y1, x0 - 1] = w[:, r, y0:y1, x0 - 1]
            if x1 < nx:
                mid[:, k, y0:y1, x1] = w[:, r, y0:y1, x1]
            rm = r - 1 if r > 0 else 0
            rp = r + 1 if r < nz - 1 else nz - 1
            for y in range(y0, y1):
                _plane_row_3d(w[0, r], w[0, rp], w[0, rm], w[1, r], w[1, rp], w[1, rm], P, r, y,
                              mid[0, k], mid[1, k], x0, x1, dtg, dtgf, cv)
        z = r - 1                       # second step, plane r - 1
        if za <= z < zb:
            zm = z - 1 if z > 0 else 0
            zp = z + 1 if z < nz - 1 else nz - 1
            uc = mid[0, z % 3] if z0 <= z < z1 else w[0, z]
            vc = mid[1, z % 3] if z0 <= z < z1 else w[1, z]
            uu = mid[0, zp % 3] if z0 <= zp < z1 else w[0, zp]
            vu = mid[1, zp % 3] if z0 <= zp < z1 else w[1, zp]
            ud = mid[0, zm % 3] if z0 <= zm < z1 else w[0, zm]
            vd = mid[1, zm % 3] if z0 <= zm < z1 else w[1, zm]
            for y in range(y0, y1):
                _plane_row_3d(uc, uu, ud, vc, vu, vd, P, z, y, wo[0, z], wo[1, z], x0, x1, dtg, dtgf, cv)


@njit(cache=True, nogil=True, parallel=True)
def _run_3d(w, w2, P, z0, z1, y0, y1, x0, x1, nsteps, dtg, dtgf, cv, nbands):
    """3D twin of :func:`_run_2d`: pairs of steps in bands of z planes, an odd
    last step parallel over (z, y) rows."""
    nz, ny, nx = w.shape[1], w.shape[2], w.shape[3]
    za, zb = max(z0 - 1, 0), min(z1 + 1, nz)
    ha, hb = max(y0 - 1, 0), min(y1 + 1, ny)
    wa, wb = max(x0 - 1, 0), min(x1 + 1, nx)
    for z in prange(za, zb):
        w2[:, z, ha:hb, wa:wb] = w[:, z, ha:hb, wa:wb]
    planes = z1 - z0
    nb = max(1, min(nbands, planes // 4))
    flip = False
    for _ in range(nsteps // 2):
        if flip:
            for b in prange(nb):
                _band_3d(w2, w, P, z0 + (planes * b) // nb, z0 + (planes * (b + 1)) // nb, z0, z1, y0, y1,
                         x0, x1, dtg, dtgf, cv)
        else:
            for b in prange(nb):
                _band_3d(w, w2, P, z0 + (planes * b) // nb, z0 + (planes * (b + 1)) // nb, z0, z1, y0, y1,
                         x0, x1, dtg, dtgf, cv)
        flip = not flip
    nyr = y1 - y0
    nrows = planes * nyr
    if nsteps % 2 == 1:
        if flip:
            for r in prange(nrows):
                _row_3d(w2, w, P, z0 + r // nyr, y0 + r % nyr, x0, x1, dtg, dtgf, cv)
        else:
            for r in prange(nrows):
                _row_3d(w, w2, P, z0 + r // nyr, y0 + r % nyr, x0, x1, dtg, dtgf, cv)
        flip = not flip
    if flip:
        for r in prange(nrows):
            z = z0 + r // nyr
            y = y0 + r % nyr
            w[:, z, y, x0:x1] = w2[:, z, y, x0:x1]


@njit(cache=True, nogil=True)
def _row_sum(u, q, x0, x1):
    acc = 0.0
    for x in range(x0, x1):
        if q[x] >= 0.0:
            acc += u[x]
    return acc


@njit(cache=True, nogil=True, parallel=True)
def _omega_sums_2d(w, P, y0, y1, x0, x1, out):
    for y in prange(y0, y1):
        out[y] = _row_sum(w[0, y], P[3, y], x0, x1)


@njit(cache=True, nogil=True, parallel=True)
def _omega_sums_3d(w, P, z0, z1, y0, y1, x0, x1, out):
    nyr = y1 - y0
    for r in prange((z1 - z0) * nyr):
        z = z0 + r // nyr
        y = y0 + r % nyr
        out[z, y] = _row_sum(w[0, z, y], P[6, z, y], x0, x1)


# ------------------------------------------------------------------ stepper

class Stepper:
    """Prepared per-cell constants and a scratch buffer for repeated steps.

    Internal to the package: :func:`gray_scott_step`, the growth driver and
    the regrowth use it. The state is one (2,) + grid float64 array
    ``w = [u, v]`` that :meth:`run` updates in place.

    Parameters
    ----------
    sigma, inside, gamma_map : validated arrays (see :func:`check_fields`)
    params : RDParams with ``dt`` and ``lambda_`` resolved
    """

    def __init__(self, sigma, inside, gamma_map, params: RDParams):
        p = params
        shape = inside.shape
        self.dim = dim = len(shape)
        self.shape = shape
        self.params = p
        h = p.dt / p.dx ** 2
        ncoef = dim * (dim + 1) // 2
        P = np.empty((ncoef + 1,) + shape)
        for i in range(dim):
            P[i] = sigma[..., i, i] * h
        pairs = [(i, j) for i in range(dim) for j in range(i + 1, dim)]
        for n, (i, j) in enumerate(pairs):
            P[dim + n] = sigma[..., i, j] * (0.5 * h)
        kill = kill_rate(gamma_map, p)
        P[ncoef] = np.where(inside, p.dt * p.gamma * (kill + p.F), -p.dt * p.lambda_)
        self.P = P
        self.dtg = p.dt * p.gamma
        self.dtgf = p.dt * p.gamma * p.F
        self.cv = p.d / dim * h
        self._w2 = np.empty((2,) + shape)
        self._rows = np.zeros(shape[:-1])

    def new_state(self, u, v):
        """A fresh (2,) + grid C-contiguous array holding copies of ``u`` and ``v``."""
        w = np.empty((2,) + self.shape)
        w[0], w[1] = u, v
        return w

    def run(self, w, nsteps, box=None) -> None:
        """Advance ``w = [u, v]`` by ``nsteps`` steps in place.

        Only the cells of ``box`` (a tuple of (start, stop) per axis, array
        order; None = whole grid) are updated; the others are read as
        frozen boundary values.
        """
        lo, hi = self._bounds(box)
        if nsteps <= 0 or any(b <= a for a, b in zip(lo, hi)):
            return
        consts = (self.dtg, self.dtgf, self.cv)
        # two bands per thread: a band's first-step halo rows (planes) are the only repeated work
        if self.dim == 2:
            nb = 2 * numba.get_num_threads()
            _run_2d(w, self._w2, self.P, lo[0], hi[0], lo[1], hi[1], int(nsteps), *consts, nb)
        else:
            nb = 2 * numba.get_num_threads()
            _run_3d(w, self._w2, self.P, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], int(nsteps), *consts, nb)

    def omega_sum(self, w, box=None) -> float:
        """Sum of ``u`` over the Omega cells of ``box``, in a fixed order (reproducible)."""
        lo, hi = self._bounds(box)
        if any(b <= a for a, b in zip(lo, hi)):
            return 0.0
        if self.dim == 2:
            _omega_sums_2d(w, self.P, lo[0], hi[0], lo[1], hi[1], self._rows)
            return math.fsum(self._rows[lo[0]:hi[0]])
        _omega_sums_3d(w, self.P, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], self._rows)
        return math.fsum(self._rows[lo[0]:hi[0], lo[1]:hi[1]].ravel())

    def _bounds(self, box):
        if box is None:
            return [0] * self.dim, list(self.shape)
        return [int(a) for a, _ in box], [int(b) for _, b in box]


def gray_scott_step(u, v, sigma, *, inside, gamma_map=None, params: RDParams = RDParams(), steps=1,
                    box=None):
    """Advance the restricted anisotropic Gray-Scott system by ``steps`` explicit steps (eq. 13).

    Parameters
    ----------
    u, v : (ny, nx) or (nz, ny, nx) float64, concentrations; not modified
    sigma : grid + (dim, dim) float64, symmetric trace-normalised diffusion
        tensors of ``u`` (see :func:`engine.rd.diffusion.diffusion_tensors`),
        components in (x, y[, z]) order
    inside : grid bool, the infill space ``Omega``
    gamma_map : grid float in [0, 1] or None, the infill map ``Gamma`` (eq. 10)
    params : RDParams; ``dt=None`` takes the largest stable step,
        an unstable ``dt`` is refused
    steps : int >= 0
    box : tuple of (start, stop) per axis (array order) or None; only these
        cells are updated, the rest are frozen boundary values

    Returns
    -------
    (u, v) : new float64 arrays
    """
    u, v, sigma, inside, gamma_map = check_fields(u, v, sigma, inside, gamma_map)
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
        raise ValueError(f"steps must be an integer >= 0; got {steps!r}")
    p = resolve_params(sigma, params)
    stepper = Stepper(sigma, inside, gamma_map, p)
    w = stepper.new_state(u, v)
    with PARALLEL_LOCK:            # numba's workqueue layer aborts on concurrent parallel launches
        stepper.run(w, steps, box)
    return w[0], w[1]
