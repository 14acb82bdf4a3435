"""The per-bin kernel lists are complete: every (pixel, kernel) pair within
reach is listed for the pixel's bin (checked against all pairs)."""

import numpy as np
import pytest

from engine.phasor._slice_bins import bin_lists, project_kernels, tile_members
from engine.gpu.slice_plane import SlicePlane

from .test_phasor_slice import PLANES, random_kernels


@pytest.mark.parametrize("plane", list(PLANES.values()) + [
    SlicePlane([0.0, 0.0, 3.0], [1, 0, 0], [0, 1, 0], (14.0, 9.0), (40, 60))],  # non-square pixels
    ids=list(PLANES) + ["anisotropic"])
@pytest.mark.parametrize("rect", [(0, 0, 64, 64), (8, 16, 24, 40)])
@pytest.mark.parametrize("bin_px", [4, 8])
def test_every_pair_in_reach_is_listed(plane, rect, bin_px):
    k = random_kernels(3)
    reach = 1.3 * k.radius
    pk = project_kernels(k, plane, reach)
    r0, c0, th, tw = rect
    th, tw = min(th, plane.shape[0] - r0), min(tw, plane.shape[1] - c0)
    rect = (r0, c0, th, tw)
    members = tile_members(pk, plane, rect)
    bin_start, items = bin_lists(pk, members, plane, rect, bin_px)
    nbx = -(-tw // bin_px)
    assert len(bin_start) == nbx * -(-th // bin_px) + 1
    pts = plane.points(rows=np.arange(r0, r0 + th), cols=np.arange(c0, c0 + tw))
    d2 = np.sum((pts[:, :, None, :] - k.positions[pk.index[members]]) ** 2, axis=-1)  # (th, tw, m)
    rows, cols, kk = np.nonzero(d2 < reach ** 2)
    listed = set()
    for b in range(len(bin_start) - 1):
        entries = items[bin_start[b]:bin_start[b + 1]]
        assert np.all(np.diff(entries) > 0)  # kernel order, no repeats
        listed.update((b, int(e)) for e in entries)
    need = {(int(r // bin_px * nbx + c // bin_px), int(j)) for r, c, j in zip(rows, cols, kk)}
    assert need and need <= listed
    # and the lists are tight: most listed pairs reach some pixel of their bin
    assert len(need) >= 0.6 * len(listed)


def test_kernels_out_of_reach_of_the_plane_are_dropped():
    k = random_kernels(3)
    plane = PLANES["z"]
    pk = project_kernels(k, plane, k.radius)
    assert np.all(np.abs(pk.depth) < k.radius)
    np.testing.assert_allclose(pk.reach2, k.radius ** 2 - pk.depth ** 2)
    far = SlicePlane.axis_aligned("z", 50.0, 0.5, ((0, 4), (0, 4)))
    assert len(project_kernels(k, far, k.radius).index) == 0
