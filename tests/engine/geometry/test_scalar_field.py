"""The scalar field kernel against independent references: hand-computed values at chosen
cells, the ramp and radial closed forms written per cell, and a slow per-cell loop for the
stroke blend (its own point-to-segment distance in plain Python floats)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from engine.geometry.scalar_field import (FieldStroke, Radial, Ramp, field_grid_shape, nearest_layer,
                                          paint_strokes, profile_values, scalar_field)

LO, HI = (0.0, 0.0, 0.0), (10.0, 10.0, 10.0)


def _centre(lo, hi, shape, k, j, i):
    """(x, y, z) of cell [k, j, i] worked out from scratch."""
    nz, ny, nx = shape
    return (lo[0] + (i + 0.5) * (hi[0] - lo[0]) / nx, lo[1] + (j + 0.5) * (hi[1] - lo[1]) / ny,
            lo[2] + (k + 0.5) * (hi[2] - lo[2]) / nz)


def _segment_distance(p, a, b):
    """Distance from point p to segment ab in 2-D, by the textbook projection."""
    ax, ay = a
    bx, by = b
    px, py = p
    ex, ey = bx - ax, by - ay
    if ex == 0 and ey == 0:
        return math.hypot(px - ax, py - ay)
    t = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(px - ax - t * ex, py - ay - t * ey)


def _profile(s, kind):
    if s >= 1.0:
        return 0.0
    return {"constant": 1.0, "linear": 1.0 - s, "smooth": 1.0 - 3 * s * s + 2 * s ** 3}[kind]


def _slow_paint(values, lo, hi, strokes):
    """The stroke blend cell by cell: the brush distance from scratch, then v <- (1-w) v + w value."""
    out = np.array(values, dtype=np.float64)
    shape = out.shape
    in_plane = {"x": (1, 2, 0), "y": (0, 2, 1), "z": (0, 1, 2)}
    for st in strokes:
        u, v, n = in_plane[st["axis"]]
        depth = st.get("depth") or st["radius"]
        pts = [tuple(p) for p in st["points"]]
        segs = list(zip(pts[:-1], pts[1:])) or [(pts[0], pts[0])]
        for k in range(shape[0]):
            for j in range(shape[1]):
                for i in range(shape[2]):
                    c = _centre(lo, hi, shape, k, j, i)
                    d = min(_segment_distance((c[u], c[v]), a, b) for a, b in segs)
                    off = (c[n] - st["position"]) / depth * st["radius"]
                    s = math.sqrt(d * d + off * off) / st["radius"]
                    w = st.get("strength", 1.0) * _profile(s, st.get("falloff", "smooth"))
                    out[k, j, i] = (1 - w) * out[k, j, i] + w * st["value"]
    return out


# --- the grid ----------------------------------------------------------------------------

def test_resolution_counts_samples_along_the_longest_side():
    assert field_grid_shape((0, 0, 0), (10, 5, 2.5), 8) == (2, 4, 8)
    assert field_grid_shape((0, 0, 0), (1, 1, 0.01), 16) == (1, 16, 16)     # at least one sample
    with pytest.raises(ValueError, match="resolution"):
        field_grid_shape(LO, HI, 0)
    with pytest.raises(ValueError, match="must exceed lo"):
        field_grid_shape((0, 0, 0), (1, 0, 1), 4)


def test_a_constant_field_is_its_base_on_the_box():
    f = scalar_field((-1, 0, 2), (3, 2, 4), (2, 2, 4), base=0.25)
    assert f.kind == "scalar" and f.values.shape == (2, 2, 4)
    assert np.all(f.values == 0.25)
    assert f.lo.tolist() == [-1, 0, 2] and f.hi.tolist() == [3, 2, 4]
    assert not f.values.flags.writeable


# --- profiles ----------------------------------------------------------------------------

def test_a_ramp_is_linear_between_its_ends_and_constant_beyond():
    # z from 2 mm (value 1) to 6 mm (value 0), cell centres at 0.5, 1.5, ..., 9.5
    v = profile_values(LO, HI, (10, 1, 1), profile=Ramp("z", 2.0, 6.0, 1.0, 0.0))[:, 0, 0]
    want = [1, 1, 0.875, 0.625, 0.375, 0.125, 0, 0, 0, 0]
    assert v.tolist() == pytest.approx(want, abs=1e-15)
    # backwards: the value at `start` (8 mm) is value_from, at `end` (4 mm) value_to
    v = profile_values(LO, HI, (1, 1, 10), profile=Ramp("x", 8.0, 4.0, -2.0, 2.0))[0, 0]
    want = [2, 2, 2, 2, 1.5, 0.5, -0.5, -1.5, -2, -2]
    assert v.tolist() == pytest.approx(want, abs=1e-15)


def test_a_ramp_along_y_on_an_uneven_grid_matches_its_closed_form_at_every_cell():
    lo, hi, shape = (-3.0, 1.0, 0.0), (5.0, 4.0, 2.0), (3, 7, 5)
    ramp = Ramp("y", 1.5, 3.25, 0.2, 0.9)
    v = profile_values(lo, hi, shape, profile=ramp)
    for k, j, i in np.ndindex(shape):
        y = _centre(lo, hi, shape, k, j, i)[1]
        t = min(max((y - 1.5) / 1.75, 0.0), 1.0)
        assert v[k, j, i] == pytest.approx(0.2 + 0.7 * t, abs=1e-14)
    assert len(np.unique(np.round(v, 12))) > 3


def test_a_radial_bump_has_inner_at_the_centre_and_outer_beyond_the_radius():
    # 10 cells of 1 mm; the centre sits on the centre of cell (5, 5, 5)
    r = Radial((5.5, 5.5, 5.5), 4.0, 1.0, 0.2, "smooth")
    v = profile_values(LO, HI, (10, 10, 10), profile=r)
    assert v[5, 5, 5] == pytest.approx(1.0)
    # 2 mm away: s = 0.5, smooth profile 1 - 3/4 + 2/8 = 0.5
    assert v[5, 5, 7] == pytest.approx(0.2 + 0.8 * 0.5)
    assert v[5, 5, 9] == pytest.approx(0.2)          # s = 1
    assert v[0, 0, 0] == pytest.approx(0.2)          # far corner
    lin = profile_values(LO, HI, (10, 10, 10), profile=Radial((5.5, 5.5, 5.5), 4.0, 1.0, 0.2, "linear"))
    assert lin[5, 6, 5] == pytest.approx(0.2 + 0.8 * 0.75)        # s = 1/4


def test_a_radial_bump_matches_its_closed_form_at_every_cell():
    lo, hi, shape = (0.0, -2.0, 1.0), (4.0, 2.0, 3.0), (4, 8, 8)
    r = Radial((1.3, 0.4, 2.2), 1.7, -0.5, 2.0)
    v = profile_values(lo, hi, shape, profile=r)
    for idx in np.ndindex(shape):
        c = _centre(lo, hi, shape, *idx)
        s = math.dist(c, (1.3, 0.4, 2.2)) / 1.7
        assert v[idx] == pytest.approx(2.0 + (-2.5) * _profile(s, "smooth"), abs=1e-13)


# --- strokes -----------------------------------------------------------------------------

def test_a_still_constant_brush_sets_exactly_the_cells_within_its_radius():
    st = FieldStroke("z", 5.5, [[5.5, 5.5]], 1.2, 7.0, falloff="constant")
    v = paint_strokes(np.zeros((10, 10, 10)), LO, (1.0, 1.0, 1.0), [st])
    # 3-D distance from the centre cell: 0 (1 cell), 1 (6 cells); sqrt(2) > 1.2 is out
    assert v[5, 5, 5] == 7.0 and v[5, 5, 6] == 7.0 and v[6, 5, 5] == 7.0
    assert v[5, 6, 6] == 0.0 and np.count_nonzero(v) == 7


def test_strokes_blend_like_a_slow_per_cell_loop_on_a_ramp():
    lo, hi, shape = (0.0, 0.0, 0.0), (6.0, 4.0, 5.0), (10, 8, 12)
    strokes = [
        {"axis": "z", "position": 2.3, "points": [[0.5, 0.5], [4.0, 3.0], [5.5, 1.0]], "radius": 1.1,
         "value": 3.0, "strength": 0.8, "falloff": "smooth", "depth": 0.6},
        {"axis": "x", "position": 3.1, "points": [[2.0, 1.0], [2.0, 4.0]], "radius": 0.9, "value": -1.0,
         "strength": 1.0, "falloff": "linear", "depth": None},
        {"axis": "y", "position": 1.0, "points": [[1.0, 1.0], [1.0, 1.0]], "radius": 1.5, "value": 0.5,
         "strength": 0.5, "falloff": "constant", "depth": 2.0},
    ]
    ramp = Ramp("x", 0.0, 6.0, 0.0, 1.0)
    field = scalar_field(lo, hi, shape, profile=ramp, strokes=[FieldStroke.from_dict(d) for d in strokes])
    base = profile_values(lo, hi, shape, profile=ramp)
    want = _slow_paint(base, lo, hi, strokes)
    assert np.allclose(field.values, want, rtol=0, atol=1e-12)
    assert np.count_nonzero(~np.isclose(want, base)) > 50          # the strokes did paint


def test_painting_leaves_its_input_alone():
    v = np.linspace(0, 1, 64).reshape(4, 4, 4)
    before = v.copy()
    out = paint_strokes(v, (0, 0, 0), (1, 1, 1), [FieldStroke("z", 2.0, [[2, 2]], 2.0, 5.0)])
    assert np.array_equal(v, before) and not np.array_equal(out, before)


def test_the_clamp_comes_after_the_strokes():
    st = FieldStroke("z", 5.0, [[5.0, 5.0], [9.0, 5.0]], 2.0, 4.0, falloff="constant")
    f = scalar_field(LO, HI, (10, 10, 10), profile=Ramp("z", 0, 10, -1.0, 2.0), strokes=[st], clamp=(0.0, 1.0))
    assert f.values.min() == 0.0 and f.values.max() == 1.0
    assert f.values[5, 5, 7] == 1.0                               # painted 4, clamped to 1
    assert f.values[0, 0, 0] == 0.0                               # ramp -0.85, clamped to 0
    assert f.values[4, 0, 0] == pytest.approx(-1.0 + 3.0 * 0.45)  # inside the range: untouched


def test_a_stroke_round_trips_through_its_dict():
    st = FieldStroke("y", 1.25, [[0, 1], [2, 3.5]], 0.7, -2.0, strength=0.3, falloff="linear", depth=1.5)
    again = FieldStroke.from_dict(st.to_dict())
    assert again.to_dict() == st.to_dict() and again.reach == 1.5
    assert FieldStroke("x", 0, [[0, 0]], 2.0, 1.0).reach == 2.0


@pytest.mark.parametrize("make, match", [
    (lambda: Ramp("z", 1.0, 1.0, 0, 1), r"Ramp\.end: .*a ramp needs a length"),
    (lambda: Ramp("w", 0, 1, 0, 1), r"Ramp\.axis: expected 'x', 'y' or 'z'"),
    (lambda: Radial((0, 0, 0), 0.0, 1, 0), r"Radial\.radius: expected a finite radius > 0"),
    (lambda: Radial((0, 0), 1.0, 1, 0), r"Radial\.centre"),
    (lambda: Radial((0, 0, 0), 1.0, 1, 0, "cubic"), r"Radial\.falloff: expected one of smooth"),
    (lambda: FieldStroke("z", 0, [[0, 0]], 1.0, 1.0, strength=1.5), r"FieldStroke\.strength: .*\[0, 1\]"),
    (lambda: FieldStroke("z", 0, [[0, 0]], -1.0, 1.0), r"FieldStroke\.radius: expected a finite number > 0"),
    (lambda: FieldStroke("z", 0, [[0, 0]], 1.0, math.nan), r"FieldStroke\.value"),
    (lambda: FieldStroke("z", 0, [[0, 0, 0]], 1.0, 1.0), r"FieldStroke\.points: expected a \(k, 2\)"),
    (lambda: FieldStroke("z", 0, [[0, 0]], 1.0, 1.0, depth=0.0), r"FieldStroke\.depth"),
    (lambda: FieldStroke.from_dict({"axis": "z", "position": 0, "points": [[0, 0]], "radius": 1,
                                    "value": 1, "field": "F"}), r"FieldStroke\.field: unknown key"),
    (lambda: FieldStroke.from_dict({"axis": "z", "position": 0, "points": [[0, 0]], "radius": 1}),
     r"FieldStroke\.value: missing"),
    (lambda: scalar_field(LO, HI, (2, 2, 2), clamp=(1.0, 0.0)), r"clamp: the low end 1\.0 must not exceed"),
    (lambda: scalar_field(HI, LO, (2, 2, 2)), r"must exceed lo"),
])
def test_bad_input_is_refused_naming_the_argument(make, match):
    with pytest.raises(ValueError, match=match):
        make()


# --- looking at it -----------------------------------------------------------------------

@pytest.mark.parametrize("axis, normal, u, v", [("z", 2, 0, 1), ("y", 1, 0, 2), ("x", 0, 1, 2)])
def test_the_nearest_layer_has_rows_along_v_and_columns_along_u(axis, normal, u, v):
    shape = (3, 4, 5)                               # nz, ny, nx
    k, j, i = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    from engine.geometry.values import Field

    f = Field(100 * i + 10 * j + k, (0, 0, 0), (5.0, 8.0, 9.0))   # value says its (x, y, z) index
    spacing = (1.0, 2.0, 3.0)
    layer = 1
    position = (layer + 0.7) * spacing[normal]      # inside cell 1 along the normal
    image, extent, index = nearest_layer(f, axis, position)
    assert index == layer
    digits = (100, 10, 1)
    nu, nv = shape[2 - u], shape[2 - v]
    assert image.shape == (nv, nu)
    for row in range(nv):
        for col in range(nu):
            want = digits[u] * col + digits[v] * row + digits[normal] * layer
            assert image[row, col] == want
    hi = (5.0, 8.0, 9.0)
    assert extent == ((0.0, hi[u]), (0.0, hi[v]))
    assert nearest_layer(f, axis, -50.0)[2] == 0 and nearest_layer(f, axis, 1e3)[2] == shape[2 - normal] - 1
