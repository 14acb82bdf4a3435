"""Painting helpers of the hint regions: round brush, stroke densification, hints text."""

import numpy as np
import pytest

from engine.growth.regions import (densify_stroke, format_region_hints, format_region_map,
                                   paint_disc, parse_region_hints, parse_region_map)


def brute_force_disc(labels, centres, radius, label):
    """Slow reference: every cell checked against every centre."""
    out = np.array(labels, dtype=np.int64)
    ny, nx = out.shape
    for i in range(ny):
        for j in range(nx):
            for x, y in np.reshape(centres, (-1, 2)):
                inside = int(np.floor(x)) == j and int(np.floor(y)) == i
                if inside or (j + 0.5 - x) ** 2 + (i + 0.5 - y) ** 2 <= radius ** 2:
                    out[i, j] = label
                    break
    return out


def test_hand_computed_small_cases():
    zero = np.zeros((5, 5), np.int64)
    plus = paint_disc(zero, [[2.5, 2.5]], 1.0, 3)        # neighbours at 1 in, diagonals at 1.41 out
    expected = np.zeros((5, 5), np.int64)
    expected[2, 1:4] = 3
    expected[1:4, 2] = 3
    np.testing.assert_array_equal(plus, expected)
    square = paint_disc(zero, [[2.5, 2.5]], 1.5, 1)
    expected = np.zeros((5, 5), np.int64)
    expected[1:4, 1:4] = 1
    np.testing.assert_array_equal(square, expected)
    single = paint_disc(zero, [[0.2, 4.9]], 0.0, 7)      # radius 0: the cell holding the centre
    assert single[4, 0] == 7 and np.count_nonzero(single) == 1
    # off the grid: only cells within reach
    edge = paint_disc(zero, [[-0.5, 2.5]], 1.0, 2)
    assert np.argwhere(edge).tolist() == [[2, 0]]
    assert not paint_disc(zero, [[-5.0, -5.0]], 1.0, 2).any()


def test_matches_brute_force_and_leaves_the_input_alone():
    rng = np.random.default_rng(4)
    for _ in range(40):
        ny, nx = rng.integers(1, 12, size=2)
        labels = rng.integers(0, 4, size=(ny, nx))
        before = labels.copy()
        centres = rng.uniform(-2, max(nx, ny) + 2, size=(rng.integers(1, 6), 2))
        radius = float(rng.choice([0.0, 0.5, 1.0, 1.5, rng.uniform(0, 4)]))
        label = int(rng.integers(0, 10))
        got = paint_disc(labels, centres, radius, label)
        np.testing.assert_array_equal(got, brute_force_disc(labels, centres, radius, label))
        np.testing.assert_array_equal(labels, before)
        assert got is not labels and got.dtype == np.int64


def test_erasing_paints_label_zero():
    labels = np.full((4, 4), 5)
    out = paint_disc(labels, [[1.5, 1.5]], 1.0, 0)
    assert out[1, 1] == 0 and np.count_nonzero(out == 0) == 5


@pytest.mark.parametrize("kwargs, word", [
    (dict(labels=np.zeros(4), centres=[[0, 0]], radius=1.0, label=1), "labels"),
    (dict(labels=np.zeros((2, 2)), centres=[[np.nan, 0]], radius=1.0, label=1), "centres"),
    (dict(labels=np.zeros((2, 2)), centres=[[0, 0]], radius=-1.0, label=1), "radius"),
    (dict(labels=np.zeros((2, 2)), centres=[[0, 0]], radius=1.0, label=36), "label"),
])
def test_bad_input_is_refused_by_name(kwargs, word):
    with pytest.raises(ValueError, match=word):
        paint_disc(**kwargs)


def test_densified_stroke_has_no_gaps():
    pts = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 4.1], [-1.0, 4.1]])
    out = densify_stroke(pts, spacing=0.5)
    assert np.all(np.hypot(*np.diff(out, axis=0).T) <= 0.5 + 1e-12)
    # every vertex appears, in order
    idx = [int(np.flatnonzero(np.all(np.isclose(out, p), axis=1))[0]) for p in pts]
    assert idx == sorted(idx) and idx[0] == 0 and idx[-1] == len(out) - 1
    # the inserted points lie on the segments: first segment is the line y = 4/3 x
    first = out[:idx[1] + 1]
    np.testing.assert_allclose(first[:, 1], first[:, 0] * 4 / 3)
    assert len(densify_stroke(pts[:1])) == 1


def test_a_dense_stroke_paints_a_band():
    """A stroke from one side to the other with radius 0.5 paints the whole middle row."""
    pts = densify_stroke([[0.1, 2.5], [9.9, 2.5]], spacing=0.5)
    out = paint_disc(np.zeros((5, 10), np.int64), pts, 0.5, 1)
    assert out[2].tolist() == [1] * 10 and np.count_nonzero(out) == 10


def test_region_hints_text_round_trip():
    texts = {2: " L=2 ", 1: "T=3,+=1", 4: ""}
    text = format_region_hints(texts)
    assert text == "1: T=3,+=1 | 2: L=2"
    assert parse_region_hints(text, str.strip) == {1: "T=3,+=1", 2: "L=2"}
    with pytest.raises(ValueError, match="label 3"):
        format_region_hints({3: "T=1 | 2: L=1"})


def test_painted_map_round_trips_through_text():
    out = paint_disc(np.zeros((3, 4), np.int64), [[1.0, 1.0]], 0.8, 11)
    text = format_region_map(out)
    np.testing.assert_array_equal(parse_region_map(text, (3, 4)), out)
