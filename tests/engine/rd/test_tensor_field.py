"""Principal decomposition against numpy.linalg.eigh and hand-solved tensors."""

import warnings

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.rd.tensor_field import check_tensor_field, principal_decomposition, reconstruct_tensor


def _random_symmetric(rng, grid, d):
    a = rng.normal(size=grid + (d, d))
    return a + np.swapaxes(a, -1, -2)


@pytest.mark.parametrize("grid", [(7, 9), (4, 5, 6)])
def test_matches_eigh_sorted_by_magnitude(grid):
    rng = np.random.default_rng(3)
    d = len(grid)
    s = _random_symmetric(rng, grid, d)
    vals, rot = principal_decomposition(s)
    ref_vals, ref_vecs = np.linalg.eigh(s)
    order = np.argsort(-np.abs(ref_vals), axis=-1)
    np.testing.assert_allclose(vals, np.take_along_axis(ref_vals, order, -1), atol=1e-12)
    ref_vecs = np.take_along_axis(ref_vecs, order[..., None, :], -1)
    # same directions up to sign (random tensors have distinct eigenvalues)
    dots = np.abs(np.einsum("...ki,...ki->...i", rot, ref_vecs))
    np.testing.assert_allclose(dots, 1.0, atol=1e-9)
    assert np.all(np.abs(vals[..., :-1]) >= np.abs(vals[..., 1:]))
    np.testing.assert_allclose(np.swapaxes(rot, -1, -2) @ rot, np.broadcast_to(np.eye(d), rot.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-12)
    err = np.abs(reconstruct_tensor(vals, rot) - s).max() / np.abs(s).max()
    assert err < 1e-12


def test_hand_solved_shear_2d():
    s = np.array([[0.0, 3.0], [3.0, 0.0]]).reshape(1, 1, 2, 2)
    vals, rot = principal_decomposition(s)
    np.testing.assert_allclose(vals[0, 0], [3.0, -3.0])
    h = np.sqrt(0.5)
    # v1 = (1, 1)/sqrt 2 (largest component positive), v2 chosen so det = +1
    np.testing.assert_allclose(rot[0, 0], [[h, -h], [h, h]], atol=1e-15)


def test_hand_solved_diagonal_3d():
    s = np.diag([1.0, -5.0, 2.0]).reshape(1, 1, 1, 3, 3)
    vals, rot = principal_decomposition(s)
    np.testing.assert_allclose(vals[0, 0, 0], [-5.0, 2.0, 1.0])
    # columns e_y, e_z, e_x: already a proper rotation
    np.testing.assert_allclose(rot[0, 0, 0], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)


def test_nan_refused_naming_the_cell():
    s = np.zeros((3, 4, 2, 2))
    s[1, 2, 0, 1] = np.nan
    with pytest.raises(ValueError, match=r"NaN or infinite entry at cell \[y=1, x=2\]"):
        principal_decomposition(s)


def test_gross_asymmetry_refused_naming_the_cell():
    s = np.tile(np.eye(3), (2, 2, 2, 1, 1))
    s[0, 1, 1, 0, 2] += 0.5
    with pytest.raises(ValueError, match=r"not symmetric at cell \[z=0, y=1, x=1\]"):
        principal_decomposition(s)


def test_slight_asymmetry_is_symmetrised_with_a_warning():
    rng = np.random.default_rng(0)
    s = _random_symmetric(rng, (3, 3), 2)
    bent = s.copy()
    bent[2, 1, 0, 1] += 1e-6
    with pytest.warns(UserWarning, match=r"symmetric part"):
        vals, rot = principal_decomposition(bent)
    sym = 0.5 * (bent + np.swapaxes(bent, -1, -2))
    np.testing.assert_allclose(reconstruct_tensor(vals, rot), sym, atol=1e-12)


def test_round_off_asymmetry_is_silent():
    s = np.tile(np.array([[2.0, 1.0], [1.0, 2.0]]), (2, 2, 1, 1))
    s[0, 0, 0, 1] += 1e-15
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = check_tensor_field(s)
    assert np.array_equal(out, np.swapaxes(out, -1, -2))


def test_shape_must_match_grid_dimension():
    with pytest.raises(ValueError, match="grid \\+ \\(d, d\\)"):
        principal_decomposition(np.zeros((4, 5, 3, 3)))


def test_cancel():
    s = np.tile(np.eye(2), (8, 8, 1, 1))
    with pytest.raises(Cancelled):
        principal_decomposition(s, progress=lambda done, total: False)
