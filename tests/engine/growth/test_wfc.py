"""Growth: rule compliance (checked from the JSON), determinism, fast == reference,
hints, availability, defects, fixed cells, progress."""

import math

import numpy as np
import pytest

from engine.geometry import Cancelled
from engine.growth import (TILESET_DIR, UNASSIGNED, grow_tiling, grow_tiling_reference,
                           load_tileset, realised_probabilities)
from engine.growth import _wfc_kernel as K
from engine.growth import wfc

from .json_rules import violations

BASIC = TILESET_DIR / "tl_basic.json"


@pytest.mark.parametrize("path, shape, periodic", [
    (BASIC, (20, 20), False),
    (BASIC, (20, 20), True),
    (BASIC, (7, 13), True),
    (BASIC, (1, 9), True),
    (BASIC, (1, 1), True),
    (BASIC, (2, 2), True),
    (TILESET_DIR / "tl_extended.json", (16, 16), True),
    (TILESET_DIR / "tl_obtuse.json", (12, 12), False),
    (TILESET_DIR / "cubic_beams.json", (5, 5, 5), True),
    (TILESET_DIR / "cubic_beams_mixed.json", (4, 5, 6), False),
])
def test_every_adjacent_pair_obeys_the_file(path, shape, periodic):
    ts = load_tileset(path)
    for seed in range(3):
        t = grow_tiling(ts, shape, periodic=periodic, rng=seed)
        assert t.stats["complete"] and t.tiles.min() >= -1
        assert violations(path, ts, t.tiles, periodic) == []


def test_same_seed_same_bytes_different_seed_differs():
    ts = load_tileset("TL+-")
    a = grow_tiling(ts, (20, 20), rng=42, record_steps=True)
    b = grow_tiling(ts, (20, 20), rng=42, record_steps=True)
    c = grow_tiling(ts, (20, 20), rng=43)
    assert a.tiles.tobytes() == b.tiles.tobytes() and a.steps.tobytes() == b.steps.tobytes()
    assert a.tiles.tobytes() != c.tiles.tobytes()
    assert a.seed == 42
    g1 = grow_tiling(ts, (9, 9), rng=np.random.default_rng(5))
    g2 = grow_tiling(ts, (9, 9), rng=np.random.default_rng(5))
    assert g1.tiles.tobytes() == g2.tiles.tobytes() and g1.seed is None
    assert isinstance(grow_tiling(ts, (3, 3)).seed, int)      # drawn and recorded


