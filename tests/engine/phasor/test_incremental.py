"""Local update of a phasor infill after a brush stroke (engine.phasor.incremental)."""

import numpy as np
import pytest

from engine.phasor.fields import constant_fields, trilinear
from engine.phasor.incremental import EMPTY, affected_box, changed_cells, update_infill
from engine.phasor.infill import sample_infill
from engine.phasor.noise import phasor_complex
from engine.phasor.sampling import sample_kernels
from engine.phasor.strokes import Stroke, apply_stroke

LO, HI, SHAPE = np.zeros(3), np.array([16.0, 16.0, 2.0]), (4, 32, 32)


def _fields():
    return constant_fields(LO, HI, SHAPE, direction=(1.0, 0.4, 0.0), frequency=2.0)


def _stroke(value=2.7, at=(3.0, 4.0)):
    return Stroke("F", "z", 1.0, [list(at), [at[0] + 1.0, at[1] + 0.5]], 1.2, value=value)


@pytest.fixture(scope="module")
def painted():
    before = _fields()
    after, box = apply_stroke(before, _stroke())
    infill = sample_infill(before, rng=5, iterations=10)
    return before, after, box, infill


def test_changed_cells_is_the_stroke_box(painted):
    before, after, box, _ = painted
    assert changed_cells(before, after) == box
    assert changed_cells(before, before) == EMPTY
    other = constant_fields(LO, HI * 2, SHAPE)
    assert changed_cells(before, other) is None


def test_points_outside_the_affected_box_sample_the_same_values(painted):
    before, after, box, _ = painted
    lo, hi = affected_box(after, box)
    assert lo[2] == -np.inf and hi[2] == np.inf      # the box spans the grid's z range
    rng = np.random.default_rng(0)
    pts = rng.uniform(LO - 2, HI + 2, size=(20000, 3))
    outside = ~np.all((pts >= lo) & (pts <= hi), axis=1)
    assert outside.sum() > 1000
    for name in ("frequency", "spread", "direction"):
        a = trilinear(getattr(before, name), LO, HI, pts[outside])
        b = trilinear(getattr(after, name), LO, HI, pts[outside])
        assert np.array_equal(a, b), name
    # and just inside, values do change somewhere
    f_in = trilinear(after.frequency, LO, HI, pts[~outside])
    assert np.any(f_in != 2.0)


def test_update_resamples_inside_and_fixes_phases_outside(painted):
    before, after, box, infill = painted
    out = update_infill(infill, after, box, margin=1.0)
    k0, k1 = infill.kernels, out.kernels
    lo, hi = affected_box(after, box)
    inside = np.all((k0.positions >= lo) & (k0.positions <= hi), axis=1)
    grow = k0.radius
    active = np.all((k0.positions >= lo - grow) & (k0.positions <= hi + grow), axis=1)
    assert np.array_equal(k1.phase_v[~active], k0.phase_v[~active])
    assert np.array_equal(k1.phase_w[~active], k0.phase_w[~active])
    assert not np.array_equal(k1.phase_v[active], k0.phase_v[active])
    fresh = sample_kernels(after, rng=5)
    for name in ("frequency", "direction_v", "direction_w"):
        assert np.array_equal(getattr(k1, name)[inside], getattr(fresh, name)[inside])
        assert np.array_equal(getattr(k1, name)[~inside], getattr(k0, name)[~inside])
    assert out.iterations == infill.iterations and out.fields is after


def test_slices_change_only_inside_the_changed_region(painted):
    before, after, box, infill = painted
    out = update_infill(infill, after, box)
    lo, hi = out.changed_region
    ys, xs = np.meshgrid(np.linspace(0.05, 15.95, 80), np.linspace(0.05, 15.95, 80), indexing="ij")
    pts = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, 1.0)], axis=1)
    g0 = phasor_complex(infill.kernels, pts, fields=before, filtered=True,
                        attenuation=infill.attenuation)
    g1 = phasor_complex(out.kernels, pts, fields=after, filtered=True,
                        attenuation=out.attenuation)
    differ = (g0[0] != g1[0]) | (g0[1] != g1[1])
    assert differ.any()
    inside = np.all((pts >= lo) & (pts <= hi), axis=1)
    assert not np.any(differ & ~inside)
    assert (~inside).sum() > 0.2 * len(pts)


def test_nothing_changed_keeps_the_kernels_and_reports_an_empty_region(painted):
    before, _, _, infill = painted
    out = update_infill(infill, before, EMPTY, filtered=False)
    assert out.kernels is infill.kernels and not out.filtered
    lo, hi = out.changed_region
    assert np.all(lo > hi)


def test_a_new_kernel_radius_or_grid_is_refused(painted):
    before, _, _, infill = painted
    lower, box = apply_stroke(before, _stroke(value=1.5))
    with pytest.raises(ValueError, match="kernel radius"):
        update_infill(infill, lower, box)
    with pytest.raises(ValueError, match="grid"):
        update_infill(infill, constant_fields(LO, HI, (4, 16, 16), frequency=2.0), EMPTY)
    with pytest.raises(ValueError, match="margin"):
        update_infill(infill, before, box, margin=-1.0)
