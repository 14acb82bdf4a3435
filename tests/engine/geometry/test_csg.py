"""Boolean ops on SDF grids; volumes of two crossing beams against the
Steinmetz solid (intersection of two perpendicular cylinders: 16 r^3 / 3)."""

import numpy as np
import pytest

from engine.geometry.csg import csg_difference, csg_intersection, csg_reduce, csg_union
from engine.geometry.marching import mesh_volume, periodic_mesh

N, R = 64, 0.2


def _beam(axis):
    """Closed-form SDF of an infinite periodic beam along `axis` through the cell centre."""
    x = np.arange(N) / N
    p = np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1)
    others = [i for i in range(3) if i != axis]
    return (np.linalg.norm(p[..., others] - 0.5, axis=-1) - R).astype(np.float32)


@pytest.fixture(scope="module")
def beams():
    return _beam(0), _beam(1)


def _volume(field):
    return mesh_volume(*periodic_mesh(field))


def test_volumes_match_inclusion_exclusion(beams):
    a, b = beams
    cyl = np.pi * R ** 2                   # one beam through a unit cell
    steinmetz = 16 * R ** 3 / 3
    assert abs(_volume(a) / cyl - 1) < 0.01
    assert abs(_volume(csg_intersection(a, b)) / steinmetz - 1) < 0.02
    assert abs(_volume(csg_union(a, b)) / (2 * cyl - steinmetz) - 1) < 0.01
    assert abs(_volume(csg_difference(a, b)) / (cyl - steinmetz) - 1) < 0.02


def test_pointwise_definitions(beams):
    a, b = beams
    np.testing.assert_array_equal(csg_union(a, b), np.minimum(a, b))
    np.testing.assert_array_equal(csg_intersection(a, b), np.maximum(a, b))
    np.testing.assert_array_equal(csg_difference(a, b), np.maximum(a, -b))
    assert csg_union(a, b).dtype == np.float32


def test_reduce(beams):
    a, b = beams
    c = _beam(2)
    np.testing.assert_array_equal(csg_reduce([a, b, c], "union"), np.minimum(np.minimum(a, b), c))
    np.testing.assert_array_equal(csg_reduce([a, b, c], "intersection"), np.maximum(np.maximum(a, b), c))
    np.testing.assert_array_equal(csg_reduce([a, b, c], "difference"), np.maximum(np.maximum(a, -b), -c))
    single = csg_reduce([a], "union")
    np.testing.assert_array_equal(single, a)
    assert single is not a


def test_inputs_are_not_mutated(beams):
    a, b = beams
    a0, b0 = a.copy(), b.copy()
    csg_difference(a, b)
    csg_reduce([a, b], "difference")
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(b, b0)


def test_shape_mismatch_names_both_shapes():
    with pytest.raises(ValueError, match=r"\(4, 4, 4\).*\(8, 8, 8\)"):
        csg_union(np.zeros((4, 4, 4)), np.zeros((8, 8, 8)))
    with pytest.raises(ValueError, match=r"fields\[2\] \(8, 8, 8\)"):
        csg_reduce([np.zeros((4, 4, 4))] * 2 + [np.zeros((8, 8, 8))], "union")


def test_reduce_refuses_bad_arguments():
    with pytest.raises(ValueError, match="op must be one of"):
        csg_reduce([np.zeros((2, 2, 2))], "xor")
    with pytest.raises(ValueError, match="at least one"):
        csg_reduce([], "union")
