"""Grid fields against a per-point trilinear loop and scipy's interpolator, their gradient bound
against finite differences, 2-D extrusion against bilinear interpolation, and the GLSL twin."""

import math

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

from engine.geometry.values import Field
from engine.implicit.field_sampling import GridField, as_grid_field, grid_field_from


def _slow_trilinear(values, lo, hi, p):
    """One point at a time: clamp to the outermost sample centres, then weight the (up to) eight
    neighbouring samples, an axis with one sample being constant."""
    nz, ny, nx = values.shape
    counts = (nx, ny, nz)
    out = np.empty(len(p))
    for k, point in enumerate(p):
        per_axis = []
        for a in range(3):
            n = counts[a]
            h = (hi[a] - lo[a]) / n
            centres = [lo[a] + (i + 0.5) * h for i in range(n)]
            x = min(max(point[a], centres[0]), centres[-1])
            if n == 1:
                per_axis.append([(0, 1.0)])
                continue
            i = 0
            while i < n - 2 and x > centres[i + 1]:
                i += 1
            t = (x - centres[i]) / h
            per_axis.append([(i, 1.0 - t), (i + 1, t)])
        total = 0.0
        for ix, wx in per_axis[0]:
            for iy, wy in per_axis[1]:
                for iz, wz in per_axis[2]:
                    total += wx * wy * wz * values[iz, iy, ix]
        out[k] = total
    return out


def _random_grid(rng, shape):
    lo = rng.uniform(-2, 1, 3)
    hi = lo + rng.uniform(0.5, 3, 3)
    return rng.normal(0, 1, shape), lo, hi


SHAPES = [(4, 5, 6), (1, 3, 4), (3, 1, 1), (1, 1, 1), (2, 2, 7), (5, 1, 3)]


@pytest.mark.parametrize("shape", SHAPES)
def test_sample_matches_a_per_point_trilinear_loop(shape):
    rng = np.random.default_rng(sum(shape))
    values, lo, hi = _random_grid(rng, shape)
    g = GridField(values, lo, hi)
    p = rng.uniform(lo - 1.0, hi + 1.0, (400, 3))                 # many points outside the box
    assert np.mean(np.any((p < lo) | (p > hi), axis=1)) > 0.3
    np.testing.assert_allclose(g.sample(p), _slow_trilinear(values, lo, hi, p), rtol=0, atol=1e-12)
    assert g.counts == shape[::-1]


def test_sample_matches_scipy_on_the_clamped_points():
    rng = np.random.default_rng(7)
    values, lo, hi = _random_grid(rng, (5, 6, 7))
    g = GridField(values, lo, hi)
    h = (hi - lo) / np.array([7, 6, 5])
    axes = [lo[a] + (np.arange(n) + 0.5) * h[a] for a, n in enumerate((7, 6, 5))]
    ref = RegularGridInterpolator((axes[2], axes[1], axes[0]), values, method="linear")
    p = rng.uniform(lo - 0.5, hi + 0.5, (2000, 3))
    q = np.clip(p, [a[0] for a in axes], [a[-1] for a in axes])
    np.testing.assert_allclose(g.sample(p), ref(q[:, ::-1]), rtol=0, atol=1e-12)


def test_samples_are_read_at_their_cell_centres_and_the_range_is_kept():
    rng = np.random.default_rng(2)
    values, lo, hi = _random_grid(rng, (3, 4, 2))
    g = GridField(values, lo, hi)
    h = (hi - lo) / np.array([2, 4, 3])
    iz, iy, ix = np.meshgrid(*[np.arange(n) for n in (3, 4, 2)], indexing="ij")
    centres = lo + (np.stack([ix, iy, iz], axis=-1).reshape(-1, 3) + 0.5) * h
    np.testing.assert_allclose(g.sample(centres), values.reshape(-1), atol=1e-12)
    f = g.sample(rng.uniform(lo - 2, hi + 2, (5000, 3)))
    assert g.minimum - 1e-12 <= f.min() and f.max() <= g.maximum + 1e-12
    assert (g.minimum, g.maximum) == (values.min(), values.max())


@pytest.mark.parametrize("shape", SHAPES)
def test_finite_differences_never_exceed_the_lipschitz_bound(shape):
    rng = np.random.default_rng(3 + sum(shape))
    values, lo, hi = _random_grid(rng, shape)
    g = GridField(values, lo, hi)
    a = rng.uniform(lo - 0.5, hi + 0.5, (20000, 3))
    for step in (1e-6, 0.05, 0.5):
        b = a + rng.normal(0, step, a.shape)
        ratio = np.abs(g.sample(a) - g.sample(b)) / np.linalg.norm(a - b, axis=1)
        assert ratio.max() <= g.lipschitz * (1 + 1e-6) + 1e-9


