"""Pictures of RD fields: slices, glyphs, streamlines and brush stamps against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from engine.rd.preview import (glyph_segments, grid_slice, principal_glyphs, principal_streamlines,
                               rescale_index, slice_point, slice_shape, stroke_centres)


def coded_grid(nz=4, ny=5, nx=6):
    z, y, x = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    return 100 * z + 10 * y + x


def rotation_2d(theta):
    """(..., 2, 2) rotations whose first column is (cos theta, sin theta)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def test_slices_of_a_coded_grid_follow_the_axis_convention():
    a = coded_grid()
    # normal z: (u, v) = (x, y); normal y: (x, z); normal x: (y, z); images indexed [v, u]
    for axis, k, code in (("z", 2, lambda u, v: 200 + 10 * v + u),
                          ("y", 3, lambda u, v: 100 * v + 30 + u),
                          ("x", 4, lambda u, v: 100 * v + 10 * u + 4)):
        s = grid_slice(a, axis, k)
        assert s.shape == slice_shape(a.shape, axis)
        v, u = np.meshgrid(np.arange(s.shape[0]), np.arange(s.shape[1]), indexing="ij")
        assert np.array_equal(s, code(u, v))
    flat = np.arange(12).reshape(3, 4)
    assert grid_slice(flat, "z", 0) is not None and np.array_equal(grid_slice(flat), flat)
    with pytest.raises(ValueError, match="2D grid"):
        grid_slice(flat, "x", 0)
    with pytest.raises(ValueError, match=r"index along y must be in \[0, 4\]"):
        grid_slice(a, "y", 5)


def test_slice_points_and_layer_rescaling():
    assert np.allclose(slice_point(1.5, 2.5), [1.5, 2.5])
    assert np.allclose(slice_point(1.5, 2.5, "z", 3), [1.5, 2.5, 3.5])
    assert np.allclose(slice_point(1.5, 2.5, "y", 3), [1.5, 3.5, 2.5])
    assert np.allclose(slice_point(1.5, 2.5, "x", 3), [3.5, 1.5, 2.5])
    # layer 5 of 16 has its centre at 5.5 / 16 of the span: layer 16 of 48 (16.5)
    assert rescale_index(5, 16, 48) == 16
    assert rescale_index(47, 48, 16) == 15 and rescale_index(0, 48, 16) == 0


def test_glyphs_follow_the_first_principal_direction_at_their_cells():
    ny, nx = 16, 32
    y, x = np.meshgrid(np.arange(ny) + 0.5, np.arange(nx) + 0.5, indexing="ij")
    theta = 0.1 * x - 0.07 * y
    R = rotation_2d(theta)
    mag = np.hypot(x, y)
    mask = x < 20
    g = principal_glyphs(R, magnitude=mag, mask=mask, count=8)
    assert len(g.centres) > 10
    assert np.all(g.centres[:, 0] < 20)
    for (u, v), vec, value in zip(g.centres, g.vectors, g.values):
        t = 0.1 * u - 0.07 * v                   # the centre is the cell centre
        assert np.allclose(vec, [np.cos(t), np.sin(t)])
        assert value == pytest.approx(np.hypot(u, v))
    second = principal_glyphs(R, direction=1, count=8)
    for (u, v), vec in zip(second.centres, second.vectors):
        t = 0.1 * u - 0.07 * v
        assert np.allclose(vec, [-np.sin(t), np.cos(t)])
    seg = glyph_segments(g.centres[:1], g.vectors[:1], 2.0)
    assert np.allclose(seg[0, 1] - seg[0, 0], 2.0 * g.vectors[0])


def test_glyphs_of_a_3d_slice_show_the_in_plane_part():
    nz, ny, nx = 6, 8, 10
    z, y, x = np.meshgrid(np.arange(nz) + 0.5, np.arange(ny) + 0.5, np.arange(nx) + 0.5, indexing="ij")
    theta = 0.2 * x + 0.3 * z
    c, s = np.cos(theta), np.sin(theta)
    R = np.zeros((nz, ny, nx, 3, 3))
    R[..., 0, 0], R[..., 1, 0] = c, s            # column 0 = (cos, sin, 0): about z
    R[..., 0, 1], R[..., 1, 1] = -s, c
    R[..., 2, 2] = 1.0
    g = principal_glyphs(R, axis="y", index=3, count=5)
    for (u, v), vec in zip(g.centres, g.vectors):   # (u, v) = (x, z): in-plane part (cos, 0)
        assert np.allclose(vec, [np.cos(0.2 * u + 0.3 * v), 0.0])
    g = principal_glyphs(R, axis="x", index=2, count=5)
    for (u, v), vec in zip(g.centres, g.vectors):   # (u, v) = (y, z): (sin, 0) at x = 2.5
        assert np.allclose(vec, [np.sin(0.2 * 2.5 + 0.3 * v), 0.0])


def test_streamlines_of_a_uniform_field_are_straight_and_of_a_circular_field_round():
    ny, nx = 40, 40
    R = rotation_2d(np.full((ny, nx), np.radians(30.0)))
    lines = principal_streamlines(R, count=4, step=0.5, max_length=10.0)
    assert lines
    d = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    for line in lines:
        steps = np.diff(line, axis=0)
        assert np.allclose(np.abs(steps @ d), 0.5) and np.allclose(steps @ np.array([-d[1], d[0]]), 0.0)

    y, x = np.meshgrid(np.arange(ny) + 0.5, np.arange(nx) + 0.5, indexing="ij")
    tangent = np.arctan2(y - 20.0, x - 20.0) + np.pi / 2
    lines = principal_streamlines(rotation_2d(tangent), count=4, step=0.25, max_length=6.0,
                                  mask=np.hypot(x - 20, y - 20) > 4)
    assert lines
    for line in lines:
        r = np.hypot(line[:, 0] - 20.0, line[:, 1] - 20.0)
        assert r.max() - r.min() < 1.0           # nearest-cell directions: within a cell of a circle


def test_stroke_centres_leave_no_gap_and_lie_on_the_drag():
    pts = np.array([[1.0, 1.0], [9.0, 1.0], [9.0, 5.0]])
    c = stroke_centres(pts, 2.0)
    assert np.allclose(c[0], pts[0]) and np.allclose(c[-1], pts[-1])
    assert np.linalg.norm(np.diff(c, axis=0), axis=1).max() <= 1.0 + 1e-12
    on_first = np.isclose(c[:, 1], 1.0) & (c[:, 0] >= 1.0) & (c[:, 0] <= 9.0)
    on_second = np.isclose(c[:, 0], 9.0) & (c[:, 1] >= 1.0) & (c[:, 1] <= 5.0)
    assert np.all(on_first | on_second)
    assert len(stroke_centres([[3.0, 4.0, 5.0]], 1.0)) == 1
    with pytest.raises(ValueError, match="radius must be > 0"):
        stroke_centres(pts, 0.0)
