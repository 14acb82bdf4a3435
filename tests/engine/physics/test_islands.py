"""Periodic components and percolation against a brute-force tiled labelling."""

import numpy as np
import pytest
import scipy.ndimage as ndi

from engine.physics.islands import keep_percolating, periodic_components


def _brute_force_kept(solid, tiles=5):
    """Label a tiles^dim block of copies non-periodically (full connectivity);
    a centre-tile voxel percolates when it is connected to one of its own
    images in the block."""
    dim = solid.ndim
    n = np.array(solid.shape)
    big = np.tile(solid, (tiles,) * dim)
    lab, _ = ndi.label(big, structure=np.ones((3,) * dim))
    c = tiles // 2
    kept = np.zeros_like(solid)
    for idx in np.argwhere(solid):
        home = lab[tuple(idx + c * n)]
        for shift in np.ndindex(*(3,) * dim):
            s = np.array(shift) - 1
            if s.any() and lab[tuple(idx + (c + s) * n)] == home:
                kept[tuple(idx)] = True
                break
    return kept


def test_rod_along_x_percolates_only_in_x():
    s = np.zeros((6, 6, 6), bool)
    s[:, 2, 3] = True
    labels, perc = periodic_components(s)
    assert labels.max() == 0
    np.testing.assert_array_equal(perc[0], [True, False, False])
    kept, dropped = keep_percolating(s)
    np.testing.assert_array_equal(kept, s)
    assert dropped == 0.0


def test_rod_crossing_the_boundary_but_shorter_than_the_cell_is_an_island():
    s = np.zeros((10, 5, 5), bool)
    s[[8, 9, 0, 1, 2], 1, 1] = True           # wraps around, length 5 < 10
    labels, perc = periodic_components(s)
    assert labels.max() == 0 and not perc.any()
    kept, dropped = keep_percolating(s)
    assert not kept.any()
    assert dropped == pytest.approx(5 / s.size)


def test_corner_contact_connects_and_percolates_diagonally():
    n = 7
    s = np.zeros((n, n, n), bool)
    for i in range(n):
        s[i, i, i] = True                      # touches its neighbour at a corner only
    labels, perc = periodic_components(s)
    assert labels.max() == 0
    assert perc[0].all()


def test_2d_eight_connectivity_and_blob():
    img = np.zeros((8, 8), bool)
    for i in range(8):
        img[i, (i + 3) % 8] = True             # diagonal staircase, wraps: percolates
    img[1, 0] = True                           # isolated pixel, not adjacent to it
    kept, dropped = keep_percolating(img)
    assert kept.sum() == 8 and not kept[1, 0]
    assert dropped == pytest.approx(1 / 64)


def test_density_weighted_dropped_fraction():
    d = np.zeros((8, 8, 8))
    d[:, 0, 0] = 1.0                           # beam
    d[4:6, 4:6, 4:6] = 0.5                     # floating blob
    kept, dropped = keep_percolating(d)
    assert kept.sum() == 8
    assert dropped == pytest.approx(8 * 0.5 / 512)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("dim", [2, 3])
def test_matches_brute_force_tiling(seed, dim):
    rng = np.random.default_rng(seed)
    shape = (6, 5, 7) if dim == 3 else (9, 11)
    frac = 0.12 if dim == 3 else 0.38           # near the percolation threshold
    solid = rng.random(shape) < frac
    kept, _ = keep_percolating(solid)
    np.testing.assert_array_equal(kept, _brute_force_kept(solid, tiles=5 if dim == 3 else 7))
