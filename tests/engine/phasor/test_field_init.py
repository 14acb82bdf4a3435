import json
import math

import numpy as np
import pytest
import trimesh

from engine.phasor.field_init import fields_from_spec

LO, HI = np.array([-2.0, -3.0, 0.0]), np.array([2.0, 3.0, 10.0])
SHAPE = (5, 6, 4)  # (nz, ny, nx): cell 1 mm in x and y, 2 mm in z


def centre_of(k, j, i, lo=LO, hi=HI, shape=SHAPE):
    step = (hi - lo) / np.array(shape[::-1])
    return lo + (np.array([i, j, k]) + 0.5) * step


def test_defaults_and_shorthands():
    f = fields_from_spec({}, lo=LO, hi=HI, shape=SHAPE)
    assert f.shape == SHAPE
    assert np.all(f.direction == [1.0, 0.0, 0.0]) and np.all(f.frequency == 1.0) and np.all(f.spread == 0.0)
    f = fields_from_spec({"D": [0, 0, 2], "F": 2.5, "Gamma": 0.3}, lo=LO, hi=HI, shape=SHAPE)
    assert np.all(f.direction == [0.0, 0.0, 1.0]) and np.all(f.frequency == 2.5) and np.all(f.spread == 0.3)


def test_along_axis_with_sign():
    f = fields_from_spec({"D": {"kind": "along_axis", "axis": "-y"}}, lo=LO, hi=HI, shape=SHAPE)
    assert np.all(f.direction == [0.0, -1.0, 0.0])


def test_radial_from_a_point_is_the_normalised_offset():
    c = [0.3, -0.2, 4.0]
    f = fields_from_spec({"D": {"kind": "radial", "centre": c}}, lo=LO, hi=HI, shape=SHAPE)
    for k, j, i in [(0, 0, 0), (4, 5, 3), (2, 3, 1)]:
        off = centre_of(k, j, i) - c
        np.testing.assert_allclose(f.direction[k, j, i], off / np.linalg.norm(off), atol=1e-12)


