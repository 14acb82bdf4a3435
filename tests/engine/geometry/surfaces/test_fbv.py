"""Fundamental bounding volumes: primitives, vertex location, the section 6.3
requirements of conjugate loops, and Algorithm 1's vertex angles/normals."""

import math

import numpy as np
import pytest

from engine.geometry.surfaces.fbv import (FBVError, FBVFitError, check_conjugate_loop,
                                          conjugate_violations, convex_volume, cuboid, fit_fbv,
                                          locate_points, loop_box, sliding_planes,
                                          sliding_violations, tetrahedron, triangular_prism,
                                          vertex_frames)

CUBE = cuboid((0, 0, 0), (0.5, 0.5, 0.5))
# 1/48 of the cubic cell: the mirror tetrahedron 0 <= z <= y <= x <= 1/2.
TET = tetrahedron([[0, 0, 0], [0.5, 0, 0], [0.5, 0.5, 0], [0.5, 0.5, 0.5]])


def p_hexagon(q=0.25):
    return np.array([[0, .5, q], [0, q, .5], [q, 0, .5], [.5, 0, q], [.5, q, 0], [q, .5, 0]])


def test_primitives_have_the_right_combinatorics():
    prism = triangular_prism([[0, 0, 0], [.5, 0, 0], [.5, .5, 0]], [0, 0, .5])
    for fbv, corners, edges in ((CUBE, 8, 12), (TET, 4, 6), (prism, 6, 9)):
        assert fbv.corners.shape[0] == corners
        assert len(fbv.edges) == edges
        # Outward normals: the centroid is strictly inside every half-space.
        assert np.all(fbv.signed_distances(fbv.corners.mean(axis=0)[None]) < 0)
    assert CUBE.is_aabb and not TET.is_aabb and not prism.is_aabb
    assert CUBE.labels[1] == "x = 0.5"


def test_custom_volume_refuses_redundant_and_unbounded_planes():
    normals = list(CUBE.normals) + [[1, 0, 0]]
    offsets = list(CUBE.offsets) + [2.0]                   # x <= 2 never touches the box
    with pytest.raises(ValueError, match="plane 6 .*does not carry a face"):
        convex_volume(normals, offsets)
    with pytest.raises(ValueError, match="finite volume|no volume"):
        convex_volume([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0]], [1, 1, 1, 1])
    with pytest.raises(ValueError, match="normals\\[1\\] is zero"):
        convex_volume([[1, 0, 0], [0, 0, 0], [0, 0, 1], [-1, 0, 0]], [1, 1, 1, 1])


def test_locate_points_reports_planes_and_inside():
    on, inside = locate_points(CUBE, [[0, 0.5, 0.25], [0.1, 0.1, 0.1], [0, 0, 0], [1, 0, 0]])
    assert on[0] == {0, 3} and on[1] == set() and on[2] == {0, 2, 4}
    assert inside.tolist() == [True, True, True, False]


def test_p_hexagon_frames_are_right_angles_along_cube_edges():
    loop = check_conjugate_loop(CUBE, p_hexagon())
    v_a, v_n = vertex_frames(CUBE, loop)
    assert np.allclose(v_a, math.pi / 2)
    # The normal is the direction of the FBV edge the vertex sits on.
    edge_dirs = np.array([[0, 0, 1], [0, 1, 0], [1, 0, 0]] * 2)
    assert np.allclose(np.abs(v_n), edge_dirs)
    assert loop.arc_planes.tolist() == [0, 5, 2, 1, 4, 3]   # x=0, z=.5, y=0, x=.5, z=0, y=.5


def test_tetrahedron_frames_match_its_dihedral_angles():
    # Schwarz P's 1/48 patch: vertices on edges OB, OC, AC, AB of the mirror
    # tetrahedron; the dihedral angles there are 90, 60, 90 and 90 degrees.
    loop = check_conjugate_loop(TET, [[1 / 3, 1 / 3, 0], [.25, .25, .25], [.5, 1 / 6, 1 / 6],
                                      [.5, .25, 0]])
    v_a, v_n = vertex_frames(TET, loop)
    assert np.allclose(np.degrees(v_a), [90, 60, 90, 90])
    assert np.allclose(np.abs(v_n[1]), np.ones(3) / math.sqrt(3))      # edge OC
    # Gauss-Bonnet: the patch has total curvature 2 pi - sum(pi - angle) =
    # -pi/6, i.e. 48 patches for the genus-3 cubic cell (chi = -4).
    assert math.isclose(2 * math.pi - np.sum(math.pi - v_a), -math.pi / 6)


def _rules(fbv, points):
    found, loop = conjugate_violations(fbv, points)
    assert loop is None
    return [(v.vertex, v.rule) for v in found], " | ".join(v.message for v in found)


def test_vertex_off_an_edge_is_refused_by_name():
    pts = p_hexagon()
    pts[2] = [0.25, 0.1, 0.5]                       # on face z = 0.5 only
    rules, text = _rules(CUBE, pts)
    assert (2, "on-edge") in rules
    assert "vertex 2 lies on face 'z = 0.5' only" in text


def test_vertex_at_a_corner_or_outside_is_refused():
    pts = p_hexagon()
    pts[4] = [0.5, 0.5, 0.0]
    rules, text = _rules(CUBE, pts)
    assert (4, "on-edge") in rules and "FBV corner" in text
    pts = p_hexagon()
    pts[1] = [0, 0.25, 0.7]
    rules, _ = _rules(CUBE, pts)
    assert (1, "inside") in rules


