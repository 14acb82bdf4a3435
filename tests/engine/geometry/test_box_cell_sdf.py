"""Distance-field kernels on an orthorhombic box cell: the fast kernels against
their slow references (wrap-around across the box faces included), the
per-axis grid rule, and the unit cube as before."""

import math

import numpy as np
import pytest

from engine.geometry.box_cell import box_grid_shape, check_cell, default_band
from engine.geometry.sdf_lines import line_sdf_grid, line_sdf_reference
from engine.geometry.sdf_triangles import surface_sdf_grid, surface_sdf_reference

BOX = (1.0, math.sqrt(3.0), 0.8)
SHAPE = (12, 20, 10)          # spacings 0.0833, 0.0866, 0.08


def test_grid_rule_puts_resolution_on_the_longest_edge():
    assert box_grid_shape((1, 1, 1), 96) == (96, 96, 96)
    assert box_grid_shape((1, math.sqrt(3), 1), 96) == (55, 96, 55)       # 96 / sqrt(3) = 55.4
    assert box_grid_shape((2, 1, 0.05), 40) == (40, 20, 8)                # floor of 8 nodes
    assert box_grid_shape((1, 3, 1.5), 30) == (10, 30, 15)


@pytest.mark.parametrize("cell", [(0, 1, 1), (1, -1, 1), (1, 1, 101), (1, 1), (1, np.nan, 1)])
def test_bad_cell_is_refused(cell):
    with pytest.raises(ValueError, match="cell"):
        check_cell(cell)
    with pytest.raises(ValueError, match="cell"):
        line_sdf_grid([[[0.1, 0.1, 0.1], [0.2, 0.2, 0.2]]], [0.05], resolution=8, cell=cell)


def test_unit_cube_is_the_default_bit_for_bit():
    poly = np.array([[0.1, 0.2, 0.3], [0.9, 0.7, 1.2], [1.3, 0.1, 0.6]])
    a = line_sdf_grid([poly], [0.08], resolution=20, method="normal")
    b = line_sdf_grid([poly], [0.08], resolution=(20, 20, 20), cell=(1, 1, 1), method="normal")
    assert np.array_equal(a, b)
    v = np.array([(0.7, 0.2, 0.5), (1.3, 0.3, 0.5), (1.0, 0.8, 0.6)])
    f = np.array([[0, 1, 2]])
    a = surface_sdf_grid(v, f, np.full(3, 0.1), resolution=16, method="normal")
    b = surface_sdf_grid(v, f, np.full(3, 0.1), resolution=(16, 16, 16), cell=[1, 1, 1], method="normal")
    assert np.array_equal(a, b)
    assert default_band((1, 1, 1), (16, 16, 16)) == 3 / 16


@pytest.mark.parametrize("method", ["spherical", "normal"])
def test_strut_crossing_the_y_face_matches_the_reference(method):
    # A bent strut that leaves the box through y = Ly and comes back at y = 0.
    poly = np.array([[0.4, 1.3, 0.3], [0.55, 1.95, 0.45], [0.6, 2.2, 0.4]])
    radii = np.array([0.06, 0.08, 0.07])
    band = 0.08                                      # the reference needs radius + band < min(L) / 4
    fast = line_sdf_grid([poly], [radii], resolution=SHAPE, cell=BOX, method=method, band=band)
    ref = line_sdf_reference([poly], [radii], resolution=SHAPE, cell=BOX, method=method, band=band)
    assert fast.shape == SHAPE
    near = np.abs(ref) < band - 1e-3
    wrapped = np.zeros(SHAPE, bool)
    wrapped[:, :5] = True                            # y < 0.43: only the wrapped part reaches here
    assert (near & wrapped & (ref < 0)).sum() > 5
    assert np.abs(fast - ref)[near].max() < 1e-3
    clear = np.abs(ref) > 1e-3
    assert np.array_equal(fast[clear] < 0, ref[clear] < 0)


def test_straight_strut_through_the_y_faces_is_a_cylinder():
    # Ends meet across the y faces: the periodic field is the infinite cylinder.
    r = 0.15
    field = line_sdf_grid([[[0.5, 0.0, 0.4], [0.5, BOX[1], 0.4]]], [r], resolution=SHAPE, cell=BOX)
    x = np.arange(SHAPE[0]) * BOX[0] / SHAPE[0]
    z = np.arange(SHAPE[2]) * BOX[2] / SHAPE[2]
    rho = np.hypot(x[:, None] - 0.5, z[None, :] - 0.4)
    exact = np.minimum(rho - r, default_band(BOX, SHAPE))
    for j in range(SHAPE[1]):
        np.testing.assert_allclose(field[:, j, :], exact, atol=1e-6)


def _patch_crossing_x():
    """A bent four-triangle patch leaving the box through x = Lx."""
    v = np.array([(0.75, 0.5, 0.3), (1.15, 0.55, 0.35), (1.2, 1.1, 0.5), (0.8, 1.05, 0.45),
                  (0.95, 0.8, 0.55)])
    f = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    return v, f


@pytest.mark.parametrize("method", ["spherical", "normal"])
def test_patch_crossing_the_x_face_matches_the_reference(method):
    v, f = _patch_crossing_x()
    t = np.array([0.1, 0.12, 0.08, 0.1, 0.11])
    fast = surface_sdf_grid(v, f, t, resolution=SHAPE, cell=BOX, method=method)
    ref = surface_sdf_reference(v, f, t, resolution=SHAPE, cell=BOX, method=method)
    assert fast.shape == SHAPE
    near = np.abs(ref) < default_band(BOX, SHAPE)
    assert (near[:3] & (ref[:3] < 0)).sum() > 5      # x < 0.25: the wrapped part
    np.testing.assert_allclose(fast[near], ref[near], atol=1e-6)
    assert np.array_equal(fast < 0, ref < 0)


def test_periodic_shift_by_whole_nodes_is_a_roll_on_a_box():
    v, f = _patch_crossing_x()
    t = np.full(len(v), 0.1)
    base = surface_sdf_grid(v, f, t, resolution=SHAPE, cell=BOX, method="normal")
    step = np.array([3, -5, 2]) * np.array(BOX) / np.array(SHAPE)
    moved = surface_sdf_grid(v + step, f, t, resolution=SHAPE, cell=BOX, method="normal")
    np.testing.assert_allclose(moved, np.roll(base, (3, -5, 2), axis=(0, 1, 2)), atol=1e-6)


def test_int_resolution_on_a_box_uses_the_grid_rule():
    field = line_sdf_grid([[[0.5, 0.0, 0.4], [0.5, 1.0, 0.4]]], [0.1], resolution=24, cell=(1, 2, 0.5))
    assert field.shape == box_grid_shape((1, 2, 0.5), 24) == (12, 24, 8)
