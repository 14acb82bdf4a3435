"""Extending patches by their symmetries (Prop. 4.2): mirror chains and
half-turn groups folded into a periodic cell.

Reference: area of Schwarz D per cubic cell of edge 1, 3.8377 (published
value quoted in the task); a Petrie hexagon patch is 1/32 of that cell
(Gauss-Bonnet: -pi per patch, genus 9 per cubic cell).
"""

import numpy as np
import pytest

from engine.geometry.surfaces.curvature import surface_area
from engine.geometry.surfaces.plateau import solve_plateau
from engine.geometry.surfaces.tiling import half_turn, mirror, tile_patch

D_AREA = 3.8377
TOL = 0.0015


def test_schwarz_d_from_its_plateau_patch_tiled_by_half_turns():
    corners = 0.25 * np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1], [1, 0, 1]],
                              float)
    surf = solve_plateau(corners, edge_length=1.5 / 96, tol=1e-7, max_iter=100)
    turns = [half_turn(corners[i], corners[(i + 1) % 6] - corners[i]) for i in range(6)]
    verts, faces, copies = tile_patch(surf.vertices, surf.faces, turns, cell=((0, 0, 0), 1.0))
    area = surface_area(verts, faces)
    print(f"D cell area {area:.5f} ({100 * (area / D_AREA - 1):+.3f}%)")
    assert copies == 32
    assert abs(area / D_AREA - 1) < TOL


def test_tile_patch_doubles_per_mirror_and_refuses_runaway_groups():
    v = np.array([[0.1, 0.1, 0.1], [0.4, 0.1, 0.1], [0.1, 0.4, 0.1]])
    f = np.array([[0, 1, 2]])
    out_v, out_f, copies = tile_patch(v, f, [mirror((0, 0, 0), (1, 0, 0)),
                                             mirror((0, 0, 0), (0, 0, 1))])
    assert copies == 4 and out_f.shape == (4, 3) and out_v.shape == (12, 3)
    # Two parallel mirrors generate translations without end unless folded.
    with pytest.raises(ValueError, match="max_copies"):
        tile_patch(v, f, [mirror((0, 0, 0), (1, 0, 0)), mirror((0.5, 0, 0), (1, 0, 0))],
                   cell=((0, 0, 0), 1.0 / 3.0 ** 0.5), max_copies=64)
