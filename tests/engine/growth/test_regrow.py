"""Local regrowth: outside untouched byte for byte, inside re-grown and compliant."""

import numpy as np
import pytest

from engine.growth import TILESET_DIR, grow_tiling, load_tileset, regrow_region
from engine.growth.regrow import dilate

from .json_rules import violations

BASIC = TILESET_DIR / "tl_basic.json"


def _box(shape, sl):
    m = np.zeros(shape, dtype=bool)
    m[sl] = True
    return m


@pytest.mark.parametrize("periodic", [False, True])
def test_outside_is_byte_identical_and_result_compliant(periodic):
    ts = load_tileset("TL+-")
    changed = 0
    for seed in range(8):
        t = grow_tiling(ts, (16, 16), periodic=periodic, rng=seed)
        before = t.tiles.tobytes()
        region = _box(t.shape, np.s_[5:9, 6:11])
        r = regrow_region(t, ts, region, margin=1, rng=100 + seed)
        cleared = _box(t.shape, np.s_[4:10, 5:12])
        assert r.stats["n_cleared"] == cleared.sum()
        assert r.tiles[~cleared].tobytes() == t.tiles[~cleared].tobytes()
        assert t.tiles.tobytes() == before                       # input untouched
        assert violations(BASIC, ts, r.tiles, periodic) == []
        assert r.stats["complete"]
        changed += int(np.any(r.tiles[cleared] != t.tiles[cleared]))
    assert changed >= 6


def test_regrow_with_hints_in_3d():
    ts = load_tileset("cubic-beams")
    t = grow_tiling(ts, (5, 5, 5), periodic=True, rng=0)
    region = _box(t.shape, np.s_[0:2, 0:2, 0:2])
    r = regrow_region(t, ts, region, margin=1, hints={"+3": 1.0, "X": 1.0}, rng=1)
    cleared = dilate(region, 1, periodic=True)
    assert cleared.sum() == 4 ** 3
    assert r.tiles[~cleared].tobytes() == t.tiles[~cleared].tobytes()
    assert violations(TILESET_DIR / "cubic_beams.json", ts, r.tiles, True) == []


def test_defects_outside_are_kept_as_defects():
    ts = load_tileset("TL+-")
    t = grow_tiling(ts, (20, 20), availability=1.0, hints={"T": .1, "L": .4, "-": .4, "+": .1},
                    rng=2)
    assert t.n_defects > 0
    region = _box(t.shape, np.s_[0:4, 0:4])
    r = regrow_region(t, ts, region, margin=0, rng=3)
    outside = ~region
    np.testing.assert_array_equal(r.tiles[outside], t.tiles[outside])
    assert violations(BASIC, ts, r.tiles, False) == []


def test_dilate_margin_and_wrap():
    m = _box((7, 7), np.s_[3, 3])
    assert dilate(m, 1, periodic=False).sum() == 9
    assert dilate(m, 2, periodic=False).sum() == 25
    corner = _box((7, 7), np.s_[0, 0])
    assert dilate(corner, 1, periodic=False).sum() == 4
    wrapped = dilate(corner, 1, periodic=True)
    assert wrapped.sum() == 9 and wrapped[6, 6] and wrapped[0, 6]


def test_bad_region_refused():
    ts = load_tileset("TL+-")
    t = grow_tiling(ts, (5, 5), rng=0)
    with pytest.raises(ValueError, match="region_mask"):
        regrow_region(t, ts, np.zeros((4, 4), bool))
    with pytest.raises(ValueError, match="margin"):
        regrow_region(t, ts, np.zeros((5, 5), bool), margin=-1)
    with pytest.raises(ValueError, match="tile set"):
        regrow_region(t, load_tileset("TL+-acute"), np.zeros((5, 5), bool))
