"""Tiling properties against energy bounds and exact solutions that do not use the solver.

Bounds used (E_s = 1, void removed):

* lower: a prismatic bar of solid area fraction A running through the cell
  along x carries the uniaxial stress field sigma_xx = 1/A in the bar, zero
  elsewhere; it is statically admissible, so by complementary energy
  S_11 <= 1/A, i.e. E_x >= A. Finite elements are stiffer than the
  continuum, so the bound holds for them too.
* upper: the displacement u = (f(x), 0[, 0]) with f piecewise linear over
  the pixel / voxel layers lies in the bilinear / trilinear element space;
  minimising its energy gives the series formula
  C_11 <= C11_solid / sum_k (h / A_k), A_k the solid fraction of layer k.
  And E_x = 1 / S_11 <= C_11 for any positive definite C.
"""

import math

import numpy as np
import pytest

from engine.growth import Tiling, grow_tiling, load_tileset, tiling_image, tiling_voxels
from engine.growth.properties import homogenize_tiling, is_singular, tiling_properties


def _uniform(ts, name, shape):
    return Tiling(np.full(shape, ts.tile_index(name), dtype=np.int32), ts.name, True)


def _layer_bound(solid, axis_x, c11_solid):
    """Series upper bound on C_11 from the solid fraction of each layer normal to x."""
    other = tuple(a for a in range(solid.ndim) if a != axis_x)
    A = solid.mean(axis=other)
    h = 1.0 / solid.shape[axis_x]
    return c11_solid / np.sum(h / A), A.min()


def test_square_grid_of_plus_blocks_lies_between_the_energy_bounds():
    ts = load_tileset("TL+-")
    til = _uniform(ts, "+@0", (2, 2))
    nu = 0.46
    p = tiling_properties(til, ts, E=1.0, nu=nu, resolution=20, line_width=4)
    img = tiling_image(til, ts, resolution=20, line_width=4).astype(bool)
    upper, a_bar = _layer_bound(img, 1, 1.0 / (1 - nu ** 2))     # x runs along columns
    assert a_bar == pytest.approx(0.2) and p["density"] == pytest.approx(0.36)
    assert a_bar <= p["E_x"] <= p["C"][0, 0] <= upper
    # square symmetry: the x and y answers agree, no normal-shear coupling
    assert p["E_y"] == pytest.approx(p["E_x"], rel=1e-6)
    assert abs(p["C"][0, 2]) < 1e-8 and abs(p["C"][1, 2]) < 1e-8
    assert p["symmetry"] == "tetragonal" and not p["singular"]
    assert p["E_avg"] == pytest.approx((p["E_x"] + p["E_y"]) / 2)
    assert p["nu_avg"] == pytest.approx((p["nu_xy"] + p["nu_yx"]) / 2)
    assert p["E_avg/E_s"] == p["E_avg"]
    # directional modulus: along the bars it is E_x; at 45 degrees the square grid is soft
    assert p["E_theta"][0] == pytest.approx(p["E_x"], rel=1e-9)
    k45 = len(p["angles"]) // 8
    assert p["angles"][k45] == pytest.approx(math.pi / 4)
    assert p["E_theta"][k45] < 0.2 * p["E_x"]
    assert p["realised_probabilities"] == {"T": 0.0, "L": 0.0, "-": 0.0, "+": 1.0}