def test_radial_from_an_axis_drops_the_axial_component_and_inward_flips():
    spec = {"D": {"kind": "radial", "axis": "z", "centre": [0.5, 0.5, 99.0], "inward": True}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    for k, j, i in [(0, 0, 0), (4, 5, 3), (2, 1, 1)]:
        p = centre_of(k, j, i)
        off = np.array([p[0] - 0.5, p[1] - 0.5, 0.0])
        np.testing.assert_allclose(f.direction[k, j, i], -off / np.linalg.norm(off), atol=1e-12)


def test_radial_on_the_axis_takes_the_fallback():
    # cell (k, 3, 2) centre is x = 0.5, y = 0.5: on the axis
    spec = {"D": {"kind": "radial", "axis": "z", "centre": [0.5, 0.5, 0.0], "fallback": [0, 1, 0]}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    assert np.all(f.direction[:, 3, 2] == [0.0, 1.0, 0.0])


@pytest.mark.parametrize("angle, want", [(0, [1, 0, 0]), (90, [0, 1, 0]), (180, [-1, 0, 0]),
                                         (45, [math.sqrt(0.5), math.sqrt(0.5), 0])])
def test_spiral_about_z_at_a_point_on_the_plus_x_side(angle, want):
    # cell (k, 3, 3): x = 1.5, y = 0.5; axis through (0, 0.5): offset is +x
    spec = {"D": {"kind": "spiral", "axis": "z", "centre": [0.0, 0.5, 0.0], "angle_deg": angle}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    np.testing.assert_allclose(f.direction[2, 3, 3], want, atol=1e-12)


def test_twist_by_90_degrees_over_the_box_height():
    # z in [0, 10] with 5 cells: centres z = 1, 3, 5, 7, 9, so t = 0.1 ... 0.9
    spec = {"D": {"kind": "twist", "axis": "z", "start": [1, 0, 0], "angle_deg": 90}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    bottom, middle, top = math.radians(9.0), math.radians(45.0), math.radians(81.0)
    np.testing.assert_allclose(f.direction[0, 2, 2], [math.cos(bottom), math.sin(bottom), 0], atol=1e-12)
    np.testing.assert_allclose(f.direction[2, 0, 3], [math.sqrt(0.5), math.sqrt(0.5), 0], atol=1e-12)
    np.testing.assert_allclose(f.direction[4, 5, 0], [math.cos(top), math.sin(top), 0], atol=1e-12)
    assert math.degrees(middle) == 45.0


def test_twist_range_clamps_and_keeps_the_axial_component():
    spec = {"D": {"kind": "twist", "axis": "z", "start": [1, 0, 1], "angle_deg": 180, "range": [3, 7]}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    s = math.sqrt(0.5)
    np.testing.assert_allclose(f.direction[0, 0, 0], [s, 0, s], atol=1e-12)   # z = 1 < 3: start
    np.testing.assert_allclose(f.direction[1, 0, 0], [s, 0, s], atol=1e-12)   # z = 3: t = 0
    np.testing.assert_allclose(f.direction[2, 0, 0], [0, s, s], atol=1e-12)   # z = 5: 90 degrees
    np.testing.assert_allclose(f.direction[4, 0, 0], [-s, 0, s], atol=1e-12)  # z = 9 > 7: 180


def test_linear_gradient_of_F_along_y():
    spec = {"F": {"kind": "linear", "axis": "y", "from": 1.0, "to": 4.0}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    ys = np.array([centre_of(0, j, 0)[1] for j in range(6)])
    np.testing.assert_allclose(f.frequency[3, :, 2], 1.0 + 3.0 * (ys + 3.0) / 6.0, atol=1e-12)


def test_radial_gradient_of_Gamma_about_an_axis():
    spec = {"Gamma": {"kind": "radial", "axis": "z", "centre": [0, 0, 0], "from": 0.0, "to": 1.0,
                      "radius": 2.0}}
    f = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    p = centre_of(1, 3, 2)  # (0.5, 0.5): distance sqrt(0.5)
    assert f.spread[1, 3, 2] == pytest.approx(math.sqrt(0.5) / 2.0, abs=1e-12)
    assert f.spread[1, 0, 0] == 1.0  # (-1.5, -2.5): beyond the radius, clamped
    assert np.linalg.norm(p[:2]) == pytest.approx(math.sqrt(0.5))


def test_radial_default_radius_reaches_the_farthest_corner():
    lo, hi = np.zeros(3), np.ones(3) * 2
    spec = {"F": {"kind": "radial", "from": 1.0, "to": 3.0}}
    f = fields_from_spec(spec, lo=lo, hi=hi, shape=(2, 2, 2))
    # every cell centre is at distance sqrt(3)/2 of the box centre; the corner at sqrt(3)
    np.testing.assert_allclose(f.frequency, 2.0, atol=1e-12)


def test_surface_normal_on_a_cube_is_the_nearest_face_normal():
    cube = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    lo, hi = np.full(3, -5.0), np.full(3, 5.0)
    f = fields_from_spec({"D": {"kind": "surface_normal"}}, lo=lo, hi=hi, shape=(10, 10, 10), mesh=cube)
    # cell [z, y, x] = (5, 5, 9): (4.5, 0.5, 0.5), nearest face x = +5
    np.testing.assert_allclose(f.direction[5, 5, 9], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(f.direction[5, 1, 5], [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(f.direction[8, 4, 6], [0, 0, 1], atol=1e-12)
    inward = fields_from_spec({"D": {"kind": "surface_normal", "inward": True}}, lo=lo, hi=hi,
                              shape=(10, 10, 10), mesh=cube)
    np.testing.assert_allclose(inward.direction[5, 5, 9], [-1, 0, 0], atol=1e-12)


def test_surface_normal_is_outward_even_for_an_inside_out_mesh():
    cube = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    flipped = (np.asarray(cube.vertices), np.asarray(cube.faces)[:, ::-1])
    f = fields_from_spec({"D": {"kind": "surface_normal"}}, lo=np.full(3, -5.0), hi=np.full(3, 5.0),
                         shape=(10, 10, 10), mesh=flipped)
    np.testing.assert_allclose(f.direction[5, 5, 9], [1, 0, 0], atol=1e-12)


def test_spec_survives_a_json_round_trip():
    spec = {"D": {"kind": "spiral", "axis": "z", "centre": [0, 0, 0], "angle_deg": 30},
            "F": {"kind": "linear", "axis": "z", "from": 1.5, "to": 0.5},
            "Gamma": {"kind": "radial", "centre": [0, 0, 0], "from": 0.0, "to": 0.8, "radius": 20}}
    a = fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    b = fields_from_spec(json.loads(json.dumps(spec)), lo=LO, hi=HI, shape=SHAPE)
    assert a.direction.tobytes() == b.direction.tobytes()
    assert a.frequency.tobytes() == b.frequency.tobytes() and a.spread.tobytes() == b.spread.tobytes()


@pytest.mark.parametrize("spec, words", [
    ({"D": {"kind": "foo"}}, "D.kind: expected one of constant, along_axis, radial"),
    ({"D": {"kind": "constant", "value": [0, 0, 0]}}, "D.value"),
    ({"D": {"kind": "constant", "value": [1, 0]}}, "D.value"),
    ({"D": {"kind": "radial", "axis": "w"}}, "D.axis"),
    ({"D": {"kind": "radial", "centre": "here"}}, "D.centre"),
    ({"D": {"kind": "radial", "inward": 1}}, "D.inward"),
    ({"D": {"kind": "twist", "axis": "z", "angle_deg": 90}}, "D.start"),
    ({"D": {"kind": "twist", "axis": "z", "start": [1, 0, 0], "angle_deg": 9, "range": [5, 1]}}, "D.range"),
    ({"D": {"kind": "spiral", "angel_deg": 9}}, "D.angel_deg: unknown key"),
    ({"D": {"kind": "surface_normal"}}, "needs the part's mesh"),
    ({"F": {"kind": "constant", "value": 0.0}}, "F.value"),
    ({"F": {"kind": "linear", "axis": "x", "from": -1.0, "to": 2.0}}, "F.from"),
    ({"F": {"kind": "linear", "from": 1.0, "to": 2.0}}, "F.axis"),
    ({"F": {"kind": "radial", "from": 1.0, "to": 2.0, "radius": 0}}, "F.radius"),
    ({"Gamma": {"kind": "constant", "value": 2.0}}, "Gamma.value"),
    ({"Gamma": {"kind": "linear", "axis": "x", "from": 0.0, "to": float("nan")}}, "Gamma.to"),
    ({"Gamma": {"kind": "twist"}}, "Gamma.kind"),
    ({"G": 1.0}, "spec.G"),
])
def test_spec_errors_name_field_and_key(spec, words):
    with pytest.raises(ValueError, match=None) as err:
        fields_from_spec(spec, lo=LO, hi=HI, shape=SHAPE)
    assert words in str(err.value)
