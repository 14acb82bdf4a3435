"""A 3D tiling seen layer by layer: projections of real cubic beam blocks."""

import numpy as np
import pytest

from engine.growth import DEFECT, UNASSIGNED, grow_tiling, load_tileset
from engine.growth.layers import (ARM_DOWN, ARM_UP, BEAM, NOT_GROWN, VOID, layer_image,
                                  tile_projections, tiling_layer)


@pytest.fixture(scope="module")
def cubic():
    return load_tileset("cubic_beams")


def test_layers_index_the_grid():
    tiles = np.arange(2 * 3 * 4).reshape(2, 3, 4)
    np.testing.assert_array_equal(tiling_layer(tiles, "z", 1), tiles[1])
    np.testing.assert_array_equal(tiling_layer(tiles, "y", 2), tiles[:, 2, :])
    np.testing.assert_array_equal(tiling_layer(tiles, "x", 3), tiles[:, :, 3])
    with pytest.raises(ValueError, match="layer index"):
        tiling_layer(tiles, "x", 4)
    with pytest.raises(ValueError, match="axis"):
        tiling_layer(tiles, "w", 0)


def _pixel_uv(n):
    u = (np.arange(n) + 0.5) / n
    return np.meshgrid(u, u)   # (u along columns, v along rows)


def test_a_straight_beam_projects_to_a_line_or_a_point(cubic):
    n, lw = 20, 4.0
    k = cubic.tile_names.index("-3@0")               # arms +x and -x
    arms = {tuple(np.sign(p[1] - p[0]).astype(int)) for p in cubic.tiles[k].polylines}
    assert arms == {(1, 0, 0), (-1, 0, 0)}
    u, v = _pixel_uv(n)
    half = lw / 2 / n
    for axis in ("z", "y"):                            # x runs along the columns: a line
        img = tile_projections(cubic, axis, resolution=n, line_width=lw)[k]
        np.testing.assert_array_equal(img == BEAM, np.abs(v - 0.5) < half)
    img = tile_projections(cubic, "x", resolution=n, line_width=lw)[k]
    d = np.hypot(u - 0.5, v - 0.5)                     # along the normal: a point, both ways
    assert np.all(img[d < 1.5 * half] == ARM_UP)
    assert np.all(img[(d >= 1.5 * half) & (d < 2.6 * half)] == ARM_DOWN)
    assert np.all(img[d >= 2.6 * half] == VOID)


def test_a_tripod_shows_one_arm_up_per_plane(cubic):
    k = cubic.tile_names.index("Y3@0")               # arms +x, +y, +z
    for axis in ("z", "y", "x"):
        img = tile_projections(cubic, axis, resolution=20)[k]
        assert (img == ARM_UP).any() and not (img == ARM_DOWN).any()
        # the two in-plane arms run from the centre to the +column and +row edges
        assert img[10, -1] == BEAM and img[-1, 10] == BEAM
        assert img[10, 0] == VOID and img[0, 10] == VOID


def test_layers_of_a_grown_tiling(cubic):
    t = grow_tiling(cubic, (4, 5, 6), rng=2)
    n = 8
    proj = tile_projections(cubic, "z", resolution=n)
    images = [layer_image(t.tiles, cubic, "z", z, resolution=n) for z in range(4)]
    for z, img in enumerate(images):
        assert img.shape == (5 * n, 6 * n)
        for i in range(5):
            for j in range(6):
                tile = t.tiles[z, i, j]
                block = img[i * n:(i + 1) * n, j * n:(j + 1) * n]
                if tile >= 0:
                    np.testing.assert_array_equal(block, proj[tile])
                else:
                    assert np.all(block == VOID)
    assert len({img.tobytes() for img in images}) == 4
    side = layer_image(t.tiles, cubic, "x", 0, resolution=n)
    assert side.shape == (4 * n, 5 * n)


def test_unassigned_cells_are_marked(cubic):
    t = grow_tiling(cubic, (2, 3, 3), rng=1, max_steps=4)
    tiles = np.array(t.tiles)
    assert (tiles == UNASSIGNED).any()
    img = layer_image(tiles, cubic, "z", 1, resolution=4)
    cells = img.reshape(3, 4, 3, 4).transpose(0, 2, 1, 3)
    for (i, j), tile in np.ndenumerate(tiles[1]):
        assert np.all(cells[i, j] == NOT_GROWN) == (tile == UNASSIGNED)
    tiles[0, 0, 0] = DEFECT
    assert np.all(layer_image(tiles, cubic, "z", 0, resolution=4)[:4, :4] == VOID)
