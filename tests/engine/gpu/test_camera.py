import math

import numpy as np
import pytest

from engine.gpu.camera import Camera, format_camera, parse_camera


def _angle(a, b):
    return math.degrees(math.acos(np.clip(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b), -1, 1)))


@pytest.mark.parametrize("eye, target", [((3.0, -4.0, 2.0), (0.5, 0.0, -1.0)), ((0, 0, 5), (0, 0.001, 0)),
                                         ((-2, 7, 1), (3, 3, 3))])
def test_the_centre_ray_points_at_the_target(eye, target):
    cam = Camera(eye, target, fov_deg=50.0)
    o, d = cam.rays(33, 21)                       # odd sizes: a pixel sits on the image centre
    assert o.shape == d.shape == (21, 33, 3)
    np.testing.assert_allclose(o, np.broadcast_to(eye, o.shape))
    view = np.subtract(target, eye) / np.linalg.norm(np.subtract(target, eye))
    np.testing.assert_allclose(d[10, 16], view, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(d, axis=2), 1.0, atol=1e-12)


@pytest.mark.parametrize("fov, w, h", [(30.0, 41, 41), (90.0, 61, 31), (150.0, 21, 45)])
def test_the_field_of_view_spans_the_expected_angles(fov, w, h):
    cam = Camera((1.0, 2.0, 3.0), (1.0, 2.0, 0.0), up=(0, 1, 0), fov_deg=fov)
    _, d = cam.rays(w, h)
    tan_half = math.tan(math.radians(fov) / 2)
    # pixel centres sit half a pixel inside the image edges
    vertical = 2 * math.degrees(math.atan((1 - 1 / h) * tan_half))
    horizontal = 2 * math.degrees(math.atan((1 - 1 / w) * tan_half * w / h))
    assert _angle(d[0, w // 2], d[-1, w // 2]) == pytest.approx(vertical, abs=1e-9)
    assert _angle(d[h // 2, 0], d[h // 2, -1]) == pytest.approx(horizontal, abs=1e-9)


def test_image_orientation_follows_up_and_right():
    # looking along -y with +z up: right = forward x up = -x
    cam = Camera((0.0, 5.0, 0.0), (0.0, 0.0, 0.0), up=(0, 0, 1), fov_deg=60.0)
    _, d = cam.rays(11, 11)
    assert d[0, 5, 2] > 0 and d[-1, 5, 2] < 0          # row 0 is the top
    assert d[5, -1, 0] < 0 and d[5, 0, 0] > 0          # the last column is on the right
    forward, right, up = cam.basis()
    np.testing.assert_allclose(np.cross(right, up), -forward, atol=1e-12)
    np.testing.assert_allclose([forward @ right, forward @ up, right @ up], 0.0, atol=1e-12)


def test_glsl_uniforms_rebuild_the_numpy_rays():
    cam = Camera((2.0, -1.0, 4.0), (0.0, 0.5, 0.0), up=(0.2, 0.0, 1.0), fov_deg=35.0)
    w, h = 7, 5
    u = cam.glsl_uniforms(w, h)
    assert u["u_cam_size"] == (w, h)
    _, d = cam.rays(w, h)
    for i in range(h):
        for j in range(w):
            sx, sy = (j + 0.5) / w, (i + 0.5) / h
            r = (np.array(u["u_cam_forward"]) + (2 * sx - 1) * np.array(u["u_cam_right"])
                 + (1 - 2 * sy) * np.array(u["u_cam_up"]))
            np.testing.assert_allclose(r / np.linalg.norm(r), d[i, j], atol=1e-12)


def test_parse_and_format_round_trip():
    cam = parse_camera(" 3, -4.5 ,2.25,0,0,0.1, 42 ")
    np.testing.assert_array_equal(cam.eye, [3, -4.5, 2.25])
    np.testing.assert_array_equal(cam.target, [0, 0, 0.1])
    assert cam.fov_deg == 42.0 and tuple(cam.up) == (0, 0, 1)
    again = parse_camera(format_camera(cam))
    np.testing.assert_array_equal(again.eye, cam.eye)
    np.testing.assert_array_equal(again.target, cam.target)
    assert again.fov_deg == cam.fov_deg and cam.format() == format_camera(cam)
    third = Camera((0.1, 0.2, 0.3), (1 / 3, 2 / 7, 1e-9), fov_deg=33.3)
    np.testing.assert_array_equal(parse_camera(third.format()).target, third.target)
    # straight down z: up falls back to +y
    assert tuple(parse_camera("0,0,5,0,0,0,30").up) == (0, 1, 0)


@pytest.mark.parametrize("text, match", [
    ("1,2,3,4,5,6", "7 comma-separated"), ("1,2,3,4,5,6,7,8", "7 comma-separated"),
    ("1,2,x,4,5,6,30", "non-number"), ("1,2,3,4,5,nan,30", "finite"), ("1,2,3,1,2,3,30", "differ"),
    ("0,0,5,0,0,0,180", "fov_deg"), ("0,0,5,0,0,0,0", "fov_deg"), ("", "7 comma-separated"),
])
def test_parse_errors_name_the_problem(text, match):
    with pytest.raises(ValueError, match=match):
        parse_camera(text)


def test_bad_cameras_are_refused():
    with pytest.raises(ValueError, match="eye"):
        Camera((0, 0), (1, 1, 1))
    with pytest.raises(ValueError, match="up"):
        Camera((0, 0, 0), (0, 0, 1), up=(0, 0, 2))
    with pytest.raises(ValueError, match="up"):
        Camera((0, 0, 0), (1, 0, 0), up=(0, 0, 0))
    with pytest.raises(ValueError, match="fov_deg"):
        Camera((0, 0, 0), (1, 0, 0), fov_deg=float("nan"))
    with pytest.raises(ValueError, match="width"):
        Camera((0, 0, 0), (1, 0, 0)).rays(0, 4)
    with pytest.raises(ValueError, match="height"):
        Camera((0, 0, 0), (1, 0, 0)).rays(4, 2.5)
    with pytest.raises(ValueError, match="string"):
        parse_camera(None)
    with pytest.raises(ValueError, match="Camera"):
        format_camera("0,0,0")
