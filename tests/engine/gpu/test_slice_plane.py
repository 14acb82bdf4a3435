import numpy as np
import pytest

from engine.gpu.slice_plane import SlicePlane
from engine.phasor.noise import SliceGrid


@pytest.mark.parametrize("axis, cols, rows", [("x", 1, 2), ("y", 0, 2), ("z", 0, 1), (2, 0, 1)])
def test_axis_aligned_pixel_centres(axis, cols, rows):
    plane = SlicePlane.axis_aligned(axis, 3.0, 0.5, ((1.0, 3.0), (-1.0, 0.5)))
    assert plane.shape == (3, 4)
    p = plane.points()
    a = {"x": 0, "y": 1, "z": 2}.get(axis, axis)
    assert np.all(p[..., a] == 3.0)
    np.testing.assert_allclose(p[0, :, cols], [1.25, 1.75, 2.25, 2.75])
    np.testing.assert_allclose(p[:, 0, rows], [-0.75, -0.25, 0.25])


def test_same_pixels_as_the_reference_slice_grid():
    plane = SlicePlane.axis_aligned("y", 2.0, 0.3, ((0.0, 3.0), (1.0, 2.5)))
    grid = SliceGrid.axis_aligned("y", 2.0, 0.3, ((0.0, 3.0), (1.0, 2.5)))
    np.testing.assert_allclose(plane.points(), grid.points(), atol=1e-12)
    oblique = SlicePlane([1.0, 0.0, 0.0], [0, 3.0, 4.0], [1.0, 0, 0], (5.0, 2.0), (10, 4))
    np.testing.assert_allclose(oblique.pixel_u, [0, 0.3, 0.4])
    np.testing.assert_allclose(oblique.points()[1, 2], [1.0 + 1.5 * 0.5, 2.5 * 0.3, 2.5 * 0.4])


def test_arrays_are_read_only():
    plane = SlicePlane.axis_aligned("z", 0.0, 1.0, ((0, 2), (0, 2)))
    with pytest.raises(ValueError):
        plane.origin[0] = 1.0


@pytest.mark.parametrize("args, match", [
    (([0, 0, 0], [1, 0, 0], [1, 1, 0], (1, 1), (2, 2)), "orthogonal"),
    (([0, 0, 0], [0, 0, 0], [0, 1, 0], (1, 1), (2, 2)), "u_axis"),
    (([0, 0, 0], [1, 0, 0], [0, 1, 0], (1, -1), (2, 2)), "size"),
    (([0, 0, 0], [1, 0, 0], [0, 1, 0], (1, 1), (2, 0)), "resolution"),
    (([0, np.nan, 0], [1, 0, 0], [0, 1, 0], (1, 1), (2, 2)), "origin"),
])
def test_bad_planes_are_refused(args, match):
    with pytest.raises(ValueError, match=match):
        SlicePlane(*args)


def test_bad_axis_aligned_arguments_are_refused():
    with pytest.raises(ValueError, match="axis"):
        SlicePlane.axis_aligned("w", 0.0, 1.0, ((0, 1), (0, 1)))
    with pytest.raises(ValueError, match="pixel_size"):
        SlicePlane.axis_aligned("z", 0.0, 0.0, ((0, 1), (0, 1)))
    with pytest.raises(ValueError, match="extent"):
        SlicePlane.axis_aligned("z", 0.0, 1.0, ((1, 0), (0, 1)))
