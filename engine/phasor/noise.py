"""Reference CPU evaluation (float64) of the two complex phasor noises.

Implements THE FORMULAS of :mod:`engine.phasor.kernels` exactly: the
truncated Gaussian kernels of eq. 2 and the filtered kernels of eqs. 14-16.
Every other evaluator (the GLSL shader) is checked against this one.

Each point visits only the grid cells within the cut-off radius (the loop
a shader runs), so the cost is O(points x sites in reach), not
O(points x sites).  The loop is compiled with numba and works through the
points in ~40 ms chunks between progress calls; per-point filter parameters
and accumulators exist per chunk only, so a 1024 x 1024 slice needs its
outputs (~50 MB, ~150 MB with gradients) and little else.
:func:`phasor_complex_reference` is the plain-numpy brute-force twin used to
check it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from numba import njit

from engine.progress import run_chunked
from .fields import PhasorFields, trilinear
from .kernels import PhasorKernels
from .sampling import local_frame

TWO_PI = 2.0 * math.pi
DEFAULT_FILTER_SCALE = 2.0


# --------------------------------------------------------------- parameters

@dataclass(frozen=True)
class _Kernel:
    """Constants of the kernels actually summed (raw or filtered)."""
    beta: float        # Gaussian coefficient of the summed kernels, mm^-2
    cutoff: float      # truncation radius, mm
    filtered: bool
    shrink: float = 0.0     # b / (a + b)
    penalty: float = 0.0    # pi^2 / (a + b)


def kernel_constants(kernels: PhasorKernels, *, filtered=False, filter_scale=DEFAULT_FILTER_SCALE) -> _Kernel:
    """Gaussian coefficient, cut-off radius and filter constants (kernels.py docstring)."""
    b = kernels.bandwidth
    if not filtered:
        return _Kernel(beta=b, cutoff=kernels.radius, filtered=False)
    s = float(filter_scale)
    if not (math.isfinite(s) and s > 0):
        raise ValueError(f"filter_scale: expected a positive filter radius in kernel radii, got {filter_scale!r}")
    a = b / s ** 2
    cutoff = math.sqrt((a + b) / (a * b)) * math.sqrt(b) * kernels.radius
    return _Kernel(beta=a * b / (a + b), cutoff=cutoff, filtered=True, shrink=b / (a + b),
                   penalty=math.pi ** 2 / (a + b))


def local_oscillators(fields: PhasorFields, points) -> tuple:
    """F(x) (n,) cycles/mm and the unperturbed directions e_v, e_w (n, 3) at ``points`` (n, 3)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    e_v, e_w = local_frame(fields.sample_direction(pts))
    return fields.sample_frequency(pts), e_v, e_w


