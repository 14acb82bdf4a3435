"""Appendix Algorithms 1 and 2 on fields with known answers."""

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.rd.regularise import (V_ALPHA, V_BETA, closest_matrix, complete_partial_orientations,
                                  mask_trivial_directions, orthonormalise, regenerate_trivial_orientations,
                                  regularise_orientations, signed_permutations)
from engine.rd.tensor_field import principal_decomposition


def _rot2(deg):
    t = np.radians(deg)
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


def _random_rotation(rng, d):
    q = orthonormalise(rng.normal(size=(d, d)))
    return q


def _assert_proper(r):
    d = r.shape[-1]
    np.testing.assert_allclose(np.swapaxes(r, -1, -2) @ r, np.broadcast_to(np.eye(d), r.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-12)


@pytest.mark.parametrize("d, size", [(2, 8), (3, 48)])
def test_signed_permutation_group(d, size):
    g = signed_permutations(d)
    assert g.shape == (size, d, d)
    np.testing.assert_array_equal(g[0], np.eye(d))
    assert len({m.tobytes() for m in g}) == size
    np.testing.assert_allclose(np.swapaxes(g, -1, -2) @ g, np.broadcast_to(np.eye(d), g.shape))


@pytest.mark.parametrize("d", [2, 3])
def test_closest_matrix_matches_brute_force_over_the_group(d):
    rng = np.random.default_rng(11)
    a = orthonormalise(rng.normal(size=(300, d, d)))
    b = orthonormalise(rng.normal(size=(300, d, d)))
    cand = b[:, None] @ signed_permutations(d)[None]
    score = (a[:, None] * cand).sum(axis=(-2, -1))
    expected = cand[np.arange(300), score.argmax(axis=1)]
    np.testing.assert_allclose(closest_matrix(a, b), expected, atol=1e-15)


def test_mask_rules_3d():
    eye = np.tile(np.eye(3), (5, 1, 1, 1, 1)).reshape(5, 1, 1, 3, 3)
    vals = np.array([[5.0, 0.0, 0.0],     # uniaxial: v1 defined, v2 v3 not
                     [5.0, 2.0, 2.0],     # |s2| = |s3|: v2 v3 undefined
                     [5.0, 5.0, 1.0],     # |s1| = |s2|: nothing kept
                     [3.0, 3.0, 3.0],     # hydrostatic
                     [5.0, 3.0, 1.0]]).reshape(5, 1, 1, 3)
    out = mask_trivial_directions(vals, eye, sigma_min=0.1)
    kept = (out != 0).any(axis=-2)[:, 0, 0]
    np.testing.assert_array_equal(kept, [[1, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0], [1, 1, 1]])


def test_mask_rules_2d():
    eye = np.tile(np.eye(2), (4, 1, 1, 1)).reshape(4, 1, 2, 2)
    vals = np.array([[3.0, 3.0], [3.0, 0.0], [0.01, 0.0], [3.0, -3.0]]).reshape(4, 1, 2)
    out = mask_trivial_directions(vals, eye, sigma_min=0.1)
    kept = (out != 0).any(axis=-2)[:, 0]
    # v2 is never dropped alone; equal magnitudes (even of opposite sign) make v1 undefined
    np.testing.assert_array_equal(kept, [[0, 0], [1, 1], [0, 0], [0, 0]])


def test_algorithm1_completes_with_v_alpha_and_falls_back_to_v_beta():
    va = np.array(V_ALPHA)
    r = np.zeros((1, 1, 3, 3, 3))
    v1 = np.array([0.0, 0.6, 0.8])
    r[0, 0, 0, :, 0] = v1
    r[0, 0, 1, :, 0] = va                 # parallel to v_alpha: must use v_beta
    r[0, 0, 2] = np.eye(3)                # complete already: untouched
    out = complete_partial_orientations(r)
    w = np.cross(v1, va)
    w /= np.linalg.norm(w)
    np.testing.assert_allclose(out[0, 0, 0], np.column_stack([v1, w, np.cross(v1, w)]), atol=1e-15)
    w = np.cross(va, np.array(V_BETA))
    w /= np.linalg.norm(w)
    np.testing.assert_allclose(out[0, 0, 1], np.column_stack([va, w, np.cross(va, w)]), atol=1e-15)
    np.testing.assert_array_equal(out[0, 0, 2], np.eye(3))
    _assert_proper(out)


@pytest.mark.parametrize("update", ["sequential", "simultaneous"])
@pytest.mark.parametrize("grid", [(9, 10), (6, 7, 5)])
def test_hole_of_zero_stress_is_filled_from_a_constant_field(update, grid):
    rng = np.random.default_rng(5)
    d = len(grid)
    r0 = _random_rotation(rng, d)
    vals = np.diag(np.arange(d, 0, -1) * 2.0 + 1.0)
    sigma = np.broadcast_to(r0 @ vals @ r0.T, grid + (d, d)).copy()
    hole = tuple(slice(2, 5) for _ in grid)
    sigma[hole] = 0.0
    p = principal_decomposition(sigma)
    out = regularise_orientations(p.values, p.rotation, update=update)
    expected_hole = np.zeros(grid, bool)
    expected_hole[hole] = True
    np.testing.assert_array_equal(out.trivial, expected_hole)
    assert not out.unfilled.any() and not out.partial.any()
    # the filled cells carry the surrounding directions (up to the sign of each column)
    dots = np.abs(np.einsum("...ki,ki->...i", out.rotation[hole], p.rotation[(0,) * d]))
    np.testing.assert_allclose(dots, 1.0, atol=1e-12)
    _assert_proper(out.rotation)


@pytest.mark.parametrize("update", ["sequential", "simultaneous"])
def test_gap_gets_the_aligned_mean_of_its_neighbours(update):
    # (left, right) neighbour angles of a one-cell gap -> expected angle. Directions
    # count modulo 90 degrees (signed permutations): -40 is 50, next to 40; 100 is 10.
    cases = [((20, -20), 0), ((40, -40), 45), ((10, 100), 10)]
    for (left, right), expected in cases:
        r = np.zeros((1, 3, 2, 2))
        r[0, 0], r[0, 2] = _rot2(left), _rot2(right)
        out, unfilled = regenerate_trivial_orientations(r, update=update)
        np.testing.assert_allclose(out[0, 1], _rot2(expected), atol=1e-12)
        assert not unfilled.any()


def test_sequential_sweep_updates_in_place_in_raster_order():
    r = np.zeros((4, 5, 2, 2))
    r[0, 0] = _rot2(30)
    seq, left_seq = regenerate_trivial_orientations(r, max_steps=1, update="sequential")
    sim, left_sim = regenerate_trivial_orientations(r, max_steps=1, update="simultaneous")
    assert not left_seq.any()                  # one sweep reaches every cell
    assert (~left_sim).sum() == 3              # the seed and its two face neighbours
    np.testing.assert_allclose(seq, np.broadcast_to(_rot2(30), seq.shape), atol=1e-12)


def test_random_field_with_holes_and_partial_cells_becomes_regular():
    rng = np.random.default_rng(8)
    a = rng.normal(size=(5, 6, 7, 3, 3))
    s = a + np.swapaxes(a, -1, -2)
    s[1:3, 2:4, 1:5] = 0.0                                    # trivial hole
    s[4, :, :] = np.diag([4.0, 0.0, 0.0])                    # uniaxial layer: partial
    p = principal_decomposition(s)
    out = regularise_orientations(p.values, p.rotation, neighbourhood="full")
    assert out.partial[4].all() and out.trivial[1:3, 2:4, 1:5].all()
    assert not out.unfilled.any()
    _assert_proper(out.rotation)
    # defined cells keep their directions
    keep = ~out.trivial & ~out.partial
    np.testing.assert_allclose(out.rotation[keep], p.rotation[keep], atol=1e-15)


def test_all_trivial_field_is_reported_unfilled():
    out = regularise_orientations(np.zeros((3, 4, 2)), np.tile(np.eye(2), (3, 4, 1, 1)))
    assert out.trivial.all() and out.unfilled.all()
    assert not out.rotation.any()


def test_cancel():
    r = np.zeros((30, 30, 2, 2))
    r[0, 0] = np.eye(2)
    with pytest.raises(Cancelled):
        regenerate_trivial_orientations(r, progress=lambda done, total: done < 10)
