"""Alignment a(x) (eq. 3), Gamma_sigma (eq. 4) and Gamma (eq. 5) on constructed fields."""

import itertools

import numpy as np
import pytest

from engine.rd.infill_map import alignment, gamma_sigma, infill_map
from engine.rd.regularise import orthonormalise


def _same_fraction(labels, neighbourhood):
    """Slow reference: per cell, (neighbours with the same label) / (neighbours in the grid)."""
    out = np.zeros(labels.shape)
    nd = labels.ndim
    offs = [o for o in itertools.product((-1, 0, 1), repeat=nd) if any(o)]
    if neighbourhood == "face":
        offs = [o for o in offs if sum(map(abs, o)) == 1]
    for idx in np.ndindex(labels.shape):
        same = count = 0
        for o in offs:
            j = tuple(i + k for i, k in zip(idx, o))
            if all(0 <= a < n for a, n in zip(j, labels.shape)):
                count += 1
                same += labels[j] == labels[idx]
        out[idx] = same / count
    return out


@pytest.mark.parametrize("grid", [(6, 7), (4, 5, 3)])
@pytest.mark.parametrize("neighbourhood", ["face", "full"])
def test_constant_direction_field_is_fully_aligned(grid, neighbourhood):
    d = len(grid)
    r0 = orthonormalise(np.random.default_rng(2).normal(size=(d, d)))
    r = np.broadcast_to(r0, grid + (d, d))
    np.testing.assert_allclose(alignment(r, neighbourhood=neighbourhood), 1.0, atol=1e-12)


@pytest.mark.parametrize("neighbourhood", ["face", "full"])
def test_two_regions_at_ninety_degrees_2d(neighbourhood):
    labels = np.zeros((6, 8), int)
    labels[:, 4:] = 1
    quarter = np.array([[0.0, -1.0], [1.0, 0.0]])
    r = np.where(labels[..., None, None] == 1, quarter, np.eye(2))
    a = alignment(r, neighbourhood=neighbourhood)
    np.testing.assert_allclose(a, _same_fraction(labels, neighbourhood), atol=1e-12)
    # closed form for an interior row at the interface: 3 of 4, or 5 of 8, neighbours alike
    assert a[2, 3] == pytest.approx(0.75 if neighbourhood == "face" else 0.625)


def test_two_regions_at_ninety_degrees_3d():
    labels = np.zeros((4, 4, 5), int)
    labels[2:] = 1
    # columns e_y, e_z, e_x: every v_i is at 90 degrees to the other region's v_i
    perm = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    r = np.where(labels[..., None, None] == 1, perm, np.eye(3))
    assert np.allclose(np.einsum("ki,ki->i", perm, np.eye(3)), 0.0)
    np.testing.assert_allclose(alignment(r), _same_fraction(labels, "face"), atol=1e-12)


def test_zero_orientation_counts_as_misaligned():
    r = np.tile(np.eye(2), (3, 3, 1, 1))
    r[1, 1] = 0.0
    a = alignment(r)
    assert a[1, 1] == 0.0
    assert a[0, 1] == pytest.approx(2 / 3)     # edge cell: 3 neighbours, one of them zero
    assert a[0, 0] == 1.0


def test_gamma_sigma_and_gamma_combination():
    labels = np.zeros((5, 6), int)
    labels[:, 3:] = 1
    r = np.where(labels[..., None, None] == 1, np.array([[0.0, -1.0], [1.0, 0.0]]), np.eye(2))
    rho = np.linspace(0.0, 1.0, 30).reshape(5, 6)
    a = _same_fraction(labels, "face")
    gs = gamma_sigma(r, rho)
    np.testing.assert_allclose(gs, (1.0 - a) * rho, atol=1e-12)
    gamma_c = np.zeros((5, 6))
    gamma_c[0, :] = 1.0
    gamma_c[4, 2] = 0.05
    g = infill_map(r, rho, gamma_c=gamma_c)
    np.testing.assert_allclose(g, np.maximum(gamma_c, gs), atol=1e-12)
    assert g[0, 0] == 1.0 and g[4, 2] == pytest.approx(gs[4, 2]) and gs[4, 2] > 0.05
    np.testing.assert_array_equal(infill_map(r, rho), gs)


def test_bad_inputs_are_refused_by_name():
    r = np.tile(np.eye(2), (3, 3, 1, 1))
    with pytest.raises(ValueError, match="rho must lie in \\[0, 1\\]"):
        gamma_sigma(r, np.full((3, 3), 1.5))
    with pytest.raises(ValueError, match="gamma_c must have the grid shape"):
        infill_map(r, np.ones((3, 3)), gamma_c=np.ones((2, 3)))
    with pytest.raises(ValueError, match="neighbourhood"):
        alignment(r, neighbourhood="moore")
