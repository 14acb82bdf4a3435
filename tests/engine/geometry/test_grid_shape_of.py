"""grid_shape_of: the grid's shape from the file header, matching what load_voxel_grid returns."""

import numpy as np
import pytest

from engine.geometry.voxel_inputs import grid_shape_of, load_voxel_grid


def test_header_shapes_match_the_loaded_grids(tmp_path):
    import pyvista as pv
    from PIL import Image

    a = np.zeros((5, 6, 7))
    a[1:4, 1:5, 1:6] = 1
    np.save(tmp_path / "a.npy", a)
    Image.fromarray(np.where(a[:, :, 3] > 0, 0, 255).astype(np.uint8)).save(tmp_path / "a.png")
    img = pv.ImageData(dimensions=(7, 6, 5))
    img.point_data["rho"] = a.transpose(2, 1, 0).ravel()   # x fastest
    img.save(tmp_path / "a.vti")
    for name in ("a.npy", "a.png", "a.vti"):
        shape = grid_shape_of(tmp_path / name)
        grid, _, _ = load_voxel_grid(tmp_path / name)
        assert np.prod(shape) >= grid.size and len(shape) == grid.ndim, name
    assert grid_shape_of(tmp_path / "a.npy") == (5, 6, 7)
    assert grid_shape_of(tmp_path / "a.png") == (5, 6)


def test_unknown_or_missing_files_give_none_and_meshes_their_res(tmp_path):
    assert grid_shape_of(tmp_path / "missing.npy") is None
    (tmp_path / "bad.npy").write_bytes(b"not an array")
    assert grid_shape_of(tmp_path / "bad.npy") is None
    (tmp_path / "m.stl").write_bytes(b"")
    assert grid_shape_of(tmp_path / "m.stl", res=40) == (40, 40, 40)
    assert grid_shape_of(tmp_path / "m.stl") == (100, 100, 100)


@pytest.mark.parametrize("n", [1000])
def test_a_huge_npy_is_measured_without_reading_it(tmp_path, n):
    path = tmp_path / "huge.npy"
    np.lib.format.open_memmap(path, mode="w+", dtype=np.uint8, shape=(n, n, n))
    assert grid_shape_of(path) == (n, n, n)
