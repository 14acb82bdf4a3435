import math

import numpy as np
import pytest

from engine.fab import PrintSettings, frontier_walls, layer_walls, perimeter_loops
from engine.fab._polyline import douglas_peucker_keep

PX = 0.1


def polyline_length(p):
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def test_stripes_give_straight_walls_at_the_frontiers():
    # 10 mm square, black where frac(x / 2) < 1/2: frontiers at x = 1, 2, ..., 9.
    n = 100
    yy, xx = np.mgrid[0:n, 0:n] * PX
    image = np.mod(xx / 2.0, 1.0) < 0.5
    inset = 0.4
    walls = frontier_walls(image, np.ones_like(image), pixel_size=PX, inset=inset)
    xs = sorted(float(w[:, 0].mean()) for w in walls)
    assert len(walls) == 9
    # pixel centres at k * PX; the part spans [-PX/2, 10 - PX/2]
    np.testing.assert_allclose(xs, np.arange(1, 10) - PX / 2, atol=PX)
    for w in walls:
        assert len(w) == 2                                   # simplified to a segment
        assert np.ptp(w[:, 0]) < 1e-9
        assert sorted(w[:, 1]) == pytest.approx([-PX / 2 + inset, 10 - PX / 2 - inset], abs=PX)


@pytest.mark.parametrize("perimeters", [1, 2])
def test_disc_perimeter_lengths(perimeters):
    px, r, w = 0.05, 5.0, 0.4
    n = int(2 * r / px) + 21
    c = (n - 1) / 2
    yy, xx = np.mgrid[0:n, 0:n]
    disc = np.hypot(xx - c, yy - c) * px <= r
    loops = perimeter_loops(disc, pixel_size=px, line_width=w, perimeters=perimeters)
    assert len(loops) == perimeters
    for k, loop in enumerate(loops):
        np.testing.assert_allclose(loop[0], loop[-1])
        expected = 2 * math.pi * (r - (k + 0.5) * w)
        assert polyline_length(loop) == pytest.approx(expected, rel=0.01)


def test_walls_are_clipped_to_the_domain_inset(diamonds):
    px, r = 0.1, 4.0
    n = 100
    c = (n - 1) / 2
    yy, xx = np.mgrid[0:n, 0:n]
    disc = np.hypot(xx - c, yy - c) * px <= r
    image = diamonds(n, px, z=0.7)
    settings = PrintSettings(perimeters=1)
    perims, walls = layer_walls(image, disc, pixel_size=px, settings=settings)
    assert len(perims) == 1 and len(walls) > 10
    pts = np.concatenate(walls)
    radius = np.hypot(pts[:, 0] - c * px, pts[:, 1] - c * px)
    # walls stop at the inner edge of the perimeter bead: r - 1 line width
    assert radius.max() <= r - 0.4 + px
    # ... but reach it: cut ends lie on that circle
    ends = np.concatenate([[w[0], w[-1]] for w in walls if not np.allclose(w[0], w[-1])])
    np.testing.assert_allclose(np.hypot(*(ends - c * px).T), r - 0.4, atol=px)


def test_uniform_or_empty_layers_have_no_walls():
    image = np.ones((20, 20), bool)
    assert frontier_walls(image, None, pixel_size=PX) == []
    assert frontier_walls(~image, None, pixel_size=PX) == []
    assert frontier_walls(image, np.zeros_like(image), pixel_size=PX) == []
    assert perimeter_loops(np.zeros((20, 20), bool), pixel_size=PX, line_width=0.4) == []


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="domain shape"):
        frontier_walls(np.zeros((4, 4), bool), np.zeros((4, 5), bool), pixel_size=PX)
    with pytest.raises(ValueError, match="pixel_size"):
        frontier_walls(np.zeros((4, 4), bool), None, pixel_size=-1.0)
    with pytest.raises(ValueError, match="image"):
        frontier_walls(np.zeros(4, bool), None, pixel_size=PX)


def test_douglas_peucker_against_hand_results():
    line = np.column_stack([np.linspace(0, 1, 11), np.zeros(11)])
    assert douglas_peucker_keep(line, 1e-6).tolist() == [True] + [False] * 9 + [True]
    # a closed square sampled densely keeps exactly its 4 corners (+ repeat)
    t = np.linspace(0, 1, 10, endpoint=False)
    sq = np.concatenate([np.column_stack([t, 0 * t]), np.column_stack([1 + 0 * t, t]),
                         np.column_stack([1 - t, 1 + 0 * t]), np.column_stack([0 * t, 1 - t]),
                         [[0.0, 0.0]]])
    kept = sq[douglas_peucker_keep(sq, 1e-6)]
    assert sorted(map(tuple, kept[:-1])) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    # a bump higher than the tolerance survives
    bump = line.copy()
    bump[5, 1] = 0.1
    assert douglas_peucker_keep(bump, 0.05)[5]
    assert not douglas_peucker_keep(bump, 0.2)[5]
