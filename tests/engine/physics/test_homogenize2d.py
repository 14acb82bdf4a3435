"""2D plane-stress pixel homogenization against closed forms and a direct solve."""

import numpy as np
import pytest

from engine.physics import periodic_fe
from engine.physics.homogenize2d import homogenize_pixels
from engine.physics.reference_solvers import homogenize_direct

from .test_homogenize3d import laminate, plane_stress, rel_err


@pytest.fixture
def multigrid_on_small_grids(monkeypatch):
    monkeypatch.setattr(periodic_fe, "MAX_COARSE_DOFS", {2: 60, 3: 100})


def _internal(image):
    """The solver's grid for the reference: axis 0 = x (columns), axis 1 = y
    (rows counted upward from the bottom row)."""
    return np.ascontiguousarray(np.asarray(image, float)[::-1, :].T)


@pytest.mark.parametrize("E, nu", [(1.0, 0.45), (70.0, 0.33)])
def test_solid_cell_gives_plane_stress_stiffness(E, nu):
    r = homogenize_pixels(np.ones((7, 5)), E=E, nu=nu)
    assert r.C.shape == (3, 3) and r.shape == (7, 5)
    assert rel_err(r.C, plane_stress(E, nu)) < 1e-9


@pytest.mark.parametrize("stack", ["columns", "rows"])
def test_two_material_laminate(stack, multigrid_on_small_grids):
    ny, nx, k = 24, 20, 7
    img = np.full((ny, nx), 0.3)
    if stack == "columns":          # layers side by side along x
        img[:, :k] = 1.0
        normal, f = 0, k / nx
    else:                           # layers on top of each other along y
        img[:k, :] = 1.0
        normal, f = 1, k / ny
    r = homogenize_pixels(img, E=3.0, nu=0.45)
    ref = laminate([plane_stress(3.0, 0.45), plane_stress(0.9, 0.45)], [f, 1 - f], normal, dim=2)
    assert r.levels >= 3
    np.testing.assert_allclose(r.C, ref, rtol=1e-6, atol=1e-9 * np.abs(ref).max())


def test_soft_void_laminate(multigrid_on_small_grids):
    img = np.zeros((16, 16))
    img[:, 3:9] = 1.0
    r = homogenize_pixels(img, nu=0.3, void_modulus=1e-3)
    ref = laminate([plane_stress(1.0, 0.3), plane_stress(1e-3, 0.0)], [6 / 16, 10 / 16], 0, dim=2)
    np.testing.assert_allclose(r.C, ref, rtol=1e-6, atol=1e-9 * np.abs(ref).max())


def test_axes_convention_y_points_up():
    """A strut drawn from the bottom-left to the top-right of the image runs
    along (1, 1) with y up: stretching along (1, 1) is stiffer than along
    (1, -1), i.e. C[xx,xy] + C[yy,xy] > 0."""
    n = 32
    row, col = np.mgrid[0:n, 0:n]
    img = (((row + col) % n) < 5).astype(float)      # anti-diagonal band in array terms
    C = homogenize_pixels(img, nu=0.3).C
    assert C[0, 2] + C[1, 2] > 0.05 * C[0, 0]
    C_flipped = homogenize_pixels(img[::-1], nu=0.3).C
    assert C_flipped[0, 2] + C_flipped[1, 2] < -0.05 * C[0, 0]


def test_square_symmetric_cell():
    n = 64
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n
    img = (np.hypot(x - 0.5, y - 0.5) > 0.32).astype(float)
    C = homogenize_pixels(img, nu=0.3).C
    assert abs(C[0, 0] - C[1, 1]) < 1e-6 * C[0, 0]
    assert abs(C[0, 2]) < 1e-6 * C[0, 0] and abs(C[1, 2]) < 1e-6 * C[0, 0]
    assert np.linalg.eigvalsh(C).min() > 0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_cells_match_direct_solve(seed, multigrid_on_small_grids):
    img = (np.random.default_rng(seed).random((24, 20)) < 0.6).astype(float)
    r = homogenize_pixels(img, nu=0.45)
    assert r.levels >= 3
    assert rel_err(r.C, homogenize_direct(_internal(img), nu=0.45, method="pinv")) < 1e-6


def test_graded_and_soft_void_cells_match_direct_solve(multigrid_on_small_grids):
    rng = np.random.default_rng(9)
    img = rng.uniform(0.1, 1.0, (30, 26))
    r = homogenize_pixels(img, nu=0.3)
    assert rel_err(r.C, homogenize_direct(_internal(img), nu=0.3, method="lu")) < 1e-6
    img = (rng.random((24, 24)) < 0.4).astype(float)
    r = homogenize_pixels(img, nu=0.3, void_modulus=1e-3)
    ref = homogenize_direct(_internal(img), nu=0.3, void_modulus=1e-3, method="lu")
    assert rel_err(r.C, ref) < 1e-6


def test_floating_islands_dropped(multigrid_on_small_grids):
    img = np.zeros((32, 32))
    img[:, 2:5] = 1.0
    img[10:13, :] = 1.0
    with_islands = img.copy()
    with_islands[20:25, 15:20] = 1.0
    with_islands[28, 28] = 0.5
    a, b = homogenize_pixels(img), homogenize_pixels(with_islands)
    assert b.dropped_fraction == pytest.approx((25 + 0.5) / 1024)
    assert rel_err(b.C, a.C) < 1e-8


def test_only_islands_refused():
    img = np.zeros((12, 12))
    img[3:5, 3:5] = 1.0
    with pytest.raises(ValueError, match="percolat"):
        homogenize_pixels(img)


@pytest.mark.parametrize("image, match", [
    (np.full((5, 5), np.nan), "NaN"), (np.full((5, 5), 2.0), r"\[0, 1\]"),
    (np.zeros((5, 5)), "empty"), (np.ones((5, 5, 5)), "2D"), (np.ones((1, 5)), "at least 2"),
])
def test_bad_image_refused(image, match):
    with pytest.raises(ValueError, match=match):
        homogenize_pixels(image)


def test_bad_material_refused():
    with pytest.raises(ValueError, match="nu must"):
        homogenize_pixels(np.ones((4, 4)), nu=0.5)
    with pytest.raises(ValueError, match="E must"):
        homogenize_pixels(np.ones((4, 4)), E=-1.0)
