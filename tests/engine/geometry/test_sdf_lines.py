"""line_sdf_grid against closed forms and the brute-force reference."""

import numpy as np
import pytest

from engine.geometry import Cancelled
from engine.geometry.marching import mesh_volume, periodic_mesh
from engine.geometry.sdf_lines import line_sdf_grid, line_sdf_reference


def _nodes(n):
    x = np.arange(n) / n
    return np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1)


def _segment_distance(p, a, b):
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def _random_polylines(rng, count, step):
    polys, radii = [], []
    for _ in range(count):
        start = rng.uniform(-0.1, 1.1, 3)
        pts = start + np.cumsum(rng.uniform(-step, step, size=(3, 3)), axis=0)
        polys.append(np.vstack([start, pts]))
        radii.append(rng.uniform(0.03, 0.08, 4))
    return polys, radii


def _compare(fast, ref, band):
    assert fast.shape == ref.shape and fast.dtype == np.float32
    near = np.abs(ref) < band - 1e-3
    assert near.sum() > 100
    assert np.abs(fast - ref)[near].max() < 1e-3
    clear = np.abs(ref) > 1e-3
    assert np.array_equal(fast[clear] < 0, ref[clear] < 0)
    assert np.all(fast <= band + 1e-7)


def test_capsule_matches_closed_form():
    n, r = 32, 0.1
    a, b = np.array([0.25, 0.5, 0.45]), np.array([0.75, 0.55, 0.5])
    band = 3 / n
    field = line_sdf_grid([np.array([a, b])], [np.array([r, r])], resolution=n)
    exact = np.minimum(_segment_distance(_nodes(n), a, b) - r, band)
    np.testing.assert_allclose(field, exact, atol=1e-6)


def test_flat_ended_cylinder_matches_closed_form():
    n, r, length = 32, 0.1, 0.5
    a, b = np.array([0.25, 0.5, 0.5]), np.array([0.75, 0.5, 0.5])
    field = line_sdf_grid([np.array([a, b])], [r], resolution=n, method="normal")
    p = _nodes(n)
    d = np.stack([np.abs(p[..., 0] - 0.5) - length / 2,
                  np.hypot(p[..., 1] - 0.5, p[..., 2] - 0.5) - r], -1)
    box2d = np.linalg.norm(np.maximum(d, 0), axis=-1) + np.minimum(d.max(-1), 0)
    np.testing.assert_allclose(field, np.minimum(box2d, 3 / n), atol=1e-6)


@pytest.mark.parametrize("periodic", [True, False])
def test_spherical_matches_reference_on_random_polylines(periodic):
    rng = np.random.default_rng(7)
    polys, radii = _random_polylines(rng, 3, 0.4)
    n = 20
    fast = line_sdf_grid(polys, radii, resolution=n, periodic=periodic)
    ref = line_sdf_reference(polys, radii, resolution=n, method="spherical", periodic=periodic)
    _compare(fast, ref, 3 / n)


@pytest.mark.parametrize("periodic", [True, False])
def test_normal_matches_reference_on_random_polylines(periodic):
    rng = np.random.default_rng(11)
    polys, radii = _random_polylines(rng, 2, 0.25)
    n = 20
    fast = line_sdf_grid(polys, radii, resolution=n, method="normal", periodic=periodic)
    ref = line_sdf_reference(polys, radii, resolution=n, method="normal", periodic=periodic)
    _compare(fast, ref, 3 / n)


def test_periodic_shift_by_whole_voxels_is_a_roll():
    n = 24
    poly = np.array([[0.8, 0.1, 0.3], [1.15, -0.2, 0.6], [1.3, 0.2, 0.9]])
    radii = [np.array([0.05, 0.08, 0.04])]
    base = line_sdf_grid([poly], radii, resolution=n)
    shift = np.array([5, -3, 7])
    moved = line_sdf_grid([poly + shift / n], radii, resolution=n)
    np.testing.assert_allclose(moved, np.roll(base, tuple(shift), axis=(0, 1, 2)), atol=1e-6)
    # a whole-cell translation changes nothing at all
    np.testing.assert_allclose(line_sdf_grid([poly + [1, -2, 3]], radii, resolution=n), base, atol=1e-6)


def test_capsule_mesh_volume_matches_closed_form():
    n, r, length = 96, 0.1, 0.5
    field = line_sdf_grid([np.array([[0.25, 0.5, 0.5], [0.75, 0.5, 0.5]])], [r], resolution=n)
    verts, faces = periodic_mesh(field)
    exact = np.pi * r ** 2 * length + 4 / 3 * np.pi * r ** 3
    assert abs(mesh_volume(verts, faces) / exact - 1) < 0.02


