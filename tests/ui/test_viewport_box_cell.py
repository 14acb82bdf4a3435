"""The viewport tiles a box cell at box offsets and draws its cell box."""

import math

import numpy as np
import pytest

from engine.geometry.values import Solid
from engine.geometry.marching import periodic_mesh
from engine.geometry.sdf_lines import line_sdf_grid
from ui.viewport import Viewport, block_bounds, sphere_placement, tile_offsets

BOX = np.array([1.0, math.sqrt(3.0), 0.8])


def test_tile_offsets_and_bounds_follow_the_box():
    off = tile_offsets(3, 2.0 * BOX)
    assert off.shape == (27, 3)
    np.testing.assert_allclose(np.unique(off[:, 1]), [-2.0 * BOX[1], 0.0, 2.0 * BOX[1]])
    np.testing.assert_allclose(np.unique(off[:, 2]), [-1.6, 0.0, 1.6])
    lo, hi = block_bounds(3, 2.0 * BOX)
    np.testing.assert_allclose(lo, -2.0 * BOX)
    np.testing.assert_allclose(hi, 4.0 * BOX)
    # a cube's edge gives what it always gave
    assert tile_offsets(3, 2.0).tolist() == tile_offsets(3, [2.0, 2.0, 2.0]).tolist()
    assert block_bounds(3, 2.0) == (-2.0, 4.0)
    scale, centre = sphere_placement(3, 2.0 * BOX, 1.0)
    edge = 6.0 * BOX.max()
    assert scale == pytest.approx(0.5 * edge)
    np.testing.assert_allclose(centre, [hi[0] + 0.3 * edge + 0.5 * edge, 0.5 * (lo[1] + hi[1]),
                                        0.5 * (lo[2] + hi[2])])
    assert sphere_placement(3, 2.0, 1.0)[1].tolist() == sphere_placement(3, [2.0] * 3, 1.0)[1].tolist()


def test_viewport_tiles_a_box_solid(qtbot):
    shape = (12, 20, 10)
    sdf = line_sdf_grid([[[0.5, 0.0, 0.4], [0.5, BOX[1], 0.4]]], [0.15], resolution=shape, cell=BOX)
    v, f = periodic_mesh(sdf, cell_size=2.0, cell=BOX)
    solid = Solid(sdf, v, f, 2.0, cell=tuple(BOX))
    view = Viewport()
    qtbot.addWidget(view)
    try:
        view.show_result(solid, None)
        view.set_tiling(3)
        assert view.mesh_point_count() == 27 * len(v)
        assert view.wait_ready()                      # the tiled mesh is prepared off the GUI thread
        assert view.solid_view().partial is False     # every tile drawn, at a coarser level
        bounds = view.solid_view().bounds()
        lo, hi = block_bounds(3, 2.0 * BOX)
        assert bounds[2] == pytest.approx(lo[1]) and bounds[3] == pytest.approx(hi[1])
        assert bounds[0] == pytest.approx(lo[0] + 2.0 * 0.35, abs=0.05)       # strut radius 0.15 at x = 0.5
        cell_box = view.plotter.renderer.actors["cell_box"].GetBounds()
        np.testing.assert_allclose(cell_box, [0, 2.0, 0, 2.0 * BOX[1], 0, 1.6])
        tiling_box = view.plotter.renderer.actors["tiling_box"].GetBounds()
        np.testing.assert_allclose(tiling_box, [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]])
    finally:
        view.close_plotter()
