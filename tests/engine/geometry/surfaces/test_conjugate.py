"""The discrete conjugate against closed forms: a helicoid piece conjugates to
a catenoid piece (C + iH is holomorphic in u + iv for
C = (cosh v cos u, cosh v sin u, v), H = (sinh v sin u, -sinh v cos u, u))."""

import math

import numpy as np
import pytest

from engine.geometry.surfaces.conjugate import conjugate_surface, midpoint_mesh
from engine.geometry.surfaces.curvature import face_areas
from engine.geometry.surfaces.plateau import solve_plateau

U, V = math.pi / 2, 1.0


def helicoid(u, v):
    return np.stack([np.sinh(v) * np.sin(u), -np.sinh(v) * np.cos(u), u + 0 * v], axis=-1)


def catenoid(u, v):
    return np.stack([np.cosh(v) * np.cos(u), np.cosh(v) * np.sin(u), v + 0 * u], axis=-1)


def _boundary_params(n):
    """(u, v) around the rectangle: helix, ruling, helix, ruling; rulings
    sampled evenly in arc length (sinh v), helices evenly in u."""
    s = np.arange(n) / n
    ruling = np.arcsinh(np.sinh(-V) + 2 * np.sinh(V) * s)
    u = np.concatenate([U * s, np.full(n, U), U * (1 - s), np.zeros(n)])
    v = np.concatenate([np.full(n, -V), ruling, np.full(n, V), -ruling])
    return u, v


