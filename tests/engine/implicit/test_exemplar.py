"""Exemplars: the eq. 37 sampling, voxel grids, occupancy conversion and file round trips."""

import json
from dataclasses import dataclass

import numpy as np
import pytest

from engine.implicit.exemplar import Exemplar, load_exemplar, occupancy_to_sdf
from engine.implicit.values import SDF, as_points


@dataclass(frozen=True, eq=False)
class _Plane(SDF):
    """x - a (exact)."""
    a: float = 0.0

    def field(self, points):
        return as_points(points)[:, 0] - self.a


@dataclass(frozen=True, eq=False)
class _Ball(SDF):
    centre: tuple = (0.0, 0.0, 0.0)
    r: float = 1.0

    def field(self, points):
        return np.linalg.norm(as_points(points) - np.asarray(self.centre), axis=1) - self.r


def _rot_z(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def test_from_sdf_is_an_equidistant_grid_in_c_order():
    ex = Exemplar.from_sdf(_Plane(0.2), (1.0, 2.0, 3.0), 2.0, (4, 5, 6))
    assert ex.shape == (4, 5, 6) and ex.points.shape == (120, 3)
    for i, j, k in [(0, 0, 0), (3, 4, 5), (1, 2, 3), (2, 0, 5)]:
        row = (i * 5 + j) * 6 + k
        expect = np.array([1.0 - 1 + 2 * i / 3, 2.0 - 1 + 2 * j / 4, 3.0 - 1 + 2 * k / 5])
        np.testing.assert_allclose(ex.points[row], expect, atol=1e-14)
        assert ex.grid()[i, j, k] == pytest.approx(expect[0] - 0.2)


def test_rotation_about_the_centre():
    c = np.array([0.5, -1.0, 2.0])
    plain = Exemplar.from_sdf(_Plane(), c, 3.0, 5)
    rot = Exemplar.from_sdf(_Plane(), c, 3.0, 5, rotation=_rot_z(0.7))
    np.testing.assert_allclose(rot.points - c, (plain.points - c) @ _rot_z(0.7).T, atol=1e-13)
    # a ball centred at the cube's centre sees the same distances however it is turned
    ball = _Ball(tuple(c), 0.8)
    a = Exemplar.from_sdf(ball, c, 3.0, 6)
    b = Exemplar.from_sdf(ball, c, 3.0, 6, rotation=_rot_z(1.3))
    np.testing.assert_allclose(a.distances, b.distances, atol=1e-12)
    np.testing.assert_allclose(a.distances, np.linalg.norm(a.points - c, axis=1) - 0.8, atol=1e-14)


def test_gaussian_noise_on_positions_seeded():
    base = Exemplar.from_sdf(_Plane(), (0, 0, 0), 2.0, 16)
    a = Exemplar.from_sdf(_Plane(), (0, 0, 0), 2.0, 16, noise_sd=0.01, seed=4)
    b = Exemplar.from_sdf(_Plane(), (0, 0, 0), 2.0, 16, noise_sd=0.01, seed=4)
    c = Exemplar.from_sdf(_Plane(), (0, 0, 0), 2.0, 16, noise_sd=0.01, seed=5)
    noise = a.points - base.points
    assert np.std(noise) == pytest.approx(0.01, rel=0.03)
    assert abs(np.mean(noise)) < 1e-3
    assert a.points.tobytes() == b.points.tobytes()
    assert not np.array_equal(a.points, c.points)
    np.testing.assert_allclose(a.distances, a.points[:, 0], atol=1e-15)   # evaluated at the perturbed points


@pytest.mark.parametrize("kw, word", [
    (dict(resolution=3), "resolution"), (dict(size=0.0), "size"), (dict(noise_sd=-0.1), "noise_sd"),
    (dict(rotation=np.diag([1.0, 1.0, -1.0])), "rotation"), (dict(rotation=2 * np.eye(3)), "rotation"),
    (dict(seed=-1), "seed"), (dict(centre=(0, 0)), "centre")])
def test_from_sdf_refuses(kw, word):
    args = dict(centre=(0, 0, 0), size=1.0, resolution=5)
    args.update(kw)
    with pytest.raises(ValueError, match=word):
        Exemplar.from_sdf(_Plane(), **args)


def test_from_voxels_positions_and_values():
    a = np.random.default_rng(2).normal(size=(4, 5, 6))
    ex = Exemplar.from_voxels(a, spacing=(0.5, 0.25, 2.0), origin=(1, 2, 3))
    np.testing.assert_array_equal(ex.grid(), a)
    assert ex.points[(2 * 5 + 3) * 6 + 4].tolist() == [2.0, 2.75, 11.0]


def test_occupancy_of_a_half_space_is_an_exact_plane():
    occ = np.zeros((20, 6, 7), dtype=bool)
    occ[:10] = True                              # solid for x index <= 9, surface at 9.5
    for spacing in (1.0, 0.3):
        d = Exemplar.from_voxels(occ, spacing).grid()
        expect = (np.arange(20) - 9.5) * spacing
        np.testing.assert_allclose(d, np.broadcast_to(expect[:, None, None], d.shape), atol=1e-12)
    # 0/1 integers and 0/255 masks are occupancy too
    np.testing.assert_allclose(Exemplar.from_voxels(occ.astype(np.uint8) * 255).grid(),
                               Exemplar.from_voxels(occ.astype(float)).grid())


def test_occupancy_of_a_ball_is_near_its_distance():
    n, r = 33, 9.0
    g = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), axis=-1) - 16.0
    exact = np.linalg.norm(g, axis=-1) - r
    d = occupancy_to_sdf(exact < 0)
    near = np.abs(exact) < 3
    assert np.max(np.abs(d - exact)[near]) < 1.0      # within a voxel near the surface
    assert np.all(np.sign(d) == np.where(exact < 0, -1, 1))


