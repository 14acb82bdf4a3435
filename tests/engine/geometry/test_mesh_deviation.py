"""`engine.geometry.mesh_deviation` against independent references.

The closest point on a triangle is checked against a dense sampling of the
triangle (barycentric grid, edges included) in every Voronoi region — the
three corners, the three edges and the face, above and below the plane —
and on degenerate triangles; the compiled loop against the numpy form; the
mesh deviation against a brute force over every triangle (also where the
nearest triangle's corners are far away), and against the closed form for a
plane shifted by a known amount.
"""

import numpy as np
import pytest

from engine.geometry.mesh_deviation import (_closest_distance, mesh_deviation,
                                            point_triangle_distance)


def _sampled_distance(p, a, b, c, n=400):
    """min over a fine barycentric grid of the triangle (edges and corners included)."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    u, v = i[keep] / n, j[keep] / n
    pts = a + np.outer(u, b - a) + np.outer(v, c - a)
    return np.linalg.norm(pts - p, axis=1).min(), 1.5 * np.linalg.norm([b - a, c - a], axis=1).max() / n


def _region_points(a, b, c, rng):
    """Points whose closest feature is each corner, each edge and the face, off the plane."""
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal)
    centre = (a + b + c) / 3
    out = []
    for corner in (a, b, c):                       # beyond each corner
        out.append(corner + 0.8 * (corner - centre) + 0.3 * normal)
    for u, v in ((a, b), (b, c), (c, a)):          # beyond each edge's midpoint
        mid = 0.5 * (u + v)
        out.append(mid + 0.7 * (mid - centre) - 0.2 * normal)
    out.append(centre + 0.5 * normal)              # above and below the face
    out.append(centre - 0.25 * normal)
    out += list(centre + rng.normal(scale=1.5, size=(30, 3)))
    return np.array(out)


TRIANGLES = [
    ((0, 0, 0), (1, 0, 0), (0, 1, 0)),
    ((0.2, -0.3, 0.5), (1.7, 0.4, -0.2), (-0.4, 1.1, 0.9)),
    ((0, 0, 0), (3, 0.1, 0), (1.5, 0.05, 0.02)),   # sliver: obtuse, nearly flat
]


@pytest.mark.parametrize("tri", TRIANGLES)
def test_the_closest_point_is_the_sampled_one_in_every_region(tri):
    a, b, c = (np.array(x, dtype=float) for x in tri)
    pts = _region_points(a, b, c, np.random.default_rng(3))
    n = len(pts)
    fast = point_triangle_distance(pts, np.tile(a, (n, 1)), np.tile(b, (n, 1)), np.tile(c, (n, 1)))
    for p, d in zip(pts, fast):
        want, tol = _sampled_distance(p, a, b, c)
        assert want - tol <= d <= want + 1e-12
        assert _closest_distance(p[0], p[1], p[2], a, b, c) == pytest.approx(d, abs=1e-12)


@pytest.mark.parametrize("tri", [((0, 0, 0), (1, 1, 1), (2, 2, 2)),     # collinear
                                 ((0, 0, 0), (1, 0, 0), (1, 0, 0)),     # two corners the same
                                 ((0.5, 0.5, 0.5),) * 3])               # a point
def test_a_degenerate_triangle_measures_to_its_segment_or_point(tri):
    a, b, c = (np.array(x, dtype=float) for x in tri)
    pts = np.random.default_rng(5).normal(size=(40, 3))
    n = len(pts)
    got = point_triangle_distance(pts, np.tile(a, (n, 1)), np.tile(b, (n, 1)), np.tile(c, (n, 1)))
    for p, d in zip(pts, got):
        want, tol = _sampled_distance(p, a, b, c, n=200)
        assert d == pytest.approx(want, abs=tol + 1e-12)
        assert _closest_distance(p[0], p[1], p[2], a, b, c) <= want + tol + 1e-12


def _wavy_sheet(n, amplitude, rng=None):
    """A height-field mesh z = amplitude * sin(x) cos(y) on [0, 4]^2 with n x n vertices."""
    x, y = np.meshgrid(np.linspace(0, 4, n), np.linspace(0, 4, n), indexing="ij")
    if rng is not None:                            # jitter in the plane: other triangles
        x = x + rng.uniform(-0.3, 0.3, x.shape) * (4 / n) * ((x > 0) & (x < 4))
        y = y + rng.uniform(-0.3, 0.3, y.shape) * (4 / n) * ((y > 0) & (y < 4))
    v = np.column_stack([x.ravel(), y.ravel(), amplitude * (np.sin(x) * np.cos(y)).ravel()])
    idx = np.arange(n * n).reshape(n, n)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return v, np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])


def _brute_one_way(points, v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    worst = 0.0
    for p in points:
        d = point_triangle_distance(np.tile(p, (len(f), 1)), a, b, c).min()
        worst = max(worst, d)
    return worst


def test_the_deviation_is_the_brute_force_one():
    va, fa = _wavy_sheet(30, 0.4)
    vb, fb = _wavy_sheet(13, 0.4, rng=np.random.default_rng(1))
    brute = max(_brute_one_way(va, vb, fb), _brute_one_way(vb, va, fa))
    assert mesh_deviation(va, fa, vb, fb) == pytest.approx(brute, rel=1e-12, abs=1e-15)


def test_big_triangles_far_from_their_corners_are_found():
    """A fine sheet against two triangles spanning it (a decimated flat face): most fine
    vertices lie over the middle of a big triangle, far from its corners."""
    v, f = _wavy_sheet(40, 0.0)
    big = np.array([[0, 0, 0.01], [4, 0, 0.01], [4, 4, 0.01], [0, 4, 0.01]], float)
    halves = np.array([[0, 1, 2], [0, 2, 3]])
    assert mesh_deviation(v, f, big, halves) == pytest.approx(0.01, rel=1e-12)
    bent = big + [[0, 0, 0], [0, 0, 0.3], [0, 0, 0], [0, 0, 0]]       # a fold along the diagonal
    brute = max(_brute_one_way(v, bent, halves), _brute_one_way(bent, v, f))
    assert mesh_deviation(v, f, bent, halves) == pytest.approx(brute, rel=1e-12)


def test_a_sheet_shifted_along_its_normal_deviates_by_the_shift():
    v, f = _wavy_sheet(20, 0.0)
    shifted = v + [0.0, 0.0, 0.037]
    assert mesh_deviation(v, f, shifted, f) == pytest.approx(0.037, rel=1e-12)
    assert mesh_deviation(v, f, v, f[:, ::-1]) == 0.0


def test_unused_vertices_do_not_count_and_an_empty_mesh_is_infinitely_far():
    v, f = _wavy_sheet(10, 0.2)
    far = np.vstack([v, [[100.0, 100.0, 100.0]]])
    assert mesh_deviation(far, f, v, f) == 0.0
    assert mesh_deviation(v, f, v, np.zeros((0, 3), int)) == float("inf")


def test_check_is_called_between_chunks_and_can_cancel():
    v, f = _wavy_sheet(100, 0.3)        # 10,000 vertices: two chunks each way
    calls = []
    mesh_deviation(v, f, v, f, check=lambda: calls.append(1))
    assert len(calls) == 4

    def stop():
        raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        mesh_deviation(v, f, v, f, check=stop)


@pytest.mark.parametrize("args, message", [
    ((np.zeros((4, 2)), [[0, 1, 2]]), "mesh a: vertices must be"),
    ((np.zeros((4, 3)), [[0, 1, 4]]), "names vertex 4, outside 0..3"),
    ((np.zeros((4, 3)), [[0, 1]]), "faces \\(m, 3\\)"),
])
def test_bad_meshes_are_refused_naming_what_is_wrong(args, message):
    with pytest.raises(ValueError, match=message):
        mesh_deviation(*args, np.zeros((3, 3)), [[0, 1, 2]])
    with pytest.raises(ValueError, match="NaN or infinite"):
        mesh_deviation(np.full((3, 3), np.nan), [[0, 1, 2]], np.eye(3), [[0, 1, 2]])
