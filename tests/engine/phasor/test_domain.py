import math
import re

import numpy as np
import pytest
import trimesh

from engine.phasor.domain import (box_of, check_closed, domain_grid, inside_mask, load_domain_mesh,
                                  slice_domain)


def _cube(size=2.0):
    return trimesh.creation.box(extents=(size, size, size))


def _sphere(r=1.0):
    return trimesh.creation.icosphere(subdivisions=4, radius=r)


def test_cube_inside_and_outside_points():
    rng = np.random.default_rng(0)
    inner = rng.uniform(-0.9, 0.9, size=(200, 3))
    outer = rng.uniform(-3.0, 3.0, size=(400, 3))
    outer = outer[np.abs(outer).max(axis=1) > 1.1]
    assert inside_mask(_cube(), inner).all()
    assert not inside_mask(_cube(), outer).any()


def test_sphere_inside_matches_the_closed_form_away_from_the_surface():
    rng = np.random.default_rng(1)
    p = rng.uniform(-1.5, 1.5, size=(3000, 3))
    r = np.linalg.norm(p, axis=1)
    clear = np.abs(r - 1.0) > 0.02
    got = inside_mask(_sphere(), p)
    assert np.array_equal(got[clear], (r < 1.0)[clear])


def test_sphere_volume_from_the_grid():
    lo, hi, shape = np.full(3, -1.1), np.full(3, 1.1), (32, 32, 32)
    mask = domain_grid(_sphere(), lo, hi, shape)
    volume = mask.mean() * 2.2 ** 3
    assert volume == pytest.approx(4.0 / 3.0 * math.pi, rel=0.03)
    # symmetric grid, symmetric sphere
    assert np.array_equal(mask, mask[::-1]) and np.array_equal(mask, mask.transpose(2, 1, 0))


def test_inside_out_mesh_still_has_its_inside():
    cube = _cube()
    flipped = (np.asarray(cube.vertices), np.asarray(cube.faces)[:, ::-1])
    assert inside_mask(flipped, [[0.0, 0.0, 0.0]]).all()
    assert not inside_mask(flipped, [[3.0, 0.0, 0.0]]).any()


def test_load_refuses_an_open_cube_naming_the_boundary(tmp_path):
    cube = _cube()
    top = np.flatnonzero(cube.triangles_center[:, 2] > 0.99)
    assert len(top) == 2
    faces = np.delete(np.asarray(cube.faces), top, axis=0)
    path = tmp_path / "open.stl"
    trimesh.Trimesh(cube.vertices, faces, process=False).export(path)
    with pytest.raises(ValueError) as err:
        load_domain_mesh(path)
    msg = str(err.value)
    assert "not closed" in msg and "4 boundary edge" in msg and "open.stl" in msg
    # both ends of the edge named lie on the rim of the missing face (z = +1)
    ends = re.findall(r"\(([-\d.e+]+), ([-\d.e+]+), ([-\d.e+]+)\) mm", msg)
    assert len(ends) == 2 and all(float(z) == 1.0 for _, _, z in ends)


def test_load_accepts_a_closed_cube_and_turns_an_inside_out_one(tmp_path):
    cube = _cube()
    path = tmp_path / "cube.obj"
    trimesh.Trimesh(cube.vertices, np.asarray(cube.faces)[:, ::-1], process=False).export(path)
    mesh = load_domain_mesh(path)
    assert mesh.volume == pytest.approx(8.0)
    stl = tmp_path / "cube.stl"
    cube.export(stl)
    assert load_domain_mesh(stl).volume == pytest.approx(8.0)


def test_non_manifold_inconsistent_and_flat_meshes_are_refused():
    cube = _cube()
    v, f = np.asarray(cube.vertices), np.asarray(cube.faces)
    with pytest.raises(ValueError, match="non-manifold edge"):
        check_closed(v, np.vstack([f, f[:1]]))
    flipped = f.copy()
    flipped[0] = flipped[0, ::-1]
    with pytest.raises(ValueError, match="not consistently oriented: 3 edge"):
        check_closed(v, flipped)
    tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match="encloses no volume"):
        check_closed(tri, np.array([[0, 1, 2], [0, 2, 1]]))


