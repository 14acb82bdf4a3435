"""The pieces that keep worker threads from holding the GIL long give the same
results, bit for bit, as the single calls they replace (issue 14: window stalls
while exporting).

References are independent of the code under test: one scikit-image call on
the whole grid, trimesh's STL exporter, scipy's connected components.
"""

import numpy as np
import pytest
from skimage.measure import marching_cubes

from engine.geometry import slab_marching as sm
from engine.geometry.marching import drop_specks, periodic_mesh


def _one_call(grid, level):
    v, f, _, _ = marching_cubes(grid, level=level, gradient_direction="descent", allow_degenerate=True)
    return v, f.astype(np.int64)


@pytest.mark.parametrize("budget", [1, 300, 1000, 4000])
def test_small_pieces_give_the_one_call_mesh_bit_for_bit(monkeypatch, budget):
    # a grid of one frame (<= FRAME_CELLS cell layers along x): pieces of 1..n
    # layers must reproduce skimage on the whole grid exactly, order included
    rng = np.random.default_rng(11)
    grid = np.asarray(rng.normal(size=(sm.FRAME_CELLS + 1, 17, 13)), np.float32)
    monkeypatch.setattr(sm, "SLAB_SAMPLES", budget)
    assert sm.slab_cells(grid.shape) < sm.FRAME_CELLS or budget == 4000
    v, f = sm.slab_marching_cubes(grid, 0.1, None)
    v1, f1 = _one_call(grid, 0.1)
    assert v.dtype == v1.dtype and np.array_equal(v, v1) and np.array_equal(f, f1)


def test_piece_size_never_changes_a_long_grid_mesh(monkeypatch):
    # several frames: the mesh is the same for every piece size (bytes of the
    # arrays) and, as a surface, the one call's
    rng = np.random.default_rng(12)
    grid = np.asarray(rng.normal(size=(70, 15, 11)), np.float32)
    meshes = []
    for budget in (1, 500, 2000, 10 ** 9):
        monkeypatch.setattr(sm, "SLAB_SAMPLES", budget)
        meshes.append(sm.slab_marching_cubes(grid, 0.0, None))
    for v, f in meshes[1:]:
        assert np.array_equal(v, meshes[0][0]) and np.array_equal(f, meshes[0][1])
    v1, f1 = _one_call(grid, 0.0)
    v, f = meshes[0]
    assert np.array_equal(f, f1)                          # same triangles in the same order
    assert np.abs(v.astype(np.float64) - v1).max() <= 4 * np.spacing(np.float32(70))


def _periodic_fields():
    x = np.arange(16) / 16
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    # Schwarz P on this grid has many nodes on the level (nudged, so vertices
    # round onto nodes): piece boundaries must fall back to frame boundaries
    schwarz = np.cos(2 * np.pi * X) + np.cos(2 * np.pi * Y) + np.cos(2 * np.pi * Z)
    gyroid = (np.sin(2 * np.pi * X + 0.3) * np.cos(2 * np.pi * Y) + np.sin(2 * np.pi * Y + 0.1)
              * np.cos(2 * np.pi * Z + 0.2) + np.sin(2 * np.pi * Z) * np.cos(2 * np.pi * X + 0.4) - 0.05)
    return {"schwarz_p": schwarz, "gyroid": gyroid}


@pytest.mark.parametrize("name", ["schwarz_p", "gyroid"])
def test_periodic_mesh_is_the_same_for_any_piece_size(monkeypatch, name):
    # a tiled closed block (pad layers, welding of clipped caps, speck removal)
    field = _periodic_fields()[name]
    monkeypatch.setattr(sm, "SLAB_SAMPLES", 10 ** 9)          # one call per frame, as before
    ref = periodic_mesh(field, tiles=(3, 2, 2))
    calls = []
    monkeypatch.setattr(sm, "SLAB_SAMPLES", 200)
    got = periodic_mesh(field, tiles=(3, 2, 2), progress=lambda d, t: calls.append((d, t)) or True)
    assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])
    assert calls[-1][0] == calls[-1][1]
    if name == "gyroid":
        assert calls[-1][1] > 20                                 # many short calls


