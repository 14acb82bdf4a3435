"""Hints: forms, expansion, availability counts, realised probabilities, Dirichlet sampling."""

import numpy as np
import pytest
from scipy import stats

from engine.growth import (Tiling, availability_counts, dirichlet_hints, expand_block_hints,
                           hint_table, load_tileset, normalize_hints, realised_probabilities)


def test_normalize_and_expand():
    np.testing.assert_allclose(normalize_hints([1, 3]), [0.25, 0.75])
    with pytest.raises(ValueError, match="positive sum"):
        normalize_hints([0, 0])
    ts = load_tileset("TL+-")
    w = expand_block_hints(ts, [0.4, 0.1, 0.1, 0.4])
    assert w.shape == (11,)
    np.testing.assert_allclose(w[ts.tiles_of("T")], 0.1)
    np.testing.assert_allclose(w[ts.tiles_of("-")], 0.05)
    np.testing.assert_allclose(w.sum(), 1.0)


def test_hint_table_forms_agree():
    ts = load_tileset("TL+-")
    a = hint_table(ts, {"T": 0.4, "L": 0.1, "-": 0.1, "+": 0.4}, (3, 3))
    b = hint_table(ts, [0.4, 0.1, 0.1, 0.4], (3, 3))
    c = hint_table(ts, np.tile([0.4, 0.1, 0.1, 0.4], (3, 3, 1)), (3, 3))
    assert a.shape == b.shape == (1, 11) and c.shape == (9, 11)
    np.testing.assert_allclose(a, b)
    np.testing.assert_allclose(c, np.repeat(a, 9, axis=0))
    d = hint_table(ts, {"T@1": 2.0, "T": 0.4}, (3, 3))[0]
    assert d[ts.tile_index("T@1")] == 2.0 and d[ts.tile_index("T@0")] == pytest.approx(0.1)
    assert d[ts.tiles_of("L")].sum() == 0


def test_availability_counts_ratio_and_absolute():
    ts = load_tileset("TL+-")
    table = hint_table(ts, None, (20, 20))
    np.testing.assert_array_equal(availability_counts(ts, 1.0, table, 400), [100] * 4)
    np.testing.assert_array_equal(
        availability_counts(ts, 2.0, hint_table(ts, [0.4, 0.1, 0.1, 0.4], (20, 20)), 400),
        [320, 80, 80, 320])
    c = availability_counts(ts, {"L": 5}, table, 400)
    assert c[1] == 5 and np.isinf(c[[0, 2, 3]]).all()
    assert availability_counts(ts, None, table, 400) is None
    assert availability_counts(ts, float("inf"), table, 400) is None


def test_realised_probabilities_counts_blocks():
    ts = load_tileset("TL+-")
    T0, P, L1 = ts.tile_index("T@0"), ts.tile_index("+@0"), ts.tile_index("L@1")
    t = Tiling(np.array([[T0, P], [P, -1], [L1, P]], dtype=np.int32), "TL+-", False)
    np.testing.assert_allclose(realised_probabilities(t, ts), [0.2, 0.2, 0.0, 0.6])
    assert realised_probabilities(t, ts, per="tile")[P] == pytest.approx(0.6)


def test_dirichlet_sums_to_one_and_spacing_respected():
    w = dirichlet_hints(4, 60, min_distance=0.12, rng=0)
    assert w.shape == (60, 4) and np.all(w > 0)
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
    d = np.linalg.norm(w[:, None] - w[None], axis=-1)
    assert d[np.triu_indices(60, 1)].min() > 0.12
    np.testing.assert_array_equal(w, dirichlet_hints(4, 60, min_distance=0.12, rng=0))


def test_dirichlet_is_uniform_on_the_simplex():
    """Symmetric Dirichlet(1): marginals are Beta(1, n-1), mean 1/n."""
    w = dirichlet_hints(3, 4000, rng=1)
    np.testing.assert_allclose(w.mean(axis=0), 1 / 3, atol=0.015)
    for k in range(3):
        assert stats.kstest(w[:, k], stats.beta(1, 2).cdf).pvalue > 0.001
    screened = dirichlet_hints(3, 150, min_distance=0.05, rng=2)
    np.testing.assert_allclose(screened.mean(axis=0), 1 / 3, atol=0.03)


def test_dirichlet_impossible_spacing_is_a_clear_error():
    with pytest.raises(ValueError, match="min_distance=1.5"):
        dirichlet_hints(3, 3, min_distance=1.5, rng=0, max_attempts=200)
    with pytest.raises(ValueError, match="n_blocks"):
        dirichlet_hints(0, 3)