def test_lipschitz_bound_is_the_slope_of_a_linear_ramp():
    # v = 2 x_index + 0 y: the slope along x is 2 / hx and the bound equals it
    values = np.broadcast_to(2.0 * np.arange(5), (3, 4, 5)).copy()
    g = GridField(values, (0, 0, 0), (2.5, 1, 1))                  # hx = 0.5
    assert g.lipschitz == pytest.approx(4.0)
    p = np.array([[0.6, 0.3, 0.5], [0.9, 0.3, 0.5]])
    assert (g.sample(p)[1] - g.sample(p)[0]) / 0.3 == pytest.approx(4.0)
    # and the bound combines the axes as sqrt(Dx^2 + Dy^2 + Dz^2)
    rng = np.random.default_rng(0)
    v = rng.normal(0, 1, (3, 4, 5))
    h = np.array([0.5, 0.25, 1.0 / 3.0])
    d = [np.abs(np.diff(v, axis=2)).max() / h[0], np.abs(np.diff(v, axis=1)).max() / h[1],
         np.abs(np.diff(v, axis=0)).max() / h[2]]
    assert GridField(v, (0, 0, 0), (2.5, 1, 1)).lipschitz == pytest.approx(math.hypot(*d))


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_2d_field_is_extruded_along_the_axis(axis):
    rng = np.random.default_rng(axis)
    v2 = rng.normal(0, 1, (4, 6))                                   # (nv, nu)
    lo, hi = np.array([-1.0, 0.5]), np.array([2.0, 2.5])
    g = grid_field_from(v2, lo, hi, extrude_axis=axis, extent=(-3.0, 3.0))
    plane = [a for a in range(3) if a != axis]                     # u, v: the others in order
    h = (hi - lo) / np.array([6, 4])
    uc, vc = (lo[k] + (np.arange(n) + 0.5) * h[k] for k, n in enumerate((6, 4)))
    ref = RegularGridInterpolator((vc, uc), v2, method="linear")
    p = rng.uniform(-4, 4, (3000, 3))
    u = np.clip(p[:, plane[0]], uc[0], uc[-1])
    w = np.clip(p[:, plane[1]], vc[0], vc[-1])
    np.testing.assert_allclose(g.sample(p), ref(np.stack([w, u], axis=1)), atol=1e-12)
    assert g.lo[axis] == -3.0 and g.hi[axis] == 3.0
    assert tuple(g.lo[plane]) == tuple(lo) and tuple(g.hi[plane]) == tuple(hi)


def test_a_3d_field_passes_through_and_fields_convert():
    rng = np.random.default_rng(5)
    v = rng.random((2, 3, 4))
    g = grid_field_from(v, (0, 0, 0), (4, 3, 2))
    np.testing.assert_array_equal(g.values, v)
    f = as_grid_field(Field(v, np.zeros(3), np.array([4.0, 3.0, 2.0])), "density_field")
    p = rng.uniform(-1, 5, (100, 3))
    np.testing.assert_allclose(f.sample(p), g.sample(p), atol=0)
    assert as_grid_field(g, "x") is g


@pytest.mark.parametrize("args, kw, match", [
    ((np.zeros(4), (0,), (1,)), {}, "2-D .* or 3-D"),
    ((np.zeros((2, 2)), (0, 0, 0), (1, 1, 1)), {}, "needs 2 box coordinates"),
    ((np.zeros((2, 2, 2)), (0, 0), (1, 1)), {}, "needs 3 box coordinates"),
    ((np.zeros((2, 2)), (0, 0), (1, 1)), dict(extrude_axis=3), "extrude_axis"),
    ((np.zeros((2, 2)), (0, 0), (1, 1)), dict(extent=(1.0, 1.0)), "extent"),
    ((np.zeros((2, 2)), (0, 0), (1, 0)), {}, "hi > lo"),
    ((np.full((2, 2, 2), np.nan), (0, 0, 0), (1, 1, 1)), {}, "NaN"),
])
def test_bad_grids_refused(args, kw, match):
    with pytest.raises(ValueError, match=match):
        grid_field_from(*args, **kw)


def test_bad_grid_field_input_refused():
    with pytest.raises(ValueError, match="at least one sample"):
        GridField(np.zeros((0, 2, 2)), (0, 0, 0), (1, 1, 1))
    with pytest.raises(ValueError, match="offset_field must be a GridField"):
        as_grid_field(3.0, "offset_field")
    with pytest.raises(ValueError, match="density_field: values must be a"):
        as_grid_field(Field(np.zeros((2, 2)), np.zeros(2), np.ones(2)), "density_field")


@pytest.mark.parametrize("shape", [(4, 5, 6), (1, 3, 4), (3, 1, 1), (1, 1, 1)])
def test_glsl_reads_the_same_interpolation(gpu, shape):
    from engine.gpu.sdf_points import evaluate_glsl
    from engine.implicit.values import SDF

    rng = np.random.default_rng(11)
    values, lo, hi = _random_grid(rng, shape)
    grid = GridField(values, lo, hi)

    class _Probe(SDF):                       # the field as an SDF, to run it through the shader
        def field(self, points):
            return grid.sample(points)

        def glsl(self, module):
            name = grid.glsl(module)
            return module.function(self, lambda n: f"float {n}(vec3 p) {{ return {name}(p); }}")

    p = rng.uniform(lo - 1, hi + 1, (5000, 3))
    probe = _Probe()
    np.testing.assert_allclose(evaluate_glsl(probe, p), grid.sample(p), rtol=0, atol=2e-5)