def test_sphere_slice_at_the_equator_is_a_disc():
    r = 10.0
    mask = slice_domain(_sphere(r), "z", 0.0, lo=(-12.0, -12.0), hi=(12.0, 12.0), shape=(500, 500))
    area = mask.sum() * (24.0 / 500) ** 2
    assert area == pytest.approx(math.pi * r * r, rel=0.02)
    assert mask[250, 250] and not mask[0, 0] and not mask[250, 2]


@pytest.mark.parametrize("axis, position, lo, hi, u_range, v_range", [
    ("z", 2.5, (-1, -1), (3, 5), (0, 2), (0, 4)),   # (u, v) = (x, y)
    ("y", 1.5, (-1, -1), (3, 7), (0, 2), (0, 6)),   # (u, v) = (x, z)
    ("x", 0.5, (-1, -1), (5, 7), (0, 4), (0, 6)),   # (u, v) = (y, z)
])
def test_box_slices_are_rectangles_in_the_documented_frame(axis, position, lo, hi, u_range, v_range):
    box = trimesh.creation.box(extents=(2.0, 4.0, 6.0))
    box.apply_translation((1.0, 2.0, 3.0))  # spans x 0..2, y 0..4, z 0..6
    shape = (37, 29)  # pixel centres never on an edge
    mask = slice_domain(box, axis, position, lo=lo, hi=hi, shape=shape)
    us = lo[0] + (np.arange(shape[1]) + 0.5) * (hi[0] - lo[0]) / shape[1]
    vs = lo[1] + (np.arange(shape[0]) + 0.5) * (hi[1] - lo[1]) / shape[0]
    want = ((vs[:, None] > v_range[0]) & (vs[:, None] < v_range[1])
            & (us[None, :] > u_range[0]) & (us[None, :] < u_range[1]))
    assert np.array_equal(mask, want)


def test_slice_through_a_face_plane_is_half_open():
    cube = _cube()  # z from -1 to 1
    bottom = slice_domain(cube, "z", -1.0, lo=(-2, -2), hi=(2, 2), shape=(8, 8))
    top = slice_domain(cube, "z", 1.0, lo=(-2, -2), hi=(2, 2), shape=(8, 8))
    assert bottom.sum() == 16 and not top.any()
    assert not slice_domain(cube, "z", 5.0, lo=(-2, -2), hi=(2, 2), shape=(8, 8)).any()


def test_slice_agrees_with_winding_numbers_on_a_torus():
    torus = trimesh.creation.torus(major_radius=3.0, minor_radius=1.0)
    shape, lo, hi = (60, 80), np.array([-4.5, -4.5]), np.array([4.5, 4.5])
    z = 0.37
    mask = slice_domain(torus, "z", z, lo=lo, hi=hi, shape=shape)
    us = lo[0] + (np.arange(shape[1]) + 0.5) * (hi[0] - lo[0]) / shape[1]
    vs = lo[1] + (np.arange(shape[0]) + 0.5) * (hi[1] - lo[1]) / shape[0]
    uu, vv = np.meshgrid(us, vs)
    pts = np.column_stack([uu.ravel(), vv.ravel(), np.full(uu.size, z)])
    wn = inside_mask(torus, pts).reshape(shape)
    # away from the surface (closed form for the exact torus) the two agree
    rho = np.hypot(uu, vv)
    d = np.hypot(rho - 3.0, z) - 1.0
    clear = np.abs(d) > 0.05
    assert mask.any() and np.array_equal(mask[clear], wn[clear])


def test_box_of_adds_the_margin():
    lo, hi = box_of(_cube(), 0.5)
    np.testing.assert_allclose(lo, -1.5)
    np.testing.assert_allclose(hi, 1.5)
    with pytest.raises(ValueError, match="margin"):
        box_of(_cube(), -1.0)
