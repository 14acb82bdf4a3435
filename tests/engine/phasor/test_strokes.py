import json
import math

import numpy as np
import pytest

from engine.phasor.fields import constant_fields
from engine.phasor.strokes import Stroke, apply_stroke, apply_strokes, stroke_weights

LO, HI = np.array([0.0, -1.0, 2.0]), np.array([6.0, 4.0, 6.0])
SHAPE = (8, 10, 12)  # (nz, ny, nx): cells 0.5 mm each way


def _fields(rng=None):
    """Fields with varied values so blends are visible."""
    rng = np.random.default_rng(5) if rng is None else rng
    base = constant_fields(LO, HI, SHAPE)
    d = rng.normal(size=SHAPE + (3,))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return type(base)(d, rng.uniform(0.5, 3.0, SHAPE), rng.uniform(0.0, 1.5, SHAPE), LO, HI)


def _reference_weights(stroke, shape=SHAPE, lo=LO, hi=HI):
    """Loop over every cell and every segment: distance in 3-D to the polyline."""
    frame = {"x": (1, 2, 0), "y": (0, 2, 1), "z": (0, 1, 2)}[stroke.axis]
    u, v, n = frame
    depth = stroke.radius if stroke.depth is None else stroke.depth
    step = (hi - lo) / np.array(shape[::-1])
    pts3 = []
    for pu, pv in stroke.points:
        q = np.zeros(3)
        q[u], q[v], q[n] = pu, pv, stroke.position
        pts3.append(q)
    segs = list(zip(pts3[:-1], pts3[1:])) or [(pts3[0], pts3[0])]
    out = np.zeros(shape)
    for k in range(shape[0]):
        for j in range(shape[1]):
            for i in range(shape[2]):
                c = lo + (np.array([i, j, k]) + 0.5) * step
                c[n] = stroke.position + (c[n] - stroke.position) * stroke.radius / depth
                best = math.inf
                for a, b in segs:
                    e = b - a
                    ee = float(e @ e)
                    t = 0.0 if ee == 0 else min(max(float((c - a) @ e) / ee, 0.0), 1.0)
                    best = min(best, float(np.linalg.norm(c - (a + t * e))))
                s = best / stroke.radius
                if s >= 1:
                    continue
                f = {"constant": 1.0, "linear": 1.0 - s, "smooth": 1.0 - 3 * s ** 2 + 2 * s ** 3}[stroke.falloff]
                out[k, j, i] = stroke.strength * f
    return out


STROKES = [
    Stroke("F", "z", 4.1, [[1.0, 0.0], [2.3, 1.7], [4.9, 1.2], [4.9, 1.2], [5.5, 3.6]], 1.1,
           strength=0.8, falloff="smooth", value=2.0),
    Stroke("Gamma", "y", 1.3, [[0.7, 3.1], [5.2, 4.4]], 0.9, strength=0.5, falloff="linear",
           value=0.3, depth=1.7),
    Stroke("D", "x", 3.05, [[0.2, 3.0], [1.1, 4.0], [3.0, 4.5]], 1.3, falloff="constant",
           tilt=0.4, depth=0.6),
    Stroke("F", "z", 3.3, [[2.2, 1.6]], 1.4, falloff="linear", value=0.7),
]


@pytest.mark.parametrize("stroke", STROKES, ids=["F-z-smooth", "Gamma-y-linear", "D-x-constant", "dab"])
def test_vectorised_weights_equal_a_per_cell_reference(stroke):
    got = stroke_weights(_fields(), stroke)
    want = _reference_weights(stroke)
    assert (want > 0).sum() > 10
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


@pytest.mark.parametrize("stroke", STROKES, ids=["F-z-smooth", "Gamma-y-linear", "D-x-constant", "dab"])
def test_input_untouched_and_cells_outside_the_box_byte_identical(stroke):
    before = _fields()
    snapshot = [a.tobytes() for a in (before.direction, before.frequency, before.spread)]
    after, changed = apply_stroke(before, stroke)
    assert [a.tobytes() for a in (before.direction, before.frequency, before.spread)] == snapshot
    w = stroke_weights(before, stroke)
    inside = np.zeros(SHAPE, dtype=bool)
    inside[changed] = True
    assert np.all(inside[w > 0]) and not np.any(w[~inside])
    # the box is tight: each face holds a brushed cell
    for axis in range(3):
        assert np.any(np.take(w[changed], 0, axis=axis) > 0)
        assert np.any(np.take(w[changed], -1, axis=axis) > 0)
    for name in ("direction", "frequency", "spread"):
        a, b = getattr(before, name), getattr(after, name)
        assert a[~inside].tobytes() == b[~inside].tobytes()


def test_value_brush_blends_towards_the_value():
    stroke = STROKES[0]
    before = _fields()
    after, _ = apply_stroke(before, stroke)
    w = _reference_weights(stroke)
    np.testing.assert_allclose(after.frequency, (1 - w) * before.frequency + w * 2.0, atol=1e-12)
    assert after.spread.tobytes() == before.spread.tobytes()
    assert after.direction.tobytes() == before.direction.tobytes()


def test_two_strokes_in_one_call_equal_sequential_application():
    a, b = STROKES[0], STROKES[2]
    start = _fields()
    once, box = apply_strokes(start, [a, b])
    step1, box_a = apply_stroke(start, a)
    step2, box_b = apply_stroke(step1, b)
    for name in ("direction", "frequency", "spread"):
        assert getattr(once, name).tobytes() == getattr(step2, name).tobytes()
    assert box == tuple(slice(min(p.start, q.start), max(p.stop, q.stop)) for p, q in zip(box_a, box_b))