def test_simple_cubic_beams_lie_between_the_energy_bounds():
    ts = load_tileset("cubic-beams")
    til = _uniform(ts, "+3@0", (1, 1, 1))
    nu = 0.3
    p = tiling_properties(til, ts, nu=nu, resolution=16, radius=0.2)
    vox = tiling_voxels(til, ts, resolution=16, radius=0.2)          # [z, y, x]
    c11_solid = (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    upper, a_bar = _layer_bound(vox, 2, c11_solid)
    assert a_bar == pytest.approx(math.pi * 0.2 ** 2, rel=0.1)       # voxelized disc
    assert a_bar <= p["E_x"] <= p["C"][0, 0] <= upper
    assert p["symmetry"] == "cubic"
    assert p["E_y"] == pytest.approx(p["E_x"], rel=1e-6)
    assert p["E_z"] == pytest.approx(p["E_x"], rel=1e-6)
    assert p["E_theta"][0] == pytest.approx(p["E_x"], rel=1e-9)
    assert "radius" in p and "line_width" not in p


def test_axes_are_the_tiling_axes_with_y_along_increasing_rows():
    # "\" chords joined into straight lines y = x + 1/2 in tiling coordinates
    # (x = column, y = row index).  Separate parallel lines carry load only
    # along d = (1, 1)/sqrt 2: C = k a a^T with a = (1/2, 1/2, 1/2) -- all
    # entries equal and positive.  Had y pointed up the rows, the line would
    # run along (1, -1) and the shear couplings C13, C23 would be negative.
    ts = load_tileset("TL+-OV\\")
    a, b = ts.tile_index("\\@0"), ts.tile_index("\\@2")
    til = Tiling(np.array([[a, b], [b, a]], dtype=np.int32), ts.name, True)
    C = np.asarray(homogenize_tiling(til, ts).C)
    assert C[0, 0] > 0
    np.testing.assert_allclose(C, np.full((3, 3), C[0, 0]), rtol=1e-3)
    assert is_singular(C)


def test_mechanism_is_reported_not_raised():
    ts = load_tileset("TL+-")
    til = _uniform(ts, "-@0", (1, 1))                 # horizontal bars only
    p = tiling_properties(til, ts, resolution=20, line_width=4)
    assert p["singular"] and p["symmetry"] == "singular"
    assert math.isnan(p["E_avg"]) and np.all(np.isnan(p["E_theta"]))
    # a prismatic bar in uniaxial stress: C11 = E * A exactly (bilinear quads span it)
    assert p["C"][0, 0] == pytest.approx(0.2, rel=1e-6)


def test_soft_void_is_never_softer_than_removed_void():
    # adding material can only stiffen: C_soft - C_removed is positive semidefinite
    ts = load_tileset("TL+-")
    til = grow_tiling(ts, (4, 4), periodic=True, rng=5)
    hard = np.asarray(homogenize_tiling(til, ts, resolution=10, void="removed", tol=1e-9).C)
    soft = np.asarray(homogenize_tiling(til, ts, resolution=10, void="soft", tol=1e-9).C)
    assert np.linalg.eigvalsh(soft - hard).min() > -1e-7 * np.abs(hard).max()
    assert soft[0, 0] > hard[0, 0]


def test_bounded_tilings_are_homogenized_as_sves():
    ts = load_tileset("TL+-")
    til = grow_tiling(ts, (4, 4), periodic=False, rng=2)
    p = tiling_properties(til, ts, resolution=10)
    assert p["periodic_cell"] is False
    assert p["C"].shape == (3, 3)


@pytest.mark.parametrize("kwargs, match", [
    ({"void": "air"}, "void must be one of"),
    ({"resolution": 1}, "resolution must be"),
    ({"line_width": 30}, "line_width must be"),
    ({"n_angles": 0}, "n_angles must be"),
])
def test_bad_options_are_refused_by_name(kwargs, match):
    ts = load_tileset("TL+-")
    til = _uniform(ts, "+@0", (1, 1))
    with pytest.raises(ValueError, match=match):
        tiling_properties(til, ts, **kwargs)


def test_non_cubic_3d_tiling_and_foreign_tileset_are_refused():
    ts3 = load_tileset("cubic-beams")
    til = _uniform(ts3, "+3@0", (1, 1, 2))
    with pytest.raises(ValueError, match="cubic tiling"):
        homogenize_tiling(til, ts3)
    with pytest.raises(ValueError, match="grown from tile set"):
        homogenize_tiling(til, load_tileset("TL+-"))