def attenuation_at(attenuation, fields: PhasorFields, points) -> np.ndarray:
    """A(x) (n,) from ``None`` (A = 1), a number, a grid on the fields' cells
    (nz, ny, nx) sampled trilinearly, or one value per point (n,)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if attenuation is None:
        return np.ones(len(pts))
    a = np.asarray(attenuation, dtype=np.float64)
    if a.ndim == 0:
        out = np.full(len(pts), float(a))
    elif a.shape == fields.shape:
        if np.all(np.isfinite(a)) and a.min() >= 0.0 and a.max() <= 1.0:
            # a valid grid stays valid: trilinear weights may round a hair outside [0, 1]
            out = np.clip(trilinear(a, fields.lo, fields.hi, pts), 0.0, 1.0)
        else:
            out = trilinear(a, fields.lo, fields.hi, pts)
    elif a.shape == (len(pts),):
        out = a.copy()
    else:
        raise ValueError(f"attenuation: expected None, a number, a {fields.shape} grid or one value per point "
                         f"({len(pts)},), got shape {a.shape}")
    if not np.all(np.isfinite(out)) or out.min() < 0.0 or out.max() > 1.0:
        raise ValueError(f"attenuation A must lie in [0, 1]; got values in [{out.min():.3g}, {out.max():.3g}]")
    return out


# ------------------------------------------------------------------ results

class PhasorSample(NamedTuple):
    """Both noises and their spatial gradients at n points.

    g_v, g_w : (n,) complex128
    grad_v, grad_w : (n, 3) complex128, d G / d x (mm^-1), or None
    envelope_v, envelope_w : (n,) float64, sum of the kernel magnitudes
        (|G| <= envelope; |G| << envelope means G is near a zero)
    """
    g_v: np.ndarray
    g_w: np.ndarray
    grad_v: np.ndarray | None
    grad_w: np.ndarray | None
    envelope_v: np.ndarray
    envelope_w: np.ndarray


# ------------------------------------------------------------ kernel sums

@njit(nogil=True, cache=True)
def _sum_kernels(points, origin, radius, grid, cell_start, positions, fvec, phases,
                 beta, cutoff, filtered, shrink, penalty, q, amp_a, with_grad,
                 g_re, g_im, env, grad_re, grad_im):  # pragma: no cover - compiled
    """Accumulate both noises at ``points`` (m, 3) from the sites in reach.

    fvec : (n, 2, 3) f_j d_kj; phases : (n, 2); q : (m, 2, 3); amp_a : (m,);
    outputs g_re, g_im, env : (m, 2); grad_re, grad_im : (m, 2, 3).
    """
    gx, gy, gz = grid[0], grid[1], grid[2]
    cut2 = cutoff * cutoff
    two_pi = 2.0 * np.pi
    for p in range(points.shape[0]):
        x, y, z = points[p, 0], points[p, 1], points[p, 2]
        c0x = max(int(np.floor((x - cutoff - origin[0]) / radius)), 0)
        c1x = min(int(np.floor((x + cutoff - origin[0]) / radius)), gx - 1)
        c0y = max(int(np.floor((y - cutoff - origin[1]) / radius)), 0)
        c1y = min(int(np.floor((y + cutoff - origin[1]) / radius)), gy - 1)
        c0z = max(int(np.floor((z - cutoff - origin[2]) / radius)), 0)
        c1z = min(int(np.floor((z + cutoff - origin[2]) / radius)), gz - 1)
        if c1x < c0x:
            continue
        for cz in range(c0z, c1z + 1):
            for cy in range(c0y, c1y + 1):
                row = gx * (cy + gy * cz)
                for s in range(cell_start[row + c0x], cell_start[row + c1x + 1]):
                    rx = x - positions[s, 0]
                    ry = y - positions[s, 1]
                    rz = z - positions[s, 2]
                    r2 = rx * rx + ry * ry + rz * rz
                    if r2 >= cut2:
                        continue
                    for k in range(2):
                        kx, ky, kz = fvec[s, k, 0], fvec[s, k, 1], fvec[s, k, 2]
                        if filtered:
                            dx = amp_a[p] * (kx - q[p, k, 0])
                            dy = amp_a[p] * (ky - q[p, k, 1])
                            dz = amp_a[p] * (kz - q[p, k, 2])
                            amp = np.exp(-beta * r2 - penalty * (dx * dx + dy * dy + dz * dz))
                            kx -= shrink * dx
                            ky -= shrink * dy
                            kz -= shrink * dz
                        else:
                            amp = np.exp(-beta * r2)
                        theta = two_pi * (kx * rx + ky * ry + kz * rz) + phases[s, k]
                        c = amp * np.cos(theta)
                        sn = amp * np.sin(theta)
                        g_re[p, k] += c
                        g_im[p, k] += sn
                        env[p, k] += amp
                        if with_grad:
                            # d/dx of amp e^{i theta} = (-2 beta r + 2 pi i k') amp e^{i theta}
                            grad_re[p, k, 0] += -2.0 * beta * rx * c - two_pi * kx * sn
                            grad_re[p, k, 1] += -2.0 * beta * ry * c - two_pi * ky * sn
                            grad_re[p, k, 2] += -2.0 * beta * rz * c - two_pi * kz * sn
                            grad_im[p, k, 0] += -2.0 * beta * rx * sn + two_pi * kx * c
                            grad_im[p, k, 1] += -2.0 * beta * ry * sn + two_pi * ky * c
                            grad_im[p, k, 2] += -2.0 * beta * rz * sn + two_pi * kz * c


def _evaluate(kernels, points, consts, fields, attenuation, with_grad, progress):
    """(g (m, 2) complex, grad (m, 2, 3) complex or None, env (m, 2)); the
    per-point filter parameters and the float accumulators live per chunk."""
    m = len(points)
    g = np.zeros((m, 2), np.complex128)
    env = np.zeros((m, 2))
    grad = np.zeros((m, 2, 3), np.complex128) if with_grad else None
    fvec = np.ascontiguousarray(kernels.frequency[:, None, None]
                                * np.stack([kernels.direction_v, kernels.direction_w], axis=1))
    phases = np.ascontiguousarray(np.stack([kernels.phase_v, kernels.phase_w], axis=1))
    per_point = attenuation is not None and np.ndim(attenuation) == 1
    if consts.filtered:
        attenuation_at(attenuation if not per_point else attenuation[:1], fields, points[:1])  # fail early

    def work(a, b):
        pts = points[a:b]
        n = b - a
        if consts.filtered:
            f, e_v, e_w = local_oscillators(fields, pts)
            q = np.ascontiguousarray(np.stack([f[:, None] * e_v, f[:, None] * e_w], axis=1))
            amp_a = attenuation_at(attenuation[a:b] if per_point else attenuation, fields, pts)
        else:
            q, amp_a = np.zeros((1, 2, 3)), np.ones(1)  # not read
        g_re, g_im, e = np.zeros((n, 2)), np.zeros((n, 2)), np.zeros((n, 2))
        gr = np.zeros((n, 2, 3) if with_grad else (1, 2, 3))
        gi = np.zeros_like(gr)
        _sum_kernels(pts, kernels.origin, float(kernels.radius), kernels.grid, kernels.cell_start,
                     kernels.positions, fvec, phases, consts.beta, consts.cutoff, consts.filtered,
                     consts.shrink, consts.penalty, q, amp_a, with_grad, g_re, g_im, e, gr, gi)
        g[a:b].real, g[a:b].imag, env[a:b] = g_re, g_im, e
        if with_grad:
            grad[a:b].real, grad[a:b].imag = gr, gi

    run_chunked(work, m, progress, first_chunk=256)
    return g, grad, env


def _as_points(points) -> tuple:
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim < 1 or pts.shape[-1] != 3 or not np.all(np.isfinite(pts)):
        raise ValueError(f"points: expected finite (..., 3) coordinates in mm, got shape {pts.shape}")
    return pts.reshape(-1, 3), pts.shape[:-1]


def phasor_sample(kernels: PhasorKernels, points, *, fields: PhasorFields | None = None, filtered=False,
                  filter_scale=DEFAULT_FILTER_SCALE, attenuation=None, gradient=False,
                  progress=None) -> PhasorSample:
    """G_v, G_w (and optionally their gradients) at ``points`` (n, 3) mm.

    See :func:`phasor_complex` for the parameters; ``gradient=True`` also
    returns dG/dx.  For filtered kernels the gradient is that of the local
    filtered field around x (filter parameters q(x), A(x) held at x), i.e.
    of ``(g * phi_x)(delta)`` times the carrier, at delta = 0.
    """
    pts, _ = _as_points(points)
    consts = kernel_constants(kernels, filtered=filtered, filter_scale=filter_scale)
    if filtered and fields is None:
        raise ValueError("fields: the filtered noise needs the control fields (F and D at each point)")
    if attenuation is not None and np.ndim(attenuation) == 1 and len(attenuation) != len(pts):
        raise ValueError(f"attenuation: expected one value per point ({len(pts)},), got {np.shape(attenuation)}")
    g, grad, env = _evaluate(kernels, np.ascontiguousarray(pts), consts, fields, attenuation, gradient, progress)
    gv, gw = (None, None) if grad is None else (grad[:, 0], grad[:, 1])
    return PhasorSample(g[:, 0], g[:, 1], gv, gw, env[:, 0], env[:, 1])


def phasor_complex(kernels: PhasorKernels, points, *, fields: PhasorFields | None = None, filtered=False,
                   filter_scale=DEFAULT_FILTER_SCALE, attenuation=None, progress=None) -> tuple:
    """The complex noises G_v, G_w at ``points``.

    Parameters
    ----------
    kernels : PhasorKernels
    points : (..., 3) float64, mm
    fields : PhasorFields, needed when ``filtered`` (F and D at each point)
    filtered : bool, use the filtered kernels of eq. 14
    filter_scale : float, filter radius in kernel radii (s; a = b / s^2)
    attenuation : None (A = 1), a number, an (nz, ny, nx) grid on the
        fields' cells (e.g. :func:`engine.phasor.attenuation.attenuation_grid`)
        or (n,) values; only used when ``filtered``
    progress : callable(done, total) -> bool, or None; False cancels

    Returns
    -------
    G_v, G_w : complex128 arrays of the points' leading shape
    """
    _, lead = _as_points(points)
    s = phasor_sample(kernels, points, fields=fields, filtered=filtered, filter_scale=filter_scale,
                      attenuation=attenuation, progress=progress)
    return s.g_v.reshape(lead), s.g_w.reshape(lead)


def phasor_complex_reference(kernels: PhasorKernels, points, *, fields: PhasorFields | None = None,
                             filtered=False, filter_scale=DEFAULT_FILTER_SCALE, attenuation=None) -> tuple:
    """Slow, obviously correct twin of :func:`phasor_complex`: every site
    against every point, no cell lookup.  For tests on small inputs."""
    pts, lead = _as_points(points)
    if filtered and fields is None:
        raise ValueError("fields: the filtered noise needs the control fields (F and D at each point)")
    b = kernels.bandwidth
    a = b / filter_scale ** 2
    if filtered:
        f, e_v, e_w = local_oscillators(fields, pts)
        amp_a = attenuation_at(attenuation, fields, pts)
        radius = math.sqrt((a + b) / (a * b)) * math.sqrt(b) * kernels.radius
    else:
        radius = kernels.radius
    result = []
    for direction, phase, e in ((kernels.direction_v, kernels.phase_v, None if not filtered else e_v),
                                (kernels.direction_w, kernels.phase_w, None if not filtered else e_w)):
        g = np.zeros(len(pts), np.complex128)
        for j in range(kernels.n):
            r = pts - kernels.positions[j]
            dist2 = np.sum(r * r, axis=1)
            fd = kernels.frequency[j] * direction[j]
            if filtered:
                delta = amp_a[:, None] * (fd - f[:, None] * e)
                term = (np.exp(-(a * b / (a + b)) * dist2 - math.pi ** 2 * np.sum(delta ** 2, axis=1) / (a + b))
                        * np.exp(1j * (2 * math.pi * np.sum((fd - (b / (a + b)) * delta) * r, axis=1)
                                       + phase[j])))
            else:
                term = np.exp(-b * dist2) * np.exp(1j * (2 * math.pi * (r @ fd) + phase[j]))
            g += np.where(dist2 < radius ** 2, term, 0.0)
        result.append(g.reshape(lead))
    return tuple(result)


# ---------------------------------------------------------------- sawtooth

def sawtooth(g) -> np.ndarray:
    """p = (Arg G / 2 pi) mod 1, float64 in [0, 1) (G = 0 gives 0)."""
    p = np.mod(np.angle(np.asarray(g)) / TWO_PI, 1.0)
    # mod of a tiny negative number rounds to exactly 1.0
    return np.where(p >= 1.0, 0.0, p)


def diamond_mask(p_v, p_w) -> np.ndarray:
    """True inside black diamond cells: ``|1/2 - p_v| + |1/2 - p_w| < 1/2``."""
    return np.abs(0.5 - np.asarray(p_v)) + np.abs(0.5 - np.asarray(p_w)) < 0.5


# ------------------------------------------------------------------ slices

@dataclass(frozen=True, eq=False)
class SliceGrid:
    """A rectangular pixel grid on a plane (same convention as engine.gpu's SlicePlane).

    Pixel ``[row i, column j]`` has its centre at
    ``origin + (j + 0.5) * pixel_u + (i + 0.5) * pixel_v``.

    origin : (3,) mm, outer corner of pixel [0, 0]
    pixel_u, pixel_v : (3,) mm, steps between columns / rows (orthogonal)
    shape : (H, W)
    """
    origin: np.ndarray
    pixel_u: np.ndarray
    pixel_v: np.ndarray
    shape: tuple

    @classmethod
    def axis_aligned(cls, axis, position, pixel_size, extent) -> "SliceGrid":
        """Slice normal to ``axis`` (0/1/2 or 'x'/'y'/'z') at ``position`` mm.

        Columns and rows run along (y, z) for x, (x, z) for y, (x, y) for z;
        ``extent = ((u0, u1), (v0, v1))`` mm; pixel counts are
        ``round(length / pixel_size)`` (at least 1).
        """
        a = {"x": 0, "y": 1, "z": 2}.get(axis, axis)
        if a not in (0, 1, 2):
            raise ValueError(f"axis: expected 'x', 'y', 'z' or 0, 1, 2, got {axis!r}")
        if not (pixel_size > 0):
            raise ValueError(f"pixel_size: expected a positive length in mm, got {pixel_size!r}")
        ext = np.asarray(extent, dtype=np.float64)
        if ext.shape != (2, 2) or np.any(ext[:, 1] <= ext[:, 0]):
            raise ValueError(f"extent: expected ((u0, u1), (v0, v1)) with u1 > u0, v1 > v0, got {extent!r}")
        iu, iv = {0: (1, 2), 1: (0, 2), 2: (0, 1)}[a]
        res = np.maximum(1, np.round((ext[:, 1] - ext[:, 0]) / pixel_size)).astype(int)
        origin = np.zeros(3)
        origin[a], origin[iu], origin[iv] = position, ext[0, 0], ext[1, 0]
        eye = np.eye(3) * float(pixel_size)
        return cls(origin, eye[iu], eye[iv], (int(res[1]), int(res[0])))

    @classmethod
    def through(cls, origin, u_axis, v_axis, size, resolution) -> "SliceGrid":
        """Arbitrary plane: ``size`` (width, height) mm along the orthogonal
        ``u_axis``, ``v_axis``, ``resolution`` (W, H) pixels."""
        u = np.asarray(u_axis, np.float64)
        v = np.asarray(v_axis, np.float64)
        u, v = u / np.linalg.norm(u), v / np.linalg.norm(v)
        if abs(float(u @ v)) > 1e-6:
            raise ValueError(f"u_axis, v_axis: expected orthogonal in-plane axes, u.v = {float(u @ v):.3g}")
        (w_mm, h_mm), (w, h) = size, resolution
        if w < 1 or h < 1 or w_mm <= 0 or h_mm <= 0:
            raise ValueError(f"size/resolution: expected positive, got {size!r}, {resolution!r}")
        return cls(np.asarray(origin, np.float64), u * (w_mm / w), v * (h_mm / h), (int(h), int(w)))

    @property
    def normal(self) -> np.ndarray:
        n = np.cross(self.pixel_u, self.pixel_v)
        return n / np.linalg.norm(n)

    def points(self) -> np.ndarray:
        """(H, W, 3) pixel centres, mm."""
        h, w = self.shape
        return (np.asarray(self.origin) + (np.arange(w)[None, :, None] + 0.5) * np.asarray(self.pixel_u)
                + (np.arange(h)[:, None, None] + 0.5) * np.asarray(self.pixel_v))


def slice_points(plane) -> np.ndarray:
    """(H * W, 3) pixel centres of ``plane`` (a SliceGrid or engine.gpu SlicePlane), row-major."""
    return np.asarray(plane.points(), dtype=np.float64).reshape(-1, 3)


def phasor_slice(kernels: PhasorKernels, plane, **options) -> tuple:
    """Sawtooth images ``(p_v, p_w)``, float64 (H, W), of ``plane``.

    ``options`` are those of :func:`phasor_complex`.
    """
    g_v, g_w = phasor_complex(kernels, slice_points(plane), **options)
    return sawtooth(g_v).reshape(plane.shape), sawtooth(g_w).reshape(plane.shape)
