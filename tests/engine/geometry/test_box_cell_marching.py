"""periodic_mesh on a box cell: per-axis spacing, tiles at box offsets, closed."""

import math

import numpy as np
import pytest
import trimesh

from engine.geometry.marching import boundary_section_match, mesh_volume, periodic_mesh
from engine.geometry.sdf_lines import line_sdf_grid

BOX = (1.0, math.sqrt(3.0), 0.8)


def _strut_field(shape=(24, 40, 20)):
    # A strut whose ends meet across the y faces plus one crossing x and z.
    return np.minimum(
        line_sdf_grid([[[0.5, 0.0, 0.4], [0.5, BOX[1], 0.4]]], [0.15], resolution=shape, cell=BOX),
        line_sdf_grid([[[0.7, 0.9, 0.6], [1.3, 0.9, 1.0]]], [0.1], resolution=shape, cell=BOX))


def test_single_cell_spans_the_box_and_tiles():
    field = _strut_field()
    v, f = periodic_mesh(field, cell_size=2.0, cell=BOX)
    box_mm = 2.0 * np.array(BOX)
    assert np.all(v.min(axis=0) >= 0) and np.all(v.max(axis=0) <= box_mm + 1e-12)
    assert np.isclose(v[:, 1].max(), box_mm[1])         # the strut meets the y faces
    assert trimesh.Trimesh(v, f, process=False).is_watertight
    assert boundary_section_match(v, f, cell_size=2.0, cell=BOX) < 1e-9
    # on the unit-cube period the faces do not pair up
    assert boundary_section_match(v, f, cell_size=2.0) > 1e-3


@pytest.mark.parametrize("tiles", [(2, 1, 1), (1, 2, 1), (1, 1, 3)])
def test_tiles_are_placed_at_box_offsets(tiles):
    field = _strut_field()
    v1, f1 = periodic_mesh(field, cell_size=2.0, cell=BOX)
    vt, ft = periodic_mesh(field, cell_size=2.0, cell=BOX, tiles=tiles)
    extent = 2.0 * np.array(BOX) * np.array(tiles)
    assert np.all(vt.min(axis=0) >= 0) and np.all(vt.max(axis=0) <= extent + 1e-9)
    assert trimesh.Trimesh(vt, ft, process=False).is_watertight
    assert mesh_volume(vt, ft) == pytest.approx(np.prod(tiles) * mesh_volume(v1, f1), rel=1e-6)   # float32 vertex positions
    # the last tile is the first one moved by (tiles - 1) box edges
    shift = 2.0 * np.array(BOX) * (np.array(tiles) - 1)
    axis = int(np.argmax(tiles))
    edge, x = 2.0 * BOX[axis], vt[:, axis]
    first = vt[(x > 1e-9) & (x < edge - 1e-9)]                   # inside the first tile
    last = vt[(x > shift[axis] + 1e-9) & (x < shift[axis] + edge - 1e-9)] - shift
    from scipy.spatial import cKDTree
    assert len(first) == len(last) > 100
    assert cKDTree(first).query(last)[0].max() < 1e-5            # float32 vertex positions


def test_cell_none_is_the_unit_cube_bit_for_bit():
    field = line_sdf_grid([[[0.1, 0.2, 0.3], [0.9, 0.7, 1.2]]], [0.12], resolution=24)
    a = periodic_mesh(field, cell_size=3.0, tiles=(2, 1, 1))
    b = periodic_mesh(field, cell_size=3.0, tiles=(2, 1, 1), cell=(1, 1, 1))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_bad_cell_is_refused():
    with pytest.raises(ValueError, match="cell"):
        periodic_mesh(_strut_field((8, 8, 8)), cell=(1, 0, 1))


def test_box_edges_weld_where_the_last_node_plane_misses_the_face_by_an_ulp():
    # A strut along y in the plane z = 0 of the box (1, 1.732051, 0.8) (the
    # hexagonal cell as typed) crosses the box edge y = Ly, z = 0; there its
    # caps on the y and z faces meet. With 48 nodes, Ly / 48 * 48 misses Ly by
    # an ulp. Merging vertices by position (what an STL reader does) must
    # leave every edge on two faces.
    box, shape = (1.0, 1.732051, 0.8), (28, 48, 22)
    assert box[1] / 48 * 48 != box[1]
    field = line_sdf_grid([[[0.5, 0.0, 0.0], [0.5, box[1], 0.0]]], [0.12], resolution=shape, cell=box)
    v, f = periodic_mesh(field, cell=box)
    _, merged = np.unique(np.round(v, 9), axis=0, return_inverse=True)
    faces = merged.ravel()[f]
    edges = np.sort(np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    assert np.all(uses == 2)