def _field(ts, shape):
    rng = np.random.default_rng(0)
    f = rng.random(shape + (ts.n_blocks,)) ** 3
    f[: shape[0] // 2, ..., ts.block_index("+")] = 5.0
    return f


CASES = [
    ("TL+-", (20, 20), dict(periodic=False)),
    ("TL+-", (20, 20), dict(periodic=True)),
    ("TL+-", (12, 12), dict(availability=1.0)),
    ("TL+-", (12, 12), dict(availability={"+": 10, "T": 30}, periodic=True)),
    ("TL+-", (10, 14), dict(hints="field")),
    ("TL+-", (10, 10), dict(hints={"T@0": 3, "T@2": 1, "-": 1, "L": 0.5, "+": 0.2})),
    ("TL+-", (10, 10), dict(max_steps=37)),
    ("TL+-OV\\", (14, 14), dict(periodic=True)),
    ("cubic-beams", (5, 5, 5), dict(periodic=True)),
    ("cubic-beams", (4, 4, 4), dict(availability=1.5)),
    ("cubic-beams-mixed", (4, 4, 4), dict(periodic=True)),
    ("cubic-beams-mixed", (3, 4, 5), dict()),
]


@pytest.mark.parametrize("name, shape, kw", CASES)
def test_fast_equals_reference_exactly(name, shape, kw):
    ts = load_tileset(name)
    kw = dict(kw)
    if kw.get("hints") == "field":
        kw["hints"] = _field(ts, shape)
    for seed in (0, 1, 2):
        a = grow_tiling(ts, shape, rng=seed, record_steps=True, **kw)
        b = grow_tiling_reference(ts, shape, rng=seed, record_steps=True, **kw)
        np.testing.assert_array_equal(a.tiles, b.tiles)
        np.testing.assert_array_equal(a.steps, b.steps)
        assert a.stats == b.stats


@pytest.mark.parametrize("name, shape, kw",
                         [c for c in CASES if "availability" not in c[2]][:6])
@pytest.mark.parametrize("slack", [4, 1])
def test_heap_path_equals_reference(name, shape, kw, slack, monkeypatch):
    """Large grids pick cells from a heap; force it (and its rebuilds) on small ones."""
    monkeypatch.setattr(wfc, "_HEAP_MIN_CELLS", 0)
    monkeypatch.setattr(wfc, "_HEAP_SLACK", slack)
    ts = load_tileset(name)
    kw = dict(kw)
    if kw.get("hints") == "field":
        kw["hints"] = _field(ts, shape)
    for seed in (0, 1):
        a = grow_tiling(ts, shape, rng=seed, record_steps=True, **kw)
        b = grow_tiling_reference(ts, shape, rng=seed, record_steps=True, **kw)
        np.testing.assert_array_equal(a.steps, b.steps)


def test_heap_and_scan_agree_on_a_large_grid(monkeypatch):
    ts = load_tileset("TL+-")
    a = grow_tiling(ts, (70, 70), periodic=True, rng=7, record_steps=True)
    monkeypatch.setattr(wfc, "_HEAP_MIN_CELLS", 10**9)
    b = grow_tiling(ts, (70, 70), periodic=True, rng=7, record_steps=True)
    np.testing.assert_array_equal(a.steps, b.steps)
    assert violations(BASIC, ts, a.tiles, True) == []


def test_fast_equals_reference_with_fixed_cells():
    ts = load_tileset("TL+-")
    base = grow_tiling(ts, (10, 10), rng=3)
    fixed = np.where(np.random.default_rng(1).random((10, 10)) < 0.3, base.tiles, -1)
    for seed in range(3):
        a = grow_tiling(ts, (10, 10), fixed=fixed, rng=seed, record_steps=True)
        b = grow_tiling_reference(ts, (10, 10), fixed=fixed, rng=seed, record_steps=True)
        np.testing.assert_array_equal(a.tiles, b.tiles)
        np.testing.assert_array_equal(a.steps, b.steps)
        held = fixed >= 0
        np.testing.assert_array_equal(a.tiles[held], fixed[held])


def test_entropy_is_eq_s1():
    """Kernel entropy of a fresh cell vs the closed form for the default hints."""
    ts = load_tileset("TL+-")
    wave = np.full((1, 1), np.uint64((1 << ts.n_tiles) - 1), dtype=np.uint64)
    s = K._entropy(0, wave, ts.weights[None, :].copy(), ts.tile_block, np.zeros(4),
                   np.zeros(4), False)
    # block hint 1/4 each, shared: 8 tiles at 1/16, two at 1/8, one at 1/4
    expected = 8 * (1 / 16) * math.log(16) + 2 * (1 / 8) * math.log(8) + 0.25 * math.log(4)
    assert s == pytest.approx(expected, rel=1e-12)


def test_single_cell_samples_by_normalised_hints():
    ts = load_tileset("TL+-")
    hints = {"T": 0.4, "+": 0.4, "-": 0.1, "L": 0.1}      # fig. S6A baseline
    n = 4000
    counts = np.zeros(ts.n_tiles)
    for seed in range(n):
        counts[grow_tiling(ts, (1, 1), hints=hints, rng=seed).tiles[0, 0]] += 1
    p = np.array([hints[t.block] / ts.n_orientations[ts.block_index(t.block)]
                  for t in ts.tiles])
    chi2 = ((counts - n * p) ** 2 / (n * p)).sum()
    assert chi2 < 31.4          # chi-square, 10 dof, p = 0.0005


def test_first_observation_uniform_and_second_is_a_neighbour():
    ts = load_tileset("TL+-")
    first = np.zeros(16)
    for seed in range(800):
        t = grow_tiling(ts, (4, 4), rng=seed, record_steps=True)
        c0, c1 = t.steps[0, 0], t.steps[1, 0]
        first[c0] += 1
        (i0, j0), (i1, j1) = divmod(int(c0), 4), divmod(int(c1), 4)
        assert abs(i0 - i1) + abs(j0 - j1) == 1     # minimal entropy is next to the growth
    chi2 = ((first - 50) ** 2 / 50).sum()
    assert chi2 < 37.7          # 15 dof, p = 0.001


def test_hints_favouring_plus_raise_its_realised_fraction():
    ts = load_tileset("TL+-")
    means = []
    for h in (0.02, 0.1, 0.3, 0.6, 0.9):
        rest = (1 - h) / 3
        hints = {"T": rest, "L": rest, "-": rest, "+": h}
        frac = [realised_probabilities(grow_tiling(ts, (20, 20), hints=hints, rng=s), ts)[3]
                for s in range(50)]
        means.append(np.mean(frac))
    assert all(b > a for a, b in zip(means, means[1:])), means


def test_defect_density_falls_as_availability_grows():
    """fig. S1E trends: fewer available blocks -> more defects; more "-" and "L"
    (low connectivity) than "T" and "+" -> more defects."""
    ts = load_tileset("TL+-")

    def density(hints, N):
        return np.mean([grow_tiling(ts, (20, 20), hints=hints, availability=N, rng=s).n_defects
                        for s in range(30)]) / 400

    poor = {"T": 0.1, "L": 0.4, "-": 0.4, "+": 0.1}
    dens = [density(poor, N) for N in (1.0, 1.1, 1.2, 1.3)]
    assert all(b < a for a, b in zip(dens, dens[1:])), dens
    assert density(poor, None) <= dens[-1]
    rich = {"T": 0.4, "L": 0.1, "-": 0.1, "+": 0.4}
    assert density(rich, 1.0) < dens[0] / 5


def test_availability_is_never_exceeded():
    ts = load_tileset("TL+-")
    for s in range(10):
        t = grow_tiling(ts, (10, 10), availability={"+": 7, "T": 20}, rng=s)
        blocks = ts.tile_block[t.tiles[t.tiles >= 0]]
        assert np.sum(blocks == ts.block_index("+")) <= 7
        assert np.sum(blocks == ts.block_index("T")) <= 20
        assert t.stats["remaining"]["+"] >= 0


def test_defects_do_not_stop_growth_and_neighbours_stay_compliant():
    ts = load_tileset("TL+-")
    total = 0
    for s in range(10):
        t = grow_tiling(ts, (20, 20), availability=1.0, rng=s, periodic=True)
        assert t.stats["complete"] and not np.any(t.tiles == UNASSIGNED)
        assert t.stats["n_defects"] == t.n_defects == int(t.defects.sum())
        assert violations(BASIC, ts, t.tiles, True) == []
        total += t.n_defects
    assert total > 0


def test_zero_hint_excludes_block_and_per_tile_hints_pick_orientations():
    ts = load_tileset("TL+-")
    t = grow_tiling(ts, (15, 15), hints={"T": 1, "-": 1, "+": 1, "L": 0}, rng=0)
    assert not np.isin(t.tiles, ts.tiles_of("L")).any()
    t = grow_tiling(ts, (15, 15), hints={"-@0": 1, "+": 1}, rng=0, periodic=True)
    assert set(np.unique(t.tiles)) <= {ts.tile_index("-@0"), ts.tile_index("+@0"), -1}


def test_per_cell_hint_field_steers_regions():
    ts = load_tileset("TL+-")
    field = np.ones((12, 12, ts.n_blocks))
    field[:, :6] = 0
    field[:, :6, ts.block_index("+")] = 1      # left half: only "+" admissible
    t = grow_tiling(ts, (12, 12), hints=field, rng=1)
    left = t.tiles[:, :6]
    assert np.all((left == ts.tile_index("+@0")) | (left == -1))
    assert np.isin(t.tiles[:, 6:], ts.tiles_of("T")).any()


def test_fixed_cells_kept_and_incompatible_fixed_refused():
    ts = load_tileset("TL+-")
    fixed = np.full((6, 6), -1)
    fixed[2, 2] = ts.tile_index("+@0")
    t = grow_tiling(ts, (6, 6), fixed=fixed, rng=0)
    assert t.tiles[2, 2] == fixed[2, 2]
    fixed[2, 3] = ts.tile_index("-@1")          # vertical bar: no arm towards the +
    with pytest.raises(ValueError, match="not allowed side by side"):
        grow_tiling(ts, (6, 6), fixed=fixed)


def test_max_steps_and_progress_cancel():
    ts = load_tileset("TL+-")
    t = grow_tiling(ts, (10, 10), max_steps=10, rng=0)
    assert t.stats["n_observations"] == 10 and not t.stats["complete"]
    assert np.sum(t.tiles == UNASSIGNED) > 0
    seen = []
    grow_tiling(ts, (30, 30), rng=0, progress=lambda d, n: seen.append((d, n)) or True)
    assert seen[-1][0] == seen[-1][1] > 0
    with pytest.raises(Cancelled):
        grow_tiling(ts, (30, 30), rng=0, progress=lambda d, n: d == 0)


@pytest.mark.parametrize("kw, words", [
    (dict(shape=(5,)), "shape"),
    (dict(shape=(5, 0)), "shape"),
    (dict(hints={"Q": 1}), "'Q'"),
    (dict(hints=np.ones(7)), "n_tiles"),
    (dict(hints={"T": -1}), "hints"),
    (dict(availability=-2.0), "availability"),
    (dict(availability={"T": 1.5}), "availability"),
    (dict(rng="seed"), "rng"),
    (dict(max_steps=-1), "max_steps"),
    (dict(fixed=np.full((3, 3), 99)), "fixed"),
    (dict(periodic="yes"), "periodic"),
])
def test_bad_arguments_are_refused(kw, words):
    ts = load_tileset("TL+-")
    args = dict(shape=(4, 4))
    args.update(kw)
    shape = args.pop("shape")
    with pytest.raises(ValueError, match=words):
        grow_tiling(ts, shape, **args)
