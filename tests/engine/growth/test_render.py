"""Rendering: pixel counts in closed form, seamless tilings, voxels, beams."""

import math

import numpy as np
import pytest

from engine.growth import (block_image, block_voxels, grow_tiling, load_tileset, tiling_beams,
                           tiling_image, tiling_outline, tiling_voxels)


@pytest.mark.parametrize("n, w", [(20, 4), (20, 2), (40, 6)])
def test_block_pixel_counts_closed_form(n, w):
    ts = load_tileset("TL+-")
    img = lambda name: block_image(ts.tiles[ts.tile_index(name)], resolution=n, line_width=w)
    assert img("+@0").sum() == 2 * w * n - w * w        # two full bars, one overlap square
    assert img("-@0").sum() == w * n
    assert img("T@0").sum() == w * n + w * (n // 2 - w // 2)
    plus = img("+@0")
    assert plus.dtype == np.uint8 and set(np.unique(plus)) == {0, 1}
    rows = np.flatnonzero(plus[:, 0])
    np.testing.assert_array_equal(rows, np.arange(n // 2 - w // 2, n // 2 + w // 2))


def test_tiling_image_is_seamless_including_the_wrap():
    ts = load_tileset("TL+-")
    t = grow_tiling(ts, (6, 9), periodic=True, rng=4)
    img = tiling_image(t, ts)
    assert img.shape == (120, 180)
    for j in range(9):          # last column of block j against first column of block j+1
        np.testing.assert_array_equal(img[:, 20 * j + 19], img[:, (20 * j + 20) % 180])
    for i in range(6):
        np.testing.assert_array_equal(img[20 * i + 19], img[(20 * i + 20) % 120])
    # the 2 x 2 repetition is seamless too (tiles the plane)
    big = np.tile(img, (2, 2))
    np.testing.assert_array_equal(big[:, 179], big[:, 180])


def test_outline_contours_are_closed():
    ts = load_tileset("TL+-")
    img = tiling_image(grow_tiling(ts, (4, 4), rng=0), ts)
    cs = tiling_outline(img)
    assert cs and all(np.allclose(c[0], c[-1]) for c in cs)


def test_voxel_plus3_volume_matches_tricylinder():
    ts = load_tileset("cubic-beams")
    r = 0.2
    vox = block_voxels(ts.tiles[ts.tile_index("+3@0")], resolution=60, radius=r)
    # union of three perpendicular unit-length cylinders: 3 pi r^2 - 8 sqrt(2) r^3
    exact = 3 * math.pi * r * r - 8 * math.sqrt(2) * r ** 3
    assert vox.mean() == pytest.approx(exact, rel=0.02)


def test_voxel_faces_follow_connectors_and_tiling_layout():
    ts = load_tileset("cubic-beams")
    t = grow_tiling(ts, (2, 3, 4), rng=0)
    v = tiling_voxels(t, ts, resolution=10)
    assert v.shape == (20, 30, 40)
    for idx in np.ndindex(t.shape):
        tile = ts.tiles[t.tiles[idx]]
        k, i, j = (10 * a for a in idx)
        block = v[k:k + 10, i:i + 10, j:j + 10]
        centre = {"+x": block[5, 5, 9], "-x": block[5, 5, 0], "+y": block[5, 9, 5],
                  "-y": block[5, 0, 5], "+z": block[9, 5, 5], "-z": block[0, 5, 5]}
        for face, label in zip(ts.faces, tile.connectors):
            assert bool(centre[face]) == (label == "1"), (tile.name, face)


def test_beams_in_physical_and_unit_coordinates():
    ts = load_tileset("cubic-beams")
    t = grow_tiling(ts, (3, 3, 3), rng=0)
    polys, radii = tiling_beams(t, ts)
    assert len(polys) == sum(len(ts.tiles[k].polylines) for k in t.tiles.ravel())
    allp = np.concatenate(polys)
    assert allp.min() >= 0 and allp.max() <= 15 and set(radii) == {1.0}
    upolys, uradii = tiling_beams(t, ts, normalize=True)
    np.testing.assert_allclose(np.concatenate(upolys), allp / 15)
    assert uradii[0] == pytest.approx(1 / 15)
