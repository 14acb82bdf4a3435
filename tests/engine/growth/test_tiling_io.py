"""tiling.json round trip and refusal of bad files."""

import json

import numpy as np
import pytest

from engine.growth import grow_tiling, load_tileset, load_tiling, save_tiling


def test_round_trip_2d_with_defects_and_unassigned(tmp_path):
    ts = load_tileset("TL+-")
    t = grow_tiling(ts, (20, 20), availability=1.0, rng=1,
                    hints={"T": .1, "L": .4, "-": .4, "+": .1})
    assert t.n_defects > 0
    p = tmp_path / "a.tiling.json"
    save_tiling(p, t, ts)
    doc = json.loads(p.read_text())
    assert doc["tileset"] == "TL+-" and doc["shape"] == [20, 20] and doc["seed"] == 1
    assert len(doc["defects"]) == t.n_defects
    u = load_tiling(p)
    assert u.tiles.tobytes() == t.tiles.tobytes() and u.periodic == t.periodic
    part = grow_tiling(ts, (5, 5), max_steps=3, rng=0)
    save_tiling(p, part, ts)
    assert load_tiling(p, ts).tiles.tobytes() == part.tiles.tobytes()


def test_round_trip_3d(tmp_path):
    ts = load_tileset("cubic-beams")
    t = grow_tiling(ts, (3, 4, 5), periodic=True, rng=2)
    save_tiling(tmp_path / "b.json", t, ts)
    u = load_tiling(tmp_path / "b.json")
    np.testing.assert_array_equal(u.tiles, t.tiles)
    assert u.periodic


@pytest.mark.parametrize("mutate, words", [
    (lambda d: d.update(format="other"), "mesoforge-tiling"),
    (lambda d: d.update(shape=[2]), "shape"),
    (lambda d: d["grid"][0].__setitem__(0, "Q@0"), "grid"),
    (lambda d: d["grid"].pop(), "grid"),
    (lambda d: d.update(defects=[[0, 0]]), "defect"),
    (lambda d: d.update(seed="x"), "seed"),
    (lambda d: d.update(tileset="nope"), "nope"),
])
def test_bad_files_are_refused_with_the_path(tmp_path, mutate, words):
    ts = load_tileset("TL+-")
    p = tmp_path / "c.json"
    save_tiling(p, grow_tiling(ts, (3, 3), rng=0), ts)
    doc = json.loads(p.read_text())
    mutate(doc)
    p.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=words):
        load_tiling(p)


def test_unreadable_file(tmp_path):
    p = tmp_path / "d.json"
    p.write_text("{")
    with pytest.raises(ValueError, match="d.json"):
        load_tiling(p)
    with pytest.raises(ValueError, match="missing.json"):
        load_tiling(tmp_path / "missing.json")


def test_engine_growth_stays_headless():
    import subprocess
    import sys
    code = ("import sys, engine.growth; bad = [m for m in sys.modules if m.split('.')[0] in "
            "('PySide6', 'ui', 'app') or m.startswith(('engine.graph', 'engine.nodes'))]; "
            "print(bad); sys.exit(1 if bad else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
