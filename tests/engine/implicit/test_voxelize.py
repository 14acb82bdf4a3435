"""SDFs to Solids (`engine.implicit.voxelize`, `engine.gpu.sdf_voxels`): closed-form volumes,
the GPU nodes against numpy's, periodic meshes that tile, and refusals before work."""

import math

import numpy as np
import pytest

from engine.geometry.marching import boundary_section_match, mesh_volume
from engine.gpu.sdf_voxels import sample_box
from engine.implicit.combine import Union
from engine.implicit.periodic import Periodic
from engine.implicit.shapes import Primitive
from engine.implicit.voxelize import grid_nodes, sample_nodes, solid_from_samples
from engine.progress import Cancelled


def test_grid_nodes_cover_the_box_with_the_longest_edge_at_the_resolution():
    o, h, n = grid_nodes((1.0, 0.0, -1.0), (3.0, 1.0, 0.0), 40, periodic=False)
    assert n == (41, 21, 21) and np.allclose(o + h * (np.array(n) - 1), (3.0, 1.0, 0.0))
    _, h, n = grid_nodes((0, 0, 0), (2.0, 1.0, 1.0), 40, periodic=True)
    assert n == (40, 20, 20) and np.allclose(h * n, (2.0, 1.0, 1.0))


def test_a_ball_in_a_box_has_the_closed_form_volume_and_a_watertight_capped_mesh():
    ball = Primitive("sphere", (0.6,), centre=(0.1, 0.0, 0.0))
    lo, hi = (-1.0, -1.0, -1.0), (1.0, 1.0, 0.3)          # cut by the top face: a capped cap
    samples, _ = sample_box(ball, lo, hi, 96, periodic=False, backend="numpy")
    solid = solid_from_samples(samples, lo, hi, periodic=False)
    h = 0.3                                               # the cut ball: sphere minus the cap above z = 0.3
    cap = math.pi * (0.6 - h) ** 2 * (3 * 0.6 - (0.6 - h)) / 3
    want = 4 / 3 * math.pi * 0.6 ** 3 - cap
    assert mesh_volume(solid.vertices, solid.faces) == pytest.approx(want, rel=0.01)
    _, counts = np.unique(np.sort(solid.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1),
                          axis=0, return_counts=True)
    assert np.all(counts == 2)                            # every edge shared by two triangles
    assert not solid.periodic and np.allclose(solid.box, (2.0, 2.0, 1.3))
    assert solid.vertices.min() >= 0 and np.all(solid.vertices.max(axis=0) <= solid.box + 1e-12)


def test_a_gyroid_cell_is_half_solid_and_its_mesh_tiles():
    g = Periodic("gyroid", cell=2.0, level=0.0)
    samples, _ = sample_box(g, (0, 0, 0), (2, 2, 2), 48, periodic=True, backend="numpy")
    solid = solid_from_samples(samples, (0, 0, 0), (2, 2, 2), periodic=True)
    assert solid.periodic and solid.cell_size == 2.0 and solid.cell == (1.0, 1.0, 1.0)
    assert mesh_volume(solid.vertices, solid.faces) / 8.0 == pytest.approx(0.5, abs=0.01)
    # a level off the exact zeros the gyroid has on the cell faces, where marching cubes would
    # put vertices on grid nodes (nudged) and the face sections differ by float32 rounding
    shifted = Periodic("gyroid", cell=2.0, level=0.1, matrix=np.eye(3))
    samples, _ = sample_box(shifted, (0.3, 0.1, -0.2), (2.3, 2.1, 1.8), 48, periodic=True, backend="numpy")
    tile = solid_from_samples(samples, (0.3, 0.1, -0.2), (2.3, 2.1, 1.8), periodic=True)
    assert boundary_section_match(tile.vertices, tile.faces, cell_size=2.0) < 1e-9


def test_the_gpu_nodes_are_numpys_in_float32(gpu):
    cloud = Union((Periodic("schwarz_p", cell=0.7, level=0.3), Primitive("torus", (0.5, 0.2))))
    lo, hi = (-0.8, -0.6, -0.5), (0.9, 0.6, 0.4)
    ref, used = sample_box(cloud, lo, hi, 33, periodic=False, backend="numpy")
    got, used_gpu = sample_box(cloud, lo, hi, 33, periodic=False, backend="gpu")
    assert (used, used_gpu) == ("numpy", "gpu") and got.shape == ref.shape
    assert np.abs(got - ref).max() < 1e-5
    o, h, n = grid_nodes(lo, hi, 33, periodic=False)
    x, y, z = (o[a] + np.arange(n[a]) * h[a] for a in range(3))
    assert got[5, 7, 3] == pytest.approx(cloud.distance([x[5], y[7], z[3]])[0], abs=1e-5)


def test_sampling_reports_progress_and_cancels():
    seen = []
    g = Periodic("gyroid", cell=1.0)
    o, h, n = grid_nodes((0, 0, 0), (1, 1, 1), 200, periodic=True)
    sample_nodes(g, o, h, n, progress=lambda d, t: seen.append((d, t)) or True)
    assert seen[0] == (0, 200) and seen[-1] == (200, 200) and len(seen) >= 3
    with pytest.raises(Cancelled):
        sample_nodes(g, o, h, n, progress=lambda d, t: d == 0)


@pytest.mark.parametrize("lo, hi, match", [((0, 0, 0), (1, 0, 1), "every edge must be > 0"),
                                           ((0, 0), (1, 1, 1), "three finite")])
def test_bad_boxes_are_refused(lo, hi, match):
    with pytest.raises(ValueError, match=match):
        grid_nodes(lo, hi, 32, periodic=False)


def test_an_empty_or_full_box_is_refused_with_a_message():
    ball = Primitive("sphere", (0.2,))
    samples, _ = sample_box(ball, (2, 2, 2), (3, 3, 3), 16, periodic=False, backend="numpy")
    with pytest.raises(ValueError, match="nothing of the medium"):
        solid_from_samples(samples, (2, 2, 2), (3, 3, 3), periodic=False)
    samples, _ = sample_box(ball, (-0.05,) * 3, (0.05,) * 3, 16, periodic=False, backend="numpy")
    with pytest.raises(ValueError, match="fills the whole box"):
        solid_from_samples(samples, (-0.05,) * 3, (0.05,) * 3, periodic=False)
