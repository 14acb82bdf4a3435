"""The diamond cells in 3D (engine.phasor.volume): half the volume of constant
fields, a closed surface, clipped to the part, cancellable, refusals named."""

import time

import numpy as np
import pytest
import trimesh

from engine.progress import Cancelled
from engine.geometry.marching import mesh_volume
from engine.phasor.fields import constant_fields
from engine.phasor.infill import sample_infill
from engine.phasor.noise import diamond_mask
from engine.phasor.volume import (MAX_VOXELS, OUTSIDE, check_sub_box, diamond_indicator, diamond_surface,
                                  diamond_volume, voxel_counts)

BOX = ([0.0, 0.0, 0.0], [10.0, 10.0, 10.0])
# 4 periods of F = 1 cell/mm along y and z, where the two noises run when D = x
SUB = ([3.0, 3.0, 3.0], [7.0, 7.0, 7.0])


@pytest.fixture(scope="module")
def constant_infill():
    fields = constant_fields(*BOX, (8, 8, 8), direction=(1.0, 0.0, 0.0), frequency=1.0, spread=0.0)
    return sample_infill(fields, iterations=20, rng=5)


@pytest.fixture(scope="module")
def constant_volume(constant_infill):
    return diamond_volume(constant_infill, *SUB, voxel=0.2)


def test_the_indicator_is_the_diamond_test_and_covers_half_the_unit_square():
    n = 800
    p, q = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
    d = diamond_indicator(p, q)
    assert np.array_equal(d < 0, diamond_mask(p, q))
    # |1/2 - p| + |1/2 - q| < 1/2 is the square of half-diagonal 1/2: area 2 (1/2)^2 = 1/2
    assert np.mean(d < 0) == pytest.approx(0.5, abs=2.0 / n)
    assert d.min() >= -0.5 and d.max() <= 0.5


def test_constant_fields_fill_half_the_sub_box(constant_volume):
    vol = constant_volume
    assert vol.indicator.shape == (21, 21, 21) and np.allclose(vol.spacing, 0.2)
    assert vol.state == "aligned+filtered" and not vol.indicator.flags.writeable
    v, f = diamond_surface(vol)
    box_volume = 4.0 ** 3
    assert mesh_volume(v, f) / box_volume == pytest.approx(0.5, abs=0.03)
    # D = x: the cells are prisms along x, so every x line of nodes is all in or all out
    inside = vol.indicator < 0
    assert np.mean(inside.all(axis=0) | ~inside.any(axis=0)) > 0.95


def test_the_surface_is_closed_outward_and_within_the_sub_box(constant_volume):
    v, f = diamond_surface(constant_volume)
    mesh = trimesh.Trimesh(v, f, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    assert np.all(v >= np.array(SUB[0]) - 1e-9) and np.all(v <= np.array(SUB[1]) + 1e-9)
    # the prisms along x are capped on the x faces of the sub-box
    assert v[:, 0].min() == SUB[0][0] and v[:, 0].max() == SUB[1][0]


def test_a_part_clips_the_cells(constant_infill):
    # 2 periods along y and z; nodes 0.2 mm apart from 3 mm: x 4.2 .. 5.8, y and z 4.2 .. 6.0 are inside
    hi = np.array([5.9, 6.1, 6.1])
    part = trimesh.creation.box(bounds=[[4.1, 4.1, 4.1], hi])
    infill = sample_infill(constant_infill.fields, domain=part, iterations=20, rng=5)
    vol = diamond_volume(infill, *SUB, voxel=0.2)
    nodes = np.stack(np.meshgrid(*[np.linspace(3, 7, 21)] * 3, indexing="ij"), axis=-1)
    outside = ~np.all((nodes > 4.1) & (nodes < hi), axis=-1)
    assert np.all(vol.indicator[outside] == OUTSIDE) and np.all(vol.indicator[~outside] < OUTSIDE)
    v, f = diamond_surface(vol)
    mesh = trimesh.Trimesh(v, f, process=False)
    assert mesh.is_watertight and mesh.volume > 0
    # a wall between an inside node (d in [-1/2, 0)) and an outside one (1/2) lies within
    # half a voxel of the inside node: the cells fill between 1.6 x 1.8 x 1.8 and 1.8 x 2 x 2 mm
    assert np.all(v >= 4.1) and np.all(v <= hi)
    half = mesh.volume / 0.5
    assert 1.6 * 1.8 * 1.8 * 0.95 <= half <= 1.8 * 2 * 2 * 1.05


def _cancel_after(calls):
    seen = []

    def progress(done, total):
        seen.append(time.perf_counter())
        return len(seen) < calls
    return progress, seen


def test_sampling_and_meshing_cancel(constant_infill, constant_volume):
    progress, seen = _cancel_after(4)
    with pytest.raises(Cancelled):
        diamond_volume(constant_infill, *SUB, voxel=0.2, engine="numpy", progress=progress)
    assert len(seen) == 4
    progress, seen = _cancel_after(1)
    with pytest.raises(Cancelled):
        diamond_surface(constant_volume, progress=progress)
    # progress counts nodes, never goes back, ends at the total and comes at least
    # once per sampled plane (so a cancel waits for one plane at most)
    calls = []
    diamond_volume(constant_infill, *SUB, voxel=0.2, engine="numpy",
                   progress=lambda d, t: calls.append((d, t)) or True)
    assert calls[0] == (0, 21 ** 3) and calls[-1] == (21 ** 3, 21 ** 3)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))
    assert len(calls) >= 21


def test_refusals_name_the_argument(constant_infill):
    fields = constant_infill.fields
    with pytest.raises(ValueError, match=r"^lo: x = -1 mm lies outside the fields' box"):
        check_sub_box(fields, [-1, 0, 0], [5, 5, 5])
    with pytest.raises(ValueError, match=r"^hi: z = 11 mm lies outside"):
        check_sub_box(fields, [0, 0, 0], [5, 5, 11])
    with pytest.raises(ValueError, match=r"^hi: the sub-box is empty along y"):
        check_sub_box(fields, [0, 5, 0], [5, 5, 5])
    with pytest.raises(ValueError, match=r"^voxel: .*limit of 16,777,216 \(256\^3\)"):
        voxel_counts([0, 0, 0], [10, 10, 10], 0.03)
    assert voxel_counts([0, 0, 0], [10, 10, 10], 10 / 256).tolist() == [256] * 3
    assert MAX_VOXELS == 256 ** 3
    with pytest.raises(ValueError, match=r"^voxel: voxel 0.5 mm is too coarse for F up to 1"):
        diamond_volume(constant_infill, *SUB, voxel=0.5)