@pytest.mark.parametrize("array, word", [
    (np.zeros((5, 5)), "3D"), (np.zeros((3, 8, 8)), "at least 4"),
    (np.full((5, 5, 5), np.nan), "NaN"), (np.ones((5, 5, 5), dtype=bool), "all solid")])
def test_from_voxels_refuses(array, word):
    with pytest.raises(ValueError, match=word):
        Exemplar.from_voxels(array)


def _sample_grid():
    return np.random.default_rng(9).normal(size=(6, 5, 4)).astype(np.float32)


def test_npy_round_trip_with_sidecar(tmp_path):
    a = _sample_grid()
    np.save(tmp_path / "a.npy", a)
    ex = load_exemplar(tmp_path / "a.npy")
    np.testing.assert_array_equal(ex.grid(), a)
    assert ex.points[-1].tolist() == [5.0, 4.0, 3.0]
    np.save(tmp_path / "b.npy", a)
    (tmp_path / "b.json").write_text(json.dumps({"spacing": [0.5, 1.0, 2.0], "origin": [1, 0, -1]}))
    ex = load_exemplar(tmp_path / "b.npy")
    assert ex.points[-1].tolist() == [3.5, 4.0, 5.0]


def test_vti_round_trip(tmp_path):
    import pyvista
    a = _sample_grid()
    img = pyvista.ImageData(dimensions=a.shape, spacing=(0.5, 0.25, 2.0), origin=(1.0, 2.0, 3.0))
    img.point_data["sdf"] = a.ravel(order="F")
    img.save(tmp_path / "a.vti")
    ex = load_exemplar(tmp_path / "a.vti")
    np.testing.assert_array_equal(ex.grid(), a)
    np.testing.assert_allclose(ex.points[(2 * 5 + 3) * 4 + 1], [2.0, 2.75, 5.0])


def test_tif_round_trip(tmp_path):
    import tifffile
    a = _sample_grid()
    tifffile.imwrite(tmp_path / "a.tif", np.transpose(a, (2, 1, 0)), photometric="minisblack")  # pages: z
    ex = load_exemplar(tmp_path / "a.tif")
    np.testing.assert_array_equal(ex.grid(), a)
    mask = np.zeros((8, 9, 10), dtype=np.uint8)
    mask[:, :, :4] = 255                                                  # solid for x index < 4
    tifffile.imwrite(tmp_path / "m.tiff", mask, photometric="minisblack")
    d = load_exemplar(tmp_path / "m.tiff").grid()
    np.testing.assert_allclose(d[:, 0, 0], np.arange(10) - 3.5)


def test_bad_files_named(tmp_path):
    np.save(tmp_path / "flat.npy", np.zeros((8, 8)))
    np.save(tmp_path / "thin.npy", np.zeros((8, 3, 8)))
    bad = np.zeros((5, 5, 5))
    bad[2, 2, 2] = np.nan
    np.save(tmp_path / "nan.npy", bad)
    (tmp_path / "junk.vti").write_text("not a vti file")
    for name, word in [("flat.npy", "3D"), ("thin.npy", "at least 4"), ("nan.npy", "NaN"),
                       ("none.npy", "no such file"), ("a.stl", "unknown exemplar format"),
                       ("junk.vti", "cannot read")]:
        with pytest.raises(ValueError, match=word) as info:
            load_exemplar(tmp_path / name)
        assert name in str(info.value)