def test_pieces_end_only_on_planes_clear_of_nodes():
    rng = np.random.default_rng(8)
    grid = np.asarray(rng.normal(size=(49, 12, 12)), np.float32)
    grid[10, 3, 4] = 1e-9                                      # a sample next to the level
    pieces = sm._pieces(grid, 0.0, 1)
    ends = {p1 for _, f1, _, p1 in pieces if p1 != f1}
    assert not ends & {9, 10, 11} and {8, 12} <= ends       # its edges and cells reach planes 9..11
    starts = [p0 for _, _, p0, _ in pieces]
    assert starts[0] == 0 and all(a < b for a, b in zip(starts, starts[1:]))
    assert {(f0, f1) for f0, f1, _, _ in pieces} == {(0, 24), (24, 48)}


def test_take_chunked_is_fancy_indexing():
    rng = np.random.default_rng(3)
    table = rng.normal(size=(50, 3))
    idx = rng.integers(0, 50, size=(1001, 3))
    assert np.array_equal(sm.take_chunked(table, idx, rows=7), table[idx])
    assert np.array_equal(sm.take_chunked(table[:, 0], idx[:, 0], rows=64), table[idx[:, 0], 0])


def _drop_specks_scipy(v, f, min_volume):
    # the reference: scipy's components on the edge graph, whole-array numpy
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    n = len(v)
    rows = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    cols = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    count, label = connected_components(coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n)),
                                        directed=False)
    if count == 1:
        return v, f
    tri = v[f]
    vol6 = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    pv = np.abs(np.bincount(label[f[:, 0]], weights=vol6, minlength=count)) / 6.0
    keep = pv[label[f[:, 0]]] >= min_volume
    if keep.all():
        return v, f
    f = f[keep]
    used = np.zeros(n, bool)
    used[f.ravel()] = True
    return v[used], (np.cumsum(used) - 1)[f]


def test_drop_specks_matches_scipy_components(monkeypatch):
    # many closed pieces of random sizes (tetrahedra), shuffled, plus an unused vertex
    rng = np.random.default_rng(4)
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    unit = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    verts, faces = [], []
    for k in range(300):
        verts.append(unit * rng.uniform(0.01, 1.0) + rng.normal(size=3) * 10)
        faces.append(tet + 4 * k)
    v = np.vstack(verts + [np.zeros((1, 3))])
    perm = rng.permutation(len(v))
    inv = np.argsort(perm)
    v = v[perm]
    f = inv[np.vstack(faces)][rng.permutation(1200)]
    monkeypatch.setattr(sm, "CHUNK_ROWS", 37)
    for min_volume in (1e-3, 0.02, 1.0):
        got, ref = drop_specks(v, f, min_volume), _drop_specks_scipy(v, f, min_volume)
        assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])


def test_vertex_components_labels_pieces_by_smallest_vertex():
    from engine.geometry.mesh_components import vertex_components
    f = np.array([[4, 5, 6], [0, 1, 2], [2, 3, 1], [6, 7, 4]])
    count, label = vertex_components(f, 9)
    assert count == 3 and label.tolist() == [0, 0, 0, 0, 1, 1, 1, 1, 2]


@pytest.mark.parametrize("chunk", [1, 5, 4096])
def test_binary_stl_is_trimesh_bytes(chunk):
    import trimesh
    from engine.geometry.stl_encode import binary_stl
    rng = np.random.default_rng(6)
    v = rng.normal(size=(400, 3))
    f = rng.integers(0, 400, size=(1500, 3))
    f[:20, 2] = f[:20, 0]                     # degenerate faces get a zero normal
    ref = trimesh.Trimesh(v, f, process=False).export(file_type="stl")
    assert bytes(binary_stl(v, f, chunk=chunk)) == ref


def test_export_mesh_stl_bytes_unchanged(tmp_path):
    import trimesh
    from engine.geometry.mesh_io import export_mesh
    x = np.arange(12) / 12
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    v, f = periodic_mesh(np.sin(2 * np.pi * X) * np.cos(2 * np.pi * Y) + np.sin(2 * np.pi * Z), tiles=(2, 1, 1))
    export_mesh(v, f, tmp_path / "a.stl")
    assert (tmp_path / "a.stl").read_bytes() == trimesh.Trimesh(v, f, process=False).export(file_type="stl")


def test_index_of_kept_and_compress_rows_are_the_whole_array_calls():
    rng = np.random.default_rng(9)
    used = rng.random(1003) < 0.3
    assert np.array_equal(sm.index_of_kept(used, rows=17), np.cumsum(used) - 1)
    a = rng.integers(0, 9, size=(1003, 3))
    assert np.array_equal(sm.compress_rows(a, used, rows=50), a[used])
    assert sm.compress_rows(a[:0], used[:0]).shape == (0, 3)
