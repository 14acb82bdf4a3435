"""Slice previews for the paint canvas, checked against closed forms and brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from engine.phasor.fields import PhasorFields, constant_fields
from engine.phasor.incremental import affected_box
from engine.phasor.preview import (direction_glyphs, direction_hue, domain_slice, field_slice,
                                   gcode_preview, mask_outline, plane_extent, region_pixel_rect,
                                   slice_plane, sub_plane, view_pixels)
from engine.phasor.strokes import Stroke, apply_stroke

LO, HI = np.array([1.0, -2.0, 0.5]), np.array([9.0, 4.0, 4.5])
SHAPE = (8, 12, 16)   # (nz, ny, nx): 0.5 mm cells


def _random_fields(seed=3):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=SHAPE + (3,))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return PhasorFields(d, rng.uniform(0.5, 2.0, SHAPE), rng.uniform(0.0, 1.2, SHAPE), LO, HI)


@pytest.mark.parametrize("axis, uv", [("x", (1, 2)), ("y", (0, 2)), ("z", (0, 1))])
def test_slice_plane_tiles_the_box_extent(axis, uv):
    plane = slice_plane(LO, HI, axis, 2.0, max_pixels=40)
    u, v = uv
    ext = np.array([[LO[u], HI[u]], [LO[v], HI[v]]])
    assert np.allclose(plane_extent(plane), ext)
    h, w = plane.shape
    assert max(h, w) == 40
    pts = plane.points()
    n = 3 - u - v
    assert np.allclose(pts[..., n], 2.0)
    assert np.allclose(pts[0, :, u], LO[u] + (np.arange(w) + 0.5) * (HI[u] - LO[u]) / w)
    assert np.allclose(pts[:, 0, v], LO[v] + (np.arange(h) + 0.5) * (HI[v] - LO[v]) / h)


def test_sub_plane_has_the_same_pixel_centres():
    plane = slice_plane(LO, HI, "y", 1.0, max_pixels=50)
    sub = sub_plane(plane, (3, 11), (7, 30))
    assert sub.shape == (8, 23)
    assert np.allclose(sub.points(), plane.points()[3:11, 7:30], atol=1e-12)
    with pytest.raises(ValueError, match="rows"):
        sub_plane(plane, (5, 5), (0, 3))


def test_view_pixels_give_four_per_period_of_the_highest_frequency():
    f = constant_fields(LO, HI, SHAPE, frequency=5.3)
    assert view_pixels(f) == math.ceil(8.0 * 5.3 * 4)      # longest side 8 mm
    assert view_pixels(constant_fields(LO, HI, SHAPE, frequency=0.1)) == 128
    assert view_pixels(constant_fields(LO, HI, SHAPE, frequency=100.0)) == 768


def test_field_slice_of_a_linear_field_is_exact_inside_the_cell_centres():
    # F = 1 + 0.1 x + 0.2 y + 0.3 z on the cell centres: trilinear reproduces it exactly
    base = constant_fields(LO, HI, SHAPE)
    xs, ys, zs = base.centres()
    z, y, x = np.meshgrid(zs, ys, xs, indexing="ij")
    f = PhasorFields(base.direction, 1 + 0.1 * x + 0.2 * y + 0.3 * z, base.spread, LO, HI)
    plane = slice_plane(LO, HI, "x", 4.1, max_pixels=30)
    got = field_slice(f, "F", plane)
    p = plane.points()
    want = 1 + 0.1 * p[..., 0] + 0.2 * p[..., 1] + 0.3 * p[..., 2]
    spacing = base.spacing
    interior = ((p[..., 1] > ys[0]) & (p[..., 1] < ys[-1]) & (p[..., 2] > zs[0]) & (p[..., 2] < zs[-1]))
    assert interior.sum() > 100
    assert np.allclose(got[interior], want[interior])
    assert spacing[0] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="field"):
        field_slice(f, "E", plane)


def test_direction_hue_and_glyphs():
    rgb = direction_hue(np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]), "z")
    assert tuple(rgb[0]) == (242, 0, 0)                   # +u: red
    assert tuple(rgb[1]) == (0, 242, 242)                 # -u: half a turn, cyan
    assert rgb[2, 1] == 242 and rgb[2, 2] == 0            # +v: a quarter turn, yellow-green
    assert tuple(rgb[3]) == (242, 242, 242)               # along the normal: no hue
    d = np.array([0.0, 0.6, 0.8])                          # y-plane: (u, v) = (x, z), normal y
    f = constant_fields(LO, HI, SHAPE, direction=d)
    centres, vectors, normal = direction_glyphs(f, "y", 1.0, count=8)
    assert centres.shape == (8 * 4, 2)                     # 8 mm x 4 mm at 1 mm spacing
    assert np.allclose(vectors, [0.0, 0.8]) and np.allclose(normal, 0.6)


def test_region_pixel_rect_holds_every_pixel_a_stroke_changed():
    fields = _random_fields()
    for stroke in (Stroke("F", "z", 2.2, [[3.0, 0.0], [5.5, 1.5]], 1.2, value=2.5),
                   Stroke("Gamma", "y", 0.3, [[8.5, 4.0]], 0.8, value=0.1, depth=1.5),
                   Stroke("D", "x", 5.0, [[-2.0, 0.6], [3.9, 4.4]], 1.0, tilt=0.4)):
        new, changed = apply_stroke(fields, stroke)
        for axis in ("x", "y", "z"):
            for position in (0.6, 1.4, 2.2, 3.1, 4.4):
                if axis != "z" and position < 1.0:
                    position += 2.0
                plane = slice_plane(LO, HI, axis, position, max_pixels=64)
                name = stroke.field
                before, after = field_slice(fields, name, plane), field_slice(new, name, plane)
                differs = np.any((before != after).reshape(plane.shape + (-1,)), axis=-1)
                rect = region_pixel_rect(plane, affected_box(new, changed))
                if rect is None:
                    assert not differs.any()
                    continue
                r0, r1, c0, c1 = rect
                inside = np.zeros(plane.shape, bool)
                inside[r0:r1, c0:c1] = True
                assert not np.any(differs & ~inside), (stroke.field, axis, position)


def test_region_pixel_rect_by_hand():
    plane = slice_plane((0, 0, 0), (10, 10, 10), "z", 5.0, max_pixels=10)   # 1 mm pixels
    assert region_pixel_rect(plane, ((2.0, 3.0, 0.0), (4.5, 7.0, 6.0))) == (3, 7, 2, 5)  # closed: 4.5 counts
    assert region_pixel_rect(plane, ((2.0, 3.0, 5.5), (4.5, 7.0, 6.0))) is None  # plane below
    assert region_pixel_rect(plane, ((-np.inf, 8.6, 0), (np.inf, np.inf, 9))) == (9, 10, 0, 10)
    assert region_pixel_rect(plane, ((2.1, 0, 0), (2.4, 10, 10))) is None  # between centres
    assert region_pixel_rect(plane, None) is None


def test_mask_outline_of_a_rectangle_and_a_hole():
    m = np.zeros((10, 12), bool)
    m[2:8, 3:10] = True
    m[4:6, 5:7] = False     # a 2 x 2 hole
    seg = mask_outline(m, ((0.0, 12.0), (0.0, 5.0)))   # du = 1, dv = 0.5
    length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)
    assert length.sum() == pytest.approx(2 * 7 + 2 * 6 * 0.5 + 2 * 2 + 2 * 2 * 0.5)
    assert seg[..., 0].min() == 3.0 and seg[..., 0].max() == 10.0
    assert seg[..., 1].min() == 1.0 and seg[..., 1].max() == 4.0


def test_domain_slice_of_a_cube():
    import trimesh

    cube = trimesh.creation.box(extents=(4.0, 2.0, 2.0))   # centred at 0
    plane = slice_plane((-4, -2, -2), (4, 2, 2), "z", 0.3, max_pixels=80)
    inside = domain_slice(cube, plane)
    p = plane.points()
    want = (np.abs(p[..., 0]) < 2.0) & (np.abs(p[..., 1]) < 1.0)
    assert np.array_equal(inside, want)
    assert domain_slice(None, plane) is None
    assert not domain_slice(cube, slice_plane((-4, -2, -2), (4, 2, 2), "z", 1.5, max_pixels=20)).any()


def test_gcode_preview_reads_paths_back_in_part_coordinates(tmp_path):
    path = tmp_path / "two.gcode"
    path.write_text("\n".join([
        "G90", "M83", "G0 X105 Y103 Z0.3", ";TYPE:perimeter", "G1 X106 Y103 E0.1", "G1 X106 Y104 E0.1",
        "G0 X100 Y100", ";TYPE:infill", "G1 X101 Y101 E0.05", ""]))
    lines = gcode_preview(path)
    assert len(lines.layers) == 1
    seg = lines.points[lines.segments]
    assert seg.shape == (3, 2, 3)
    assert np.allclose(seg[0], [[5, 3, 0.3], [6, 3, 0.3]])
    assert np.allclose(seg[2], [[0, 0, 0.3], [1, 1, 0.3]])
    assert lines.colours.tolist() == [[230, 120, 30], [230, 120, 30], [40, 110, 200]]
    with pytest.raises(ValueError, match="cannot read"):
        gcode_preview(tmp_path / "missing.gcode")


def test_pattern_slice_matches_the_brute_force_noise():
    from engine.phasor.fields import trilinear
    from engine.phasor.infill import sample_infill
    from engine.phasor.noise import phasor_complex_reference, sawtooth
    from engine.phasor.preview import pattern_slice

    fields = constant_fields((0, 0, 0), (6, 6, 6), (4, 4, 4), direction=(0.6, 0.8, 0.0), frequency=1.5)
    infill = sample_infill(fields, per_cell=2, iterations=2, filtered=True, rng=4)
    plane = sub_plane(slice_plane(fields.lo, fields.hi, "y", 2.7, max_pixels=24), (5, 15), (3, 13))
    pts = plane.points().reshape(-1, 3)
    # A(x) per point; trilinear weights of an all-ones grid can sum to 1 + 2e-16, which the
    # reference refuses as outside [0, 1], so the round-off is clipped here
    a = np.clip(trilinear(infill.attenuation, fields.lo, fields.hi, pts), 0.0, 1.0)
    g_v, g_w = phasor_complex_reference(infill.kernels, pts, fields=fields, filtered=True,
                                        filter_scale=infill.filter_scale, attenuation=a)
    p_v, p_w = sawtooth(g_v).reshape(10, 10), sawtooth(g_w).reshape(10, 10)
    got, used = pattern_slice(infill, plane, "p_v", engine="numpy")
    assert used == "numpy"
    wrapped = np.abs((got - p_v + 0.5) % 1.0 - 0.5)
    assert wrapped.max() < 1e-9
    diamonds, _ = pattern_slice(infill, plane, "diamonds", engine="numpy")
    want = (np.abs(0.5 - p_v) + np.abs(0.5 - p_w) < 0.5).astype(float)
    assert np.array_equal(diamonds, want)
    with pytest.raises(ValueError, match="show"):
        pattern_slice(infill, plane, "p_u")
