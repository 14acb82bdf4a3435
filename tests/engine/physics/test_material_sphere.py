"""Material sphere and polar plot against closed forms: an isotropic solid
is a sphere of radius E; a cubic one reaches E_100 and E_111 in the <100>
and <111> directions, which is the maximum depends on the Zener ratio."""

import numpy as np
import pytest
import trimesh

from engine.physics.elastic import isotropic_plane_stress, isotropic_stiffness
from .test_elastic import cubic
from engine.physics.material_sphere import material_polar, material_sphere, material_sphere_polydata



def e100_e111(c11, c12, c44):
    e100 = (c11 - c12) * (c11 + 2 * c12) / (c11 + c12)
    s11 = (c11 + c12) / ((c11 - c12) * (c11 + 2 * c12))
    s12 = -c12 / ((c11 - c12) * (c11 + 2 * c12))
    s44 = 1 / c44
    e111 = 1 / (s11 - 2 * (s11 - s12 - s44 / 2) / 3)
    return e100, e111


def angle_to_family(d, family):
    """Smallest angle (degrees) between unit d and any member of a <hkl> family."""
    if family == "100":
        members = np.eye(3)
    else:
        members = np.array([[1, a, b] for a in (1, -1) for b in (1, -1)]) / np.sqrt(3)
    return np.degrees(np.arccos(np.clip(np.abs(members @ d).max(), -1, 1)))


@pytest.mark.parametrize("subdivisions", [0, 2, 4])
def test_isotropic_sphere_has_radius_E(subdivisions):
    v, f, e = material_sphere(isotropic_stiffness(3.0, 0.3), subdivisions=subdivisions)
    assert v.shape == (10 * 4 ** subdivisions + 2, 3) and e.shape == (v.shape[0],)
    assert np.allclose(np.linalg.norm(v, axis=1), 3.0, rtol=1e-12)
    assert np.allclose(e, 3.0, rtol=1e-12)
    mesh = trimesh.Trimesh(v, f, process=False)
    assert mesh.is_watertight and mesh.volume > 0  # closed and outward-wound


@pytest.mark.parametrize("c", [(168.4, 121.4, 75.4), (200.0, 100.0, 20.0)])
def test_cubic_extremes_at_100_and_111(c):
    e100, e111 = e100_e111(*c)
    v, f, e = material_sphere(cubic(*c), subdivisions=4)
    d = v / e[:, None]
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    lo, hi = sorted((e100, e111))
    assert e.min() >= lo * (1 - 1e-12) and e.max() <= hi * (1 + 1e-12)
    assert e.min() == pytest.approx(lo, rel=1e-2) and e.max() == pytest.approx(hi, rel=1e-2)
    stiff, soft = ("111", "100") if 2 * c[2] / (c[0] - c[1]) > 1 else ("100", "111")
    assert angle_to_family(d[np.argmax(e)], stiff) < 5
    assert angle_to_family(d[np.argmin(e)], soft) < 5


def test_compliance_quantity_is_reciprocal():
    C = cubic(168.4, 121.4, 75.4)
    v, _, e = material_sphere(C, subdivisions=2)
    vc, _, ec = material_sphere(C, subdivisions=2, quantity="compliance")
    assert np.allclose(ec, 1 / e) and np.allclose(np.linalg.norm(vc, axis=1), 1 / e)


def test_polydata_carries_E():
    C = cubic(168.4, 121.4, 75.4)
    v, f, e = material_sphere(C, subdivisions=3)
    mesh = material_sphere_polydata(C, subdivisions=3)
    assert mesh.n_points == v.shape[0] and mesh.n_cells == f.shape[0]
    assert np.allclose(mesh.points, v) and np.allclose(mesh.point_data["E"], e)
    assert mesh.active_scalars_name == "E"
    assert "1/E" in material_sphere_polydata(C, subdivisions=1, quantity="compliance").point_data


def test_polar_isotropic_and_square():
    theta, e = material_polar(isotropic_plane_stress(2.0, 0.3), n=90)
    assert theta.shape == e.shape == (90,) and theta[0] == 0 and theta[-1] < 2 * np.pi
    assert np.allclose(e, 2.0, rtol=1e-12)
    sq = np.array([[10.0, 3.0, 0.0], [3.0, 10.0, 0.0], [0.0, 0.0, 1.0]])
    S = np.linalg.inv(sq)
    theta, e = material_polar(sq, n=8)
    e0, e45 = 1 / S[0, 0], 4 / (S[0, 0] + S[1, 1] + 2 * S[0, 1] + S[2, 2])
    assert np.allclose(e, [e0, e45] * 4, rtol=1e-12)
    _, ec = material_polar(sq, n=8, quantity="compliance")
    assert np.allclose(ec, 1 / e)


@pytest.mark.parametrize("call,words", [
    (lambda: material_sphere(isotropic_plane_stress(1, 0.3)), ["6x6", "material_polar"]),
    (lambda: material_polar(isotropic_stiffness(1, 0.3)), ["3x3", "material_sphere"]),
    (lambda: material_sphere(isotropic_stiffness(1, 0.3), subdivisions=9), ["subdivisions", "9"]),
    (lambda: material_sphere(isotropic_stiffness(1, 0.3), subdivisions=2.0), ["subdivisions"]),
    (lambda: material_sphere(isotropic_stiffness(1, 0.3), quantity="E"), ["quantity", "'E'"]),
    (lambda: material_polar(isotropic_plane_stress(1, 0.3), n=2), ["n", "2"]),
    (lambda: material_sphere(np.diag([1.0, 1, 1, 1, 1, 0])), ["positive definite"]),
])
def test_refusals(call, words):
    with pytest.raises(ValueError) as err:
        call()
    for w in words:
        assert w in str(err.value)