def _kabsch(a, b):
    """Rotation R and shift t with R a + t ~ b."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1, 1, d]) @ u.T
    return r, cb - r @ ca


def _case(n):
    u, v = _boundary_params(n)
    pts = helicoid(u, v)
    longest = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1).max()
    surf = solve_plateau(pts, edge_length=1.001 * longest, tol=1e-9, max_iter=300)
    src = np.asarray(surf.source)
    assert np.array_equal(src, np.arange(pts.shape[0]))       # no extra boundary points
    return surf, catenoid(u, v)


def _errors(surf, target):
    """Conjugate vs catenoid after a rigid fit on the boundary: boundary and
    interior errors, the fitted rotation angle, and the better sign."""
    best = None
    for sign in (1, -1):
        conj = conjugate_surface(surf.vertices, surf.faces, sign=sign)
        r, t = _kabsch(conj.vertices[surf.boundary], target)
        w = conj.vertices @ r.T + t
        err_b = np.linalg.norm(w[surf.boundary] - target, axis=1).max()
        radial = np.hypot(w[:, 0], w[:, 1])
        err_i = np.max(np.abs(radial - np.cosh(w[:, 2])) / np.cosh(w[:, 2]))
        angle = math.degrees(math.acos(np.clip((np.trace(r) - 1) / 2, -1, 1)))
        if best is None or err_b < best[0]:
            best = (err_b, err_i, angle, sign, conj)
    return best


@pytest.fixture(scope="module")
def cases():
    return [_case(n) for n in (10, 20)]


def test_helicoid_conjugates_to_catenoid_with_second_order_error(cases):
    (coarse, t1), (fine, t2) = cases
    e1, i1, a1, s1, _ = _errors(coarse, t1)
    e2, i2, a2, s2, _ = _errors(fine, t2)
    assert s1 == s2
    assert e2 < 2e-3 and i2 < 2e-3
    # Halving h divides the errors by about 4.
    assert e1 / e2 > 2.8 and i1 / i2 > 2.8
    # Same frame: the best rigid fit is a pure translation (Prop. 4.1a, the
    # conjugate keeps the normals, so it is not turned).
    assert a2 < 0.05


def _cos(a, b):
    return np.einsum("ij,ij->i", a, b) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)


def test_normals_are_preserved(cases):
    worst = []
    for surf, _ in cases:
        conj = conjugate_surface(surf.vertices, surf.faces, sign=-1)
        v = surf.vertices[surf.faces]
        n_orig = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        # Exactly on the midpoint triangles...
        m = conj.midpoints[conj.face_edges]
        assert _cos(np.cross(m[:, 1] - m[:, 0], m[:, 2] - m[:, 0]), n_orig).min() > 1 - 1e-9
        # ... and up to the discretisation on the vertex mesh.
        w = conj.vertices[surf.faces]
        cos_w = _cos(np.cross(w[:, 1] - w[:, 0], w[:, 2] - w[:, 0]), n_orig)
        worst.append(np.degrees(np.arccos(cos_w.min())))
    assert worst[1] < 4.0 and worst[0] / worst[1] > 1.5


def test_isometry_on_midpoints_and_vertices(cases):
    rel = []
    for surf, _ in cases:
        conj = conjugate_surface(surf.vertices, surf.faces, sign=-1)
        mid = 0.5 * (surf.vertices[conj.edges[:, 0]] + surf.vertices[conj.edges[:, 1]])
        for k in range(3):
            a, b = conj.face_edges[:, k], conj.face_edges[:, (k + 1) % 3]
            d0 = np.linalg.norm(mid[a] - mid[b], axis=1)
            d1 = np.linalg.norm(conj.midpoints[a] - conj.midpoints[b], axis=1)
            assert np.max(np.abs(d1 - d0)) <= 2 * conj.closure_error + 1e-12
        e = conj.edges
        l0 = np.linalg.norm(surf.vertices[e[:, 0]] - surf.vertices[e[:, 1]], axis=1)
        l1 = np.linalg.norm(conj.vertices[e[:, 0]] - conj.vertices[e[:, 1]], axis=1)
        rel.append(np.sqrt(np.mean(((l1 - l0) / l0) ** 2)))
        # Areas agree (each conjugate triangle is the original turned).
        a0 = face_areas(surf.vertices, surf.faces).sum()
        a1 = face_areas(conj.vertices, surf.faces).sum()
        assert abs(a1 / a0 - 1) < 5e-3
    assert rel[1] < 0.02 and rel[0] / rel[1] > 1.8


def test_closure_error_measures_harmonicity(cases):
    surf, _ = cases[1]
    good = conjugate_surface(surf.vertices, surf.faces)
    assert good.closure_error < 1e-4
    v = np.array(surf.vertices)
    interior = np.setdiff1d(np.arange(v.shape[0]), surf.boundary)
    v[interior] += 0.02 * np.random.default_rng(0).standard_normal((interior.size, 3))
    bad = conjugate_surface(v, surf.faces)
    assert bad.closure_error > 50 * good.closure_error


def test_signs_are_point_reflections_and_outputs_are_read_only(cases):
    surf, _ = cases[0]
    plus = conjugate_surface(surf.vertices, surf.faces, sign=1)
    minus = conjugate_surface(surf.vertices, surf.faces, sign=-1)
    assert np.allclose(plus.vertices, -minus.vertices, atol=1e-12)
    assert np.allclose(plus.vertices.mean(axis=0), 0, atol=1e-12)
    assert not plus.vertices.flags.writeable
    verts, faces = midpoint_mesh(plus)
    assert verts.shape == (plus.edges.shape[0], 3) and faces.shape == surf.faces.shape
    with pytest.raises(ValueError, match="sign must be 1 or -1"):
        conjugate_surface(surf.vertices, surf.faces, sign=0)


def test_cached_connectivity_gives_identical_bytes(cases):
    import engine.geometry.surfaces.conjugate as conjugate

    surf, _ = cases[0]
    conjugate._GRAPHS.clear()
    first = conjugate_surface(surf.vertices, surf.faces)
    assert len(conjugate._GRAPHS) == 1
    again = conjugate_surface(surf.vertices, surf.faces)
    assert first.vertices.tobytes() == again.vertices.tobytes()
    assert first.midpoints.tobytes() == again.midpoints.tobytes()