def test_loop_edge_off_a_face_is_refused():
    # Vertex 0 on edge x=0,y=.5 and vertex 1 on edge x=.5,y=0: no common plane.
    pts = np.array([[0, .5, .25], [.5, 0, .25], [.5, .25, 0], [.25, .5, 0]])
    rules, text = _rules(CUBE, pts)
    assert (0, "edge-on-face") in rules
    assert "loop edge from vertex 0 to vertex 1 does not lie on an FBV face" in text


def test_loop_that_does_not_turn_at_a_vertex_is_refused():
    # Vertex 1 sits on edge x=0,z=.5 but both its loop edges run on x=0.
    pts = np.array([[0, .5, .25], [0, .25, .5], [0, 0, .25], [.25, 0, 0], [.25, .5, 0]])
    rules, text = _rules(CUBE, pts)
    assert (1, "turn") in rules
    assert "both loop edges at it run on 'x = 0'" in text


def test_loops_whose_dual_cannot_close_are_refused():
    # Cutting off a cube corner: outward normals -x, -y, -z cannot sum to 0
    # with positive weights, so no surface meets the three planes at right
    # angles with its normal along the edges (the 6.3 inset's invalid case).
    rules, text = _rules(CUBE, [[.2, 0, 0], [0, .2, 0], [0, 0, .2]])
    assert rules == [(-1, "normals")]
    assert "the dual contour cannot close" in text
    # A rectangle lying in face y = 0, up and down two vertical edges.
    rules, _ = _rules(CUBE, [[0, 0, .1], [0, 0, .4], [.5, 0, .4], [.5, 0, .1]])
    assert rules == [(-1, "normals")]


def test_check_raises_with_every_violation():
    pts = p_hexagon()
    pts[2] = [0.25, 0.1, 0.5]
    pts[4] = [0.5, 0.5, 0.0]
    with pytest.raises(FBVError) as err:
        check_conjugate_loop(CUBE, pts)
    assert {v.vertex for v in err.value.violations} == {2, 4}
    assert "vertex 2" in str(err.value) and "vertex 4" in str(err.value)


def test_sliding_segments_must_lie_on_faces():
    pts = np.array([[0, .1, .1], [0, .4, .2], [.3, .4, .5], [.2, .2, .2]])
    found = sliding_violations(CUBE, pts, [True, False, True, False])
    assert [(v.vertex, v.rule) for v in found] == [(2, "sliding-on-face")]
    assert sliding_violations(CUBE, pts, [True, False, False, False]) == []


def test_fitted_volumes_hold_the_loop():
    # A flat loop: the box is widened across it, so no face holds the loop.
    square = [[0, 0, .5], [1, 0, .5], [1, 1, .5], [0, 1, .5]]
    lo, hi = loop_box(square)
    assert lo.tolist() == [0, 0, 0] and hi.tolist() == [1, 1, 1]
    assert fit_fbv("cuboid", square).is_aabb
    # The regular tetrahedron's skew quadrilateral: its alternate-corner tetrahedron.
    quad = np.array([[0, 0, 0], [1, 1, 0], [0, 1, 1], [1, 0, 1]], float) / 4
    tet = fit_fbv("tetrahedron", quad)
    assert tet.kind == "tetrahedron" and locate_points(tet, quad)[1].all()
    assert all(len(planes) == 3 for planes in locate_points(tet, quad)[0])   # corners


def test_fit_refusals_name_the_parameter():
    with pytest.raises(FBVFitError, match="at least 4 half-spaces") as err:
        fit_fbv("custom", [[0, 0, 0]], planes=[[[1, 0, 0], 1]])
    assert err.value.parameter == "fbv_planes"
    quad = np.array([[0, 0, 0], [1, 1, 0], [0, 1, 1], [1, 0, 1]], float) / 4
    with pytest.raises(FBVFitError, match="holds every loop vertex") as err:
        fit_fbv("prism", quad)
    assert err.value.parameter == "fbv"


def test_sliding_planes_pick_a_face_or_say_why_not():
    square = np.array([[0, 0, .5], [1, 0, .5], [1, 1, .5], [0, 1, .5]])
    box = fit_fbv("cuboid", square)
    chains = [square[[0, 1]], square[[1, 2]], square[[2, 3]], square[[3, 0]]]
    planes = sliding_planes(box, chains, [False, True, False, True], square)
    assert planes[0] is None and planes[2] is None
    assert sorted(box.labels[k] for k in (planes[1], planes[3])) == ["x = 0", "x = 1"]
    across = [np.array([[0, 0, .5], [1, 1, .5]])]
    (why,) = sliding_planes(box, across, [True], square)
    assert "sliding-on-face" in why


def test_points_typed_to_six_decimals_still_lie_on_oblique_faces():
    # A hexagonal prism piece (centre, edge midpoint, vertex of a unit
    # triangle): its side faces are at 30 and 60 degrees, so vertices typed
    # with six decimals sit up to ~1e-6 off them -- still "on the face".
    r = 1 / math.sqrt(3)
    c, s = math.sqrt(3) / 2, 0.5
    fbv = convex_volume([[-1, 0, 0], [s, -c, 0], [c, s, 0], [0, 0, -1], [0, 0, 1]], [0, 0, r / 2, 0, 0.2])
    typed = np.round([[r / 2 * c, r / 2 * s, 0.2], [0.15 * c, 0.15 * s, 0.0]], 6)
    on, inside = locate_points(fbv, typed)
    assert inside.all()
    assert len(on[0]) == 3 and len(on[1]) == 2          # top, side, mirror / bottom, mirror
    # ... while a point 1e-3 outside is refused.
    assert not locate_points(fbv, typed + [1e-3, 0, 0])[1][0]