def test_normal_method_has_flat_free_ends_and_round_joints():
    n, r = 50, 0.08                       # node spacing 0.02
    bend = np.array([[0.2, 0.3, 0.5], [0.6, 0.3, 0.5], [0.6, 0.7, 0.5]])
    sph = line_sdf_grid([bend], [r], resolution=n)
    nor = line_sdf_grid([bend], [r], resolution=n, method="normal")
    # (0.16, 0.3, 0.5): 0.04 beyond the free end, on the axis
    assert sph[8, 15, 25] < 0 < nor[8, 15, 25]
    # (0.64, 0.28, 0.5): past the end of the first frustum and before the
    # start of the second, only the joint sphere covers it
    assert nor[32, 14, 25] < 0 and sph[32, 14, 25] < 0


def test_closed_loop_gets_a_joint_at_the_seam():
    n, r = 50, 0.06
    square = np.array([[0.3, 0.3, 0.5], [0.7, 0.3, 0.5], [0.7, 0.7, 0.5], [0.3, 0.7, 0.5], [0.3, 0.3, 0.5]])
    corner = (14, 14, 25)                 # (0.28, 0.28, 0.5), outside both frusta
    assert line_sdf_grid([square], [r], resolution=n, method="normal")[corner] < 0
    assert line_sdf_grid([square[:-1]], [r], resolution=n, method="normal")[corner] > 0


def test_cancellation_is_prompt():
    rng = np.random.default_rng(3)
    polys = [rng.uniform(0, 1, size=(2, 3)) for _ in range(1500)]
    radii = [0.06] * len(polys)
    line_sdf_grid(polys[:2], radii[:2], resolution=8, progress=lambda d, t: True)  # JIT warm-up
    planes = []

    def progress(done, total):
        planes.append(done)
        return True

    line_sdf_grid(polys, radii, resolution=96, progress=progress)
    # checked before and after every chunk of planes; a chunk grows at most
    # 4x over the one before (so one slow region cannot hide a cancel long)
    assert planes[0] == 0 and planes[-1] == 96 and len(planes) >= 3
    steps = np.diff(planes)
    assert np.all(steps > 0) and steps[0] <= 2 and np.all(steps[1:] <= 4 * steps[:-1]), steps

    calls = []

    def stop_soon(done, total):
        calls.append(done)
        return len(calls) < 2

    with pytest.raises(Cancelled):
        line_sdf_grid(polys, radii, resolution=96, progress=stop_soon)
    assert calls[-1] < 96


def test_inputs_are_not_mutated_and_output_is_periodic_float32():
    poly = np.array([[0.1, 0.2, 0.3], [0.9, 0.7, 0.4]])
    rad = np.array([0.05, 0.1])
    p0, r0 = poly.copy(), rad.copy()
    field = line_sdf_grid([poly], [rad], resolution=16)
    np.testing.assert_array_equal(poly, p0)
    np.testing.assert_array_equal(rad, r0)
    assert field.shape == (16, 16, 16) and field.dtype == np.float32


def test_no_polylines_gives_an_empty_field():
    field = line_sdf_grid([], [], resolution=8)
    assert np.all(field == np.float32(3 / 8))


@pytest.mark.parametrize("kwargs, match", [
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[0.1], resolution=1), "resolution"),
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[0.1], resolution=8.0), "resolution"),
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[0.1], resolution=8, method="cubic"), "method"),
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[], resolution=8), "one entry per polyline"),
    (dict(polylines=[[[0, 0, 0]]], radii=[0.1], resolution=8), r"polylines\[0\]"),
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[[0.1, 0.1, 0.1]], resolution=8), r"radii\[0\]"),
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[-0.1], resolution=8), ">= 0"),
    (dict(polylines=[[[0, 0, np.inf], [1, 1, 1]]], radii=[0.1], resolution=8), "finite"),
    (dict(polylines=[[[0, 0, 0], [1, 1, 1]]], radii=[0.1], resolution=8, band=0), "band"),
])
def test_bad_input_is_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        line_sdf_grid(**kwargs)


def test_concurrent_calls_from_threads_agree():
    from concurrent.futures import ThreadPoolExecutor
    rng = np.random.default_rng(5)
    polys, radii = _random_polylines(rng, 4, 0.3)
    expected = line_sdf_grid(polys, radii, resolution=32)
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(
            lambda k: line_sdf_grid(polys, radii, resolution=32, progress=(lambda d, t: True) if k % 2 else None),
            range(8)))
    for r in results:
        np.testing.assert_array_equal(r, expected)