def test_direction_brush_with_no_tilt_paints_the_drag_direction_in_the_slice():
    lo, hi, shape = np.zeros(3), np.array([10.0, 10.0, 4.0]), (4, 10, 10)
    start = constant_fields(lo, hi, shape, direction=(0.0, 0.0, 1.0))
    # drag from (2, 2) to (8, 8) on z = 2.5 (a cell-centre layer); centre cell (5.5, 5.5)
    stroke = Stroke("D", "z", 2.5, [[2.0, 2.0], [8.0, 8.0]], 2.0, strength=1.0)
    after, changed = apply_stroke(start, stroke)
    s = math.sqrt(0.5)
    np.testing.assert_allclose(after.direction[2, 5, 5], [s, s, 0.0], atol=1e-12)
    np.testing.assert_allclose(after.direction[2, 2, 2], [s, s, 0.0], atol=1e-12)
    assert after.direction[2, 5, 5, 2] == 0.0
    # far from the stroke: unchanged
    assert np.all(after.direction[2, 9, 0] == [0.0, 0.0, 1.0])
    tilted, _ = apply_stroke(start, Stroke("D", "z", 2.5, [[2.0, 2.0], [8.0, 8.0]], 2.0, tilt=math.pi / 6))
    np.testing.assert_allclose(tilted.direction[2, 5, 5], [s * math.cos(math.pi / 6), s * math.cos(math.pi / 6),
                                                           0.5], atol=1e-12)


def test_direction_brush_follows_each_segment_and_a_heading_overrides_it():
    lo, hi, shape = np.zeros(3), np.array([10.0, 10.0, 1.0]), (1, 10, 10)
    start = constant_fields(lo, hi, shape)
    path = [[0.5, 5.5], [5.5, 5.5], [5.5, 9.5]]  # right, then up
    after, _ = apply_stroke(start, Stroke("D", "z", 0.5, path, 0.6))
    np.testing.assert_allclose(after.direction[0, 5, 2], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(after.direction[0, 8, 5], [0, 1, 0], atol=1e-12)
    fixed, _ = apply_stroke(start, Stroke("D", "z", 0.5, path, 0.6, heading=[0.0, -3.0]))
    np.testing.assert_allclose(fixed.direction[0, 5, 2], [0, -1, 0], atol=1e-12)


def test_a_cancelling_direction_blend_keeps_the_old_direction():
    lo, hi, shape = np.zeros(3), np.ones(3), (1, 1, 1)
    start = constant_fields(lo, hi, shape, direction=(-1.0, 0.0, 0.0))
    stroke = Stroke("D", "z", 0.5, [[0.5, 0.5]], 1.0, strength=0.5, heading=[1.0, 0.0])
    after, changed = apply_stroke(start, stroke)
    assert changed == (slice(0, 1),) * 3
    assert np.all(after.direction == [-1.0, 0.0, 0.0])


def test_a_stroke_that_misses_the_grid_changes_nothing():
    start = _fields()
    after, changed = apply_stroke(start, Stroke("F", "z", 50.0, [[1.0, 1.0]], 1.0, value=2.0))
    assert changed == (slice(0, 0),) * 3 and after is start


def test_json_round_trip_is_exact():
    for stroke in STROKES + [Stroke("D", "z", 0.1, [[0.1, 0.2]], 0.3, heading=[0.1, 0.7], tilt=-0.2)]:
        text = stroke.to_json()
        back = Stroke.from_json(text)
        assert back.to_dict() == stroke.to_dict()
        assert back.points.tobytes() == stroke.points.tobytes()
        assert json.loads(back.to_json()) == json.loads(text)


BASE = {"field": "F", "axis": "z", "position": 1.0, "points": [[0, 0], [1, 1]], "radius": 1.0, "value": 2.0}


@pytest.mark.parametrize("change, words", [
    ({"value": 0.0}, "Stroke.value"), ({"value": -1.0}, "Stroke.value"),
    ({"value": float("nan")}, "Stroke.value"), ({"value": None}, "Stroke.value"),
    ({"field": "Gamma", "value": 1.7}, "Stroke.value"), ({"field": "Gamma", "value": -0.1}, "Stroke.value"),
    ({"radius": 0.0}, "Stroke.radius"), ({"radius": float("inf")}, "Stroke.radius"),
    ({"strength": 1.5}, "Stroke.strength"), ({"falloff": "gauss"}, "Stroke.falloff"),
    ({"axis": "w"}, "Stroke.axis"), ({"field": "G"}, "Stroke.field"),
    ({"depth": 0.0}, "Stroke.depth"), ({"position": float("nan")}, "Stroke.position"),
    ({"points": [[0, 0, 0]]}, "Stroke.points"), ({"points": []}, "Stroke.points"),
    ({"points": [[0, float("nan")]]}, "Stroke.points"),
    ({"field": "D", "value": None, "heading": [0, 0]}, "Stroke.heading"),
    ({"field": "D", "value": None, "points": [[1, 1], [1, 1]]}, "Stroke.heading"),
    ({"field": "D", "value": None, "tilt": 2.0}, "Stroke.tilt"),
    ({"field": "D"}, "Stroke.value"), ({"heading": [1, 0]}, "Stroke.heading"),
    ({"colour": "red"}, "Stroke.colour"),
])
def test_bad_strokes_are_refused_naming_the_key(change, words):
    with pytest.raises(ValueError) as err:
        Stroke.from_dict({**BASE, **change})
    assert words in str(err.value)


def test_from_json_names_a_missing_key():
    with pytest.raises(ValueError, match="Stroke.radius: missing"):
        Stroke.from_json(json.dumps({k: v for k, v in BASE.items() if k != "radius"}))
