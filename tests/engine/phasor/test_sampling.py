import math

import numpy as np
import pytest

from engine.phasor.fields import PhasorFields, constant_fields
from engine.phasor.sampling import local_frame, resample_kernels, sample_kernels, site_cells

LO, HI = np.array([0.0, -2.0, 1.0]), np.array([12.0, 7.0, 6.0])


def _random_fields(seed, shape=(3, 4, 5), spread=0.6):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=shape + (3,))
    d /= np.linalg.norm(d, axis=-1)[..., None]
    f = rng.uniform(1.0, 2.0, shape)
    f.flat[0] = 1.0  # same F_min, so the same radius, for every seed
    return PhasorFields(d, f, rng.uniform(0.0, spread, shape), LO, HI)


def test_sites_fill_every_cell_of_a_grid_covering_the_box_with_one_cell_margin():
    fields = _random_fields(0)
    k = sample_kernels(fields, per_cell=5, c=3.0, rng=4)
    assert k.radius == pytest.approx(3.0 / fields.min_frequency())
    np.testing.assert_allclose(k.origin, LO - k.radius)
    assert np.all(k.origin + k.grid * k.radius >= HI + k.radius)
    assert np.all(np.diff(k.cell_start) == 5)
    flat = k.cell_of(k.positions) @ np.array([1, k.grid[0], k.grid[0] * k.grid[1]])
    np.testing.assert_array_equal(flat, site_cells(k))
    assert np.all(k.phase_v == 0) and np.all(k.phase_w == 0)
    assert np.all(np.abs(k.spread_u) <= 1) and k.spread_u.std() > 0.4


def test_local_frame_is_the_papers_v_and_w_with_a_fixed_fallback_for_vertical_d():
    rng = np.random.default_rng(1)
    d = rng.normal(size=(50, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    v, w = local_frame(d)
    z = np.array([0.0, 0.0, 1.0])
    zxd = np.cross(z, d)
    np.testing.assert_allclose(v, zxd / np.linalg.norm(zxd, axis=1)[:, None], atol=1e-12)
    zxdxd = np.cross(zxd, d)
    np.testing.assert_allclose(w, zxdxd / np.linalg.norm(zxdxd, axis=1)[:, None], atol=1e-12)
    for a, b in ((v, w), (v, d), (w, d)):
        np.testing.assert_allclose(np.sum(a * b, axis=1), 0.0, atol=1e-12)
    v, w = local_frame([[0, 0, 1], [0, 0, -1], [1e-8, 0, 1]])
    np.testing.assert_allclose(v, [[1, 0, 0]] * 3, atol=1e-7)
    np.testing.assert_allclose(w, [[0, -1, 0], [0, 1, 0], [0, -1, 0]], atol=1e-7)


def test_spread_tilts_only_dv_about_w_by_spread_u_times_gamma():
    fields = _random_fields(2, spread=math.pi / 2)
    k = sample_kernels(fields, rng=3)
    v, w = local_frame(fields.sample_direction(k.positions))
    gamma = fields.sample_spread(k.positions)
    np.testing.assert_array_equal(k.direction_w, w)
    np.testing.assert_allclose(np.sum(k.direction_v * w, axis=1), 0.0, atol=1e-12)
    tilt = np.arctan2(np.sum(k.direction_v * np.cross(w, v), axis=1), np.sum(k.direction_v * v, axis=1))
    np.testing.assert_allclose(tilt, k.spread_u * gamma, atol=1e-12)
    flat = sample_kernels(constant_fields(LO, HI, (2, 2, 2), direction=(0, 1, 1)), rng=3)
    np.testing.assert_allclose(flat.direction_v, local_frame(np.tile([0, 1, 1], (flat.n, 1)) / math.sqrt(2))[0])


def test_same_seed_gives_identical_bytes_and_another_seed_differs():
    fields = _random_fields(3)
    a, b, c = (sample_kernels(fields, rng=s) for s in (7, 7, 8))
    for name in ("positions", "frequency", "direction_v", "direction_w", "spread_u"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
    assert not np.array_equal(a.positions, c.positions)
    g = sample_kernels(fields, rng=np.random.default_rng(7))
    assert g.seed == -1 and np.array_equal(g.positions, a.positions)


def test_resampling_every_cell_equals_a_fresh_sample_of_the_new_fields():
    before, after = _random_fields(4), _random_fields(5)
    k = sample_kernels(before, rng=11)
    k = k.with_phases(np.arange(k.n) * 0.1, -np.arange(k.n) * 0.2)
    redone, changed = resample_kernels(k, after, np.ones(tuple(k.grid[::-1]), dtype=bool))
    fresh = sample_kernels(after, rng=11)
    np.testing.assert_array_equal(changed, np.arange(k.n))
    for name in ("positions", "frequency", "direction_v", "direction_w", "spread_u", "cell_start"):
        assert getattr(redone, name).tobytes() == getattr(fresh, name).tobytes(), name
    np.testing.assert_array_equal(redone.phase_v, k.phase_v)
    np.testing.assert_array_equal(redone.phase_w, k.phase_w)


def test_resampling_a_box_changes_only_the_sites_inside_it():
    before, after = _random_fields(6), _random_fields(7)
    k = sample_kernels(before, rng=2)
    box = (np.array([2.0, 0.0, 2.0]), np.array([8.0, 5.0, 4.0]))
    redone, changed = resample_kernels(k, after, box)
    inside = np.all((k.positions >= box[0]) & (k.positions <= box[1]), axis=1)
    np.testing.assert_array_equal(changed, np.flatnonzero(inside))
    assert 0 < len(changed) < k.n
    fresh = sample_kernels(after, rng=2)
    for name in ("frequency", "direction_v", "direction_w"):
        new, old, want = getattr(redone, name), getattr(k, name), getattr(fresh, name)
        np.testing.assert_array_equal(new[~inside], old[~inside])
        np.testing.assert_array_equal(new[inside], want[inside])
    cells = np.zeros(int(np.prod(k.grid)), dtype=bool)
    cells[[3, 40]] = True
    _, changed = resample_kernels(k, after, cells)
    np.testing.assert_array_equal(changed, np.flatnonzero(np.isin(site_cells(k), [3, 40])))


@pytest.mark.parametrize("kwargs, words", [({"per_cell": 0}, "per_cell"), ({"c": -1.0}, "c:"),
                                           ({"rng": "x"}, "rng"), ({"box": ((0, 0, 0), (0, 1, 1))}, "box")])
def test_bad_sampling_options_are_refused_by_name(kwargs, words):
    with pytest.raises(ValueError, match=words):
        sample_kernels(_random_fields(0), **kwargs)


def test_bad_region_is_refused():
    k = sample_kernels(_random_fields(0), rng=0)
    with pytest.raises(ValueError, match="region"):
        resample_kernels(k, _random_fields(1), np.ones(5, dtype=bool))
    with pytest.raises(ValueError, match="region"):
        resample_kernels(k, _random_fields(1), "everything")
