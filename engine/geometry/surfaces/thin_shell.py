"""Direct surfaces: a thin shell stretched over a fixed boundary (paper
section 5.1.2).

The rest shape is a flat disc mesh much smaller than the boundary, with the
connectivity of the deformed mesh. Its boundary is pinned to the target loop
and the interior minimises

    E(x) = E_inplane(x) + alpha * E_bend(x)

* ``E_inplane``: an as-rigid-as-possible membrane energy,
  ``sum_t A_t |F_t - R_t|^2`` with ``F_t`` the 3x2 deformation gradient of
  triangle t from its rest shape and ``R_t`` the nearest matrix with
  orthonormal columns, divided by ``A_rest * s0^2`` (``s0`` the nominal
  stretch, boundary radius / rest radius) so that it is dimensionless and of
  order one whatever the rest size.
* ``E_bend``: the discrete-shell hinge energy
  ``sum_e 3 |e|^2 / (A_1 + A_2) * theta_e^2`` over interior edges (rest
  lengths and areas; the rest dihedral angles are zero), scale free.

Because the rest disc is small the membrane is stretched everywhere, so with
little bending weight it behaves like a soap film and approximates a minimal
surface; more bending weight gives smoother, fuller patches. The minimiser is
scipy's L-BFGS over the interior vertex positions with analytic gradients.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.linalg import cholesky, solve_triangular
from scipy.optimize import minimize

from engine.progress import report
from .boundary import BoundaryLoop, sample_loop
from .curvature import cotan_laplacian, mixed_areas
from .mesh_init import _interior_edges, disc_mesh

__all__ = ["ThinShellSurface", "ShellModel", "shell_model", "shell_energy", "solve_thin_shell"]

DEFAULT_ALPHA = 0.1
DEFAULT_REST_SCALE = 0.25
DEFAULT_PIECES_PER_PERIMETER = 40

# Largest number of free coordinates (3 per interior vertex) for which the
# minimiser is preconditioned by a dense Cholesky factor (memory ~ 8 n^2
# bytes); beyond it, by the diagonal only.
DENSE_PRECONDITIONER_LIMIT = 6000


@dataclass(frozen=True)
class ShellModel:
    """Rest-state quantities of a shell (all from the flat rest mesh).

    Attributes
    ----------
    faces : (m, 3) int64
    rest_inverse : (m, 2, 2) float64
        Inverse of each triangle's rest edge matrix ``[X1 - X0, X2 - X0]``.
    rest_area : (m,) float64
    inplane_scale : float
        Divisor making the membrane term dimensionless.
    hinge : (k, 4) int64
        Interior edges as ``(p, q, r, s)``: edge ``p q``, wing ``r`` of the
        face ``(p, q, r)``, wing ``s`` of ``(q, p, s)``.
    hinge_weight : (k,) float64
        ``3 |e|^2 / (A_1 + A_2)`` at rest.
    """

    faces: np.ndarray
    rest_inverse: np.ndarray
    rest_area: np.ndarray
    inplane_scale: float
    hinge: np.ndarray
    hinge_weight: np.ndarray


@dataclass(frozen=True)
class ThinShellSurface:
    """Result of :func:`solve_thin_shell`.

    Attributes
    ----------
    vertices : (n, 3) float64, read-only
        Boundary first, in loop order; boundary rows equal the sampled input.
    faces : (m, 3) int64, read-only
    boundary : (b,) int64, read-only
    rest_uv : (n, 2) float64, read-only
        Rest positions (model units), a disc of radius ``rest_radius``.
    energy_history : (k,) float64, read-only
        Total energy at the start and after every L-BFGS iteration.
    inplane_energy, bend_energy : float
        Final terms (the total is ``inplane + alpha * bend``).
    iterations : int
    converged : bool
    alpha : float
    """

    vertices: np.ndarray
    faces: np.ndarray
    boundary: np.ndarray
    rest_uv: np.ndarray
    energy_history: np.ndarray
    inplane_energy: float
    bend_energy: float
    iterations: int
    converged: bool
    alpha: float


def _hinges(faces, n):
    a, b, _, h1, h2 = _interior_edges(faces, n)
    opposite = faces.T.ravel()
    return np.column_stack([a[h1], b[h1], opposite[h1], opposite[h2]])


def shell_model(rest_uv, faces, *, stretch):
    """Precompute the rest-state quantities of a flat shell.

    Parameters
    ----------
    rest_uv : (n, 2) float64
        Flat rest positions; faces counter-clockwise.
    faces : (m, 3) int64
    stretch : float
        Nominal stretch ``s0`` (> 0) used to normalise the membrane term.

    Returns
    -------
    ShellModel
    """
    p = rest_uv[faces]
    dm = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=2)          # (m, 2, 2)
    det = dm[:, 0, 0] * dm[:, 1, 1] - dm[:, 0, 1] * dm[:, 1, 0]
    if np.any(det <= 0.0):
        t = int(np.flatnonzero(det <= 0.0)[0])
        raise ValueError(f"rest triangle {t} is degenerate or clockwise (signed area {det[t] / 2:.3g})")
    area = 0.5 * det
    hinge = _hinges(faces, rest_uv.shape[0])
    e2 = np.sum((rest_uv[hinge[:, 1]] - rest_uv[hinge[:, 0]]) ** 2, axis=1)
    tri_area = _hinge_face_areas(rest_uv, hinge)
    return ShellModel(faces=faces, rest_inverse=np.linalg.inv(dm), rest_area=area,
                      inplane_scale=float(area.sum()) * stretch ** 2, hinge=hinge,
                      hinge_weight=3.0 * e2 / tri_area)


def _hinge_face_areas(uv, hinge):
    def tri(a, b, c):
        u, w = uv[b] - uv[a], uv[c] - uv[a]
        return 0.5 * np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])
    p, q, r, s = hinge.T
    return tri(p, q, r) + tri(q, p, s)


def _nearest_orthonormal(f):
    """Polar factor of each 3x2 matrix: ``F (F^T F)^(-1/2)``."""
    c = np.einsum("tki,tkj->tij", f, f)                                    # (m, 2, 2)
    det = np.maximum(c[:, 0, 0] * c[:, 1, 1] - c[:, 0, 1] * c[:, 1, 0], 0.0)
    root_det = np.sqrt(det)
    # Square root of a 2x2 SPD matrix: (C + sqrt(det) I) / sqrt(tr + 2 sqrt(det)).
    s = c.copy()
    s[:, 0, 0] += root_det
    s[:, 1, 1] += root_det
    s /= np.sqrt(np.maximum(c[:, 0, 0] + c[:, 1, 1] + 2.0 * root_det, 1e-300))[:, None, None]
    s_det = s[:, 0, 0] * s[:, 1, 1] - s[:, 0, 1] * s[:, 1, 0]
    s_inv = np.empty_like(s)
    s_inv[:, 0, 0], s_inv[:, 1, 1] = s[:, 1, 1], s[:, 0, 0]
    s_inv[:, 0, 1], s_inv[:, 1, 0] = -s[:, 0, 1], -s[:, 1, 0]
    s_inv /= np.maximum(s_det, 1e-300)[:, None, None]
    return np.einsum("tij,tjk->tik", f, s_inv)


def _inplane(x, model):
    f_idx = model.faces
    p = x[f_idx]
    edges = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=2)       # (m, 3, 2)
    f = np.einsum("tij,tjk->tik", edges, model.rest_inverse)
    diff = f - _nearest_orthonormal(f)
    w = model.rest_area / model.inplane_scale
    energy = float(np.sum(w * np.sum(diff ** 2, axis=(1, 2))))
    # dE/dF = 2 w (F - R) (R is the minimiser, so it does not contribute).
    g_edges = np.einsum("tik,tjk->tij", 2.0 * w[:, None, None] * diff, model.rest_inverse)
    grad = np.zeros_like(x)
    np.add.at(grad, f_idx[:, 1], g_edges[:, :, 0])
    np.add.at(grad, f_idx[:, 2], g_edges[:, :, 1])
    np.add.at(grad, f_idx[:, 0], -g_edges[:, :, 0] - g_edges[:, :, 1])
    return energy, grad


def _bend(x, model):
    p, q, r, s = (x[model.hinge[:, k]] for k in range(4))
    e = q - p
    n1 = np.cross(e, r - p)                      # face (p, q, r)
    n2 = np.cross(-e, s - q)                     # face (q, p, s)
    e_len = np.linalg.norm(e, axis=1)
    n1_sq = np.maximum(np.einsum("ij,ij->i", n1, n1), 1e-300)
    n2_sq = np.maximum(np.einsum("ij,ij->i", n2, n2), 1e-300)
    sin = np.einsum("ij,ij->i", np.cross(n1, n2), e) / e_len
    cos = np.einsum("ij,ij->i", n1, n2)
    theta = np.arctan2(sin, cos)
    energy = float(np.sum(model.hinge_weight * theta ** 2))
    # Dihedral-angle gradient: a wing moving along its face normal turns the
    # face about the edge by (distance / height); the edge end points take
    # the opposite of the wings' gradients, split by where each wing's foot
    # falls on the edge (so the four sum to zero).
    g_r = -(e_len / n1_sq)[:, None] * n1
    g_s = -(e_len / n2_sq)[:, None] * n2
    e_sq = e_len ** 2
    a_r = np.einsum("ij,ij->i", r - p, e) / e_sq
    a_s = np.einsum("ij,ij->i", s - p, e) / e_sq
    g_p = -(1.0 - a_r)[:, None] * g_r - (1.0 - a_s)[:, None] * g_s
    g_q = -a_r[:, None] * g_r - a_s[:, None] * g_s
    coef = (2.0 * model.hinge_weight * theta)[:, None]
    grad = np.zeros_like(x)
    for k, g in enumerate((g_p, g_q, g_r, g_s)):
        np.add.at(grad, model.hinge[:, k], coef * g)
    return energy, grad


def shell_energy(vertices, model, *, alpha=DEFAULT_ALPHA):
    """Thin-shell energy and its gradient.

    Parameters
    ----------
    vertices : (n, 3) float64
        Deformed positions.
    model : ShellModel
    alpha : float
        Bending weight (>= 0).

    Returns
    -------
    (total float, inplane float, bend float, gradient (n, 3) float64)
    """
    e_in, g_in = _inplane(vertices, model)
    e_b, g_b = _bend(vertices, model)
    return e_in + alpha * e_b, e_in, e_b, g_in + alpha * g_b


def _preconditioner(rest_uv, faces, vertices, free, alpha, stretch):
    """Upper factor ``R`` (``R^T R = K``) of a quadratic model of the energy,
    over the interleaved coordinates ``(x0, y0, z0, x1, ...)`` of the free
    vertices.

    The membrane behaves like the Dirichlet energy of the rest mesh (all
    three coordinates) and the hinges, for small motion along the normals
    ``n_i`` of the start surface, like the squared Laplacian of ``n_i . x_i``;
    both are scaled by the nominal stretch. Minimising in ``y = R x`` makes
    the problem well conditioned for L-BFGS whatever the bending weight and
    mesh size (the bending part alone has condition number ~ (size / h)^4).
    Returns a dense matrix, or a 1-D diagonal above the size limit.
    """
    flat = np.column_stack([rest_uv, np.zeros(rest_uv.shape[0])])
    lap = cotan_laplacian(flat, faces).tocsc()
    mass = mixed_areas(flat, faces)
    membrane = (-lap / mass.sum()).tocsr()[free][:, free]
    bilap = (lap @ sp.diags(1.0 / mass) @ lap).tocsr()[free][:, free]
    normals = _vertex_normals(vertices, faces)[free]
    k = free.size
    pick = sp.csr_matrix((normals.ravel(), (np.repeat(np.arange(k), 3), np.arange(3 * k))),
                         shape=(k, 3 * k))
    model = sp.kron(membrane, sp.identity(3)) + alpha * (pick.T @ bilap @ pick)
    model = (2.0 / stretch ** 2) * model.tocsr()
    if 3 * k > DENSE_PRECONDITIONER_LIMIT:
        return np.sqrt(model.diagonal())
    return cholesky(model.toarray(), lower=False)


def _vertex_normals(vertices, faces):
    p = vertices[faces]
    face_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    out = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(out, faces[:, k], face_n)
    length = np.linalg.norm(out, axis=1, keepdims=True)
    return out / np.where(length > 0.0, length, 1.0)


def _check_options(alpha, rest_scale, tol, max_iter, edge_length):
    for name, value in (("alpha", alpha), ("tol", tol)):
        if not isinstance(value, (int, float, np.floating)) or not math.isfinite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0; got {value!r}")
    if not isinstance(rest_scale, (int, float, np.floating)) or not 0.0 < rest_scale <= 1.0:
        raise ValueError(f"rest_scale must be in (0, 1]; got {rest_scale!r}")
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be an integer >= 1; got {max_iter!r}")
    if edge_length is not None and not (math.isfinite(float(edge_length)) and float(edge_length) > 0):
        raise ValueError(f"edge_length must be a finite number > 0; got {edge_length!r}")


def _boundary_points(boundary, edge_length):
    if isinstance(boundary, BoundaryLoop):
        pts = boundary.points
        perimeter = float(np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1).sum())
        h = perimeter / DEFAULT_PIECES_PER_PERIMETER if edge_length is None else float(edge_length)
        return sample_loop(boundary, edge_length=h).points, None
    pts = np.asarray(boundary, dtype=np.float64)
    if edge_length is None and pts.ndim == 2 and pts.shape[0] >= 3 and pts.shape[1] == 3 \
            and np.all(np.isfinite(pts)):
        perimeter = float(np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1).sum())
        edge_length = perimeter / DEFAULT_PIECES_PER_PERIMETER
    return pts, edge_length


def solve_thin_shell(boundary, *, alpha=DEFAULT_ALPHA, edge_length=None,
                     rest_scale=DEFAULT_REST_SCALE, tol=1e-10, max_iter=2000, progress=None):
    """Direct surface: a stretched thin shell pinned to a fixed boundary.

    Parameters
    ----------
    boundary : BoundaryLoop or array_like (n, 3)
        A loop (straight segments stay straight, smooth runs are splined,
        sliding segments are held where given) or a closed polygon.
    alpha : float
        Bending weight (>= 0); larger is smoother.
    edge_length : float, optional
        Target edge length (model units); default the perimeter / 40.
    rest_scale : float
        Rest disc radius over the boundary's radius ``perimeter / (2 pi)``,
        in (0, 1].
    tol : float
        Relative energy decrease per iteration below which L-BFGS stops.
    max_iter : int
        L-BFGS iteration limit.
    progress : callable, optional
        ``progress(done, total) -> bool`` once per iteration; False cancels.

    Returns
    -------
    ThinShellSurface

    Raises
    ------
    ValueError
        Bad boundary (see :func:`~.boundary.boundary_loop` and
        :func:`~.mesh_init.disc_mesh`) or options.
    engine.progress.Cancelled
        The progress callback returned False.
    """
    _check_options(alpha, rest_scale, tol, max_iter, edge_length)
    pts, mesh_length = _boundary_points(boundary, edge_length)
    mesh = disc_mesh(pts, edge_length=mesh_length)
    b = mesh.boundary.size
    bpts = mesh.vertices[:b]
    perimeter = float(np.linalg.norm(np.roll(bpts, -1, axis=0) - bpts, axis=1).sum())
    rest_radius = rest_scale * perimeter / (2.0 * math.pi)
    rest = mesh.uv * rest_radius
    model = shell_model(rest, mesh.faces, stretch=1.0 / rest_scale)
    x = mesh.vertices.copy()
    free = np.arange(b, x.shape[0])
    factor = (_preconditioner(rest, mesh.faces, x, free, alpha, 1.0 / rest_scale)
              if free.size else None)
    dense = factor is not None and factor.ndim == 2

    def to_x(y):
        flat = solve_triangular(factor, y, lower=False, check_finite=False) if dense else y / factor
        return flat.reshape(-1, 3)

    def fun(y):
        x[b:] = to_x(y)
        total, _, _, grad = shell_energy(x, model, alpha=alpha)
        g = grad[b:].ravel()
        return total, (solve_triangular(factor, g, trans="T", lower=False, check_finite=False) if dense else g / factor)

    y0 = (factor @ x[b:].ravel() if dense else factor * x[b:].ravel()) if free.size else None
    history = [shell_energy(x, model, alpha=alpha)[0]]
    iterations = [0]

    def callback(intermediate_result):
        history.append(float(intermediate_result.fun))
        iterations[0] += 1
        report(progress, iterations[0], max_iter)

    report(progress, 0, max_iter)
    if x.shape[0] > b:
        res = minimize(fun, y0, jac=True, method="L-BFGS-B", callback=callback,
                       options={"maxiter": max_iter, "ftol": tol, "gtol": 1e-12, "maxcor": 20})
        x[b:] = to_x(res.x)
        converged = bool(res.success)
    else:
        converged = True
    _, e_in, e_b, _ = shell_energy(x, model, alpha=alpha)
    hist = np.asarray(history)
    for arr in (x, mesh.faces, mesh.boundary, rest, hist):
        arr.setflags(write=False)
    return ThinShellSurface(vertices=x, faces=mesh.faces, boundary=mesh.boundary, rest_uv=rest,
                            energy_history=hist,
                            inplane_energy=e_in, bend_energy=e_b, iterations=iterations[0],
                            converged=converged, alpha=float(alpha))
