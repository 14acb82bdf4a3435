"""The Schwarz D -> gyroid -> Schwarz P associate family from one discrete D
patch (the Plateau solution in a Petrie hexagon of a cube).

References: area per cubic cell of edge 1 -- P 2.3451, D 3.8377, gyroid
3.0915 (published values quoted in the task). Counting patches uses
Gauss-Bonnet: the hexagon's six right-angled corners between geodesic
edges give total curvature 2 pi - 6 (pi / 2) = -pi per patch, and a cell of
Euler characteristic chi holds -2 chi patches: P (genus 3, cubic cell)
8, the gyroid's cubic cell (two genus-3 primitive cells) 16.
"""

import math

import numpy as np
import pytest

from engine.geometry.surfaces.associate import (BONNET_ANGLE_DEG, associate_periods,
                                                associate_surface, lattice_basis)
from engine.geometry.surfaces.conjugate import conjugate_surface
from engine.geometry.surfaces.curvature import face_areas
from engine.geometry.surfaces.plateau import solve_plateau

L = 0.25                          # hexagon cube edge; the D cell has edge 4 L = 1


@pytest.fixture(scope="module")
def d_patch():
    corners = L * np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1], [1, 0, 1]], float)
    surf = solve_plateau(corners, edge_length=6 * L / 96, tol=1e-7, max_iter=100)
    b, src = np.asarray(surf.boundary), np.asarray(surf.source)
    at = np.flatnonzero(src >= 0)
    segments = [np.append(b[at[k]:(at[k + 1] if k < 5 else b.size)], b[at[(k + 1) % 6]])
                for k in range(6)]
    conj = conjugate_surface(surf.vertices, surf.faces)
    return surf, conj, segments


def _lattice(d_patch, degrees):
    surf, conj, segments = d_patch
    tau = associate_periods(surf.vertices, conj.vertices, segments, math.radians(degrees),
                            max_word=4)
    return lattice_basis(tau)


def test_family_ends_are_the_surface_and_its_conjugate(d_patch):
    surf, conj, _ = d_patch
    assert np.allclose(associate_surface(surf.vertices, surf.faces, 0.0, conjugate=conj).vertices,
                       surf.vertices)
    assert np.allclose(associate_surface(surf.vertices, surf.faces, math.pi / 2,
                                         conjugate=conj).vertices, conj.vertices, atol=1e-12)


def test_every_member_is_isometric_on_the_midpoint_triangles(d_patch):
    surf, conj, _ = d_patch
    ref = None
    for phi in (0.0, 0.3, math.radians(BONNET_ANGLE_DEG), 1.2):
        g = associate_surface(surf.vertices, surf.faces, phi, conjugate=conj)
        area = face_areas(g.midpoints, g.face_edges).sum()
        ref = area if ref is None else ref
        assert abs(area / ref - 1) < 1e-5          # the closure error of a 1e-7 Plateau solve


def test_d_and_p_lattices(d_patch):
    surf, _, _ = d_patch
    basis, resid, _ = _lattice(d_patch, 0.0)
    assert resid < 1e-9
    # D: face-centred cubic with cubic edge 4 L = 1 (vectors (1/2)(1,1,0)).
    assert np.allclose(np.linalg.norm(basis, axis=1), math.sqrt(0.5))
    assert math.isclose(abs(np.linalg.det(basis)), 0.25, rel_tol=1e-9)
    # P (phi = 90 deg): simple cubic; 8 patches per cell give 2.3451 a^2.
    basis, resid, _ = _lattice(d_patch, 90.0)
    a_p = np.linalg.norm(basis, axis=1)
    assert resid < 1e-6 and np.ptp(a_p) < 1e-4 * a_p.mean()
    assert np.allclose(basis @ basis.T / a_p.mean() ** 2, np.eye(3), atol=1e-4)
    area = 8 * surf.area / a_p.mean() ** 2
    assert abs(area / 2.3451 - 1) < 0.0015


def test_gyroid_at_the_bonnet_angle(d_patch):
    surf, conj, _ = d_patch
    basis, resid, zero = _lattice(d_patch, BONNET_ANGLE_DEG)
    # The translations close up into a lattice (up to discretisation)...
    assert resid < 5e-3 and zero < 1e-3
    # ... which is body-centred cubic: equal shortest vectors a (1/2)(+-1,+-1,+-1)
    # with pairwise cosines +-1/3.
    lengths = np.linalg.norm(basis, axis=1)
    cosines = (basis @ basis.T / np.outer(lengths, lengths))[np.triu_indices(3, 1)]
    assert np.ptp(lengths) < 1e-3 * lengths.mean()
    assert np.allclose(np.abs(cosines), 1 / 3, atol=2e-3)
    a_g = 2 * lengths.mean() / math.sqrt(3)
    g = associate_surface(surf.vertices, surf.faces, math.radians(BONNET_ANGLE_DEG),
                          conjugate=conj)
    patch_area = face_areas(g.vertices, g.faces).sum()
    area = 16 * patch_area / a_g ** 2
    assert abs(area / 3.0915 - 1) < 0.0015
    # Lattice ratios of the family (same metric): a_G / a_D ~ 0.788.
    assert abs(a_g - 0.788) < 0.002


def test_other_angles_are_not_periodic(d_patch):
    _, resid, _ = _lattice(d_patch, 30.0)
    assert resid > 0.1
