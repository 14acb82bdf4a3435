"""Painted hint regions on the Grow node and local regrowth from the previous tiling."""

import numpy as np
import pytest

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack
from engine.growth.regions import format_region_map, parse_region_map


def _graph(size=(12, 12)):
    doc = GraphDocument(seed=4)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", node_id="ts"))
    st.push(AddNode("Grow", {"size": list(size)}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    return doc, st


def _allowed_everywhere(tiling, ts):
    t = tiling.tiles
    ny, nx = t.shape
    for i in range(ny):
        for j in range(nx):
            for di, dj in ((0, 1), (1, 0)):
                a, b = t[i, j], t[(i + di) % ny, (j + dj) % nx]
                if a < 0 or b < 0:
                    continue
                ok = False
                for d in range(ts.allowed.shape[0]):
                    ok = ok or bool(ts.allowed[d, a, b])
                assert ok


def test_region_map_text_round_trip_and_errors():
    labels = np.zeros((3, 4), int)
    labels[1, 1:3] = 2
    text = format_region_map(labels)
    assert text == "0000;0220;0000"
    assert np.array_equal(parse_region_map(text, (3, 4)), labels)
    with pytest.raises(ValueError, match="row 1 .* 3 cells"):
        parse_region_map("0000;022;0000", (3, 4))
    with pytest.raises(ValueError, match="'#' is not a label"):
        parse_region_map("0000;0#20;0000", (3, 4))


def test_repainting_regrows_only_the_region_plus_margin():
    doc, st = _graph()
    ev = Evaluator()
    before = ev.evaluate(doc).output("g").tiling.tiles.copy()
    labels = np.zeros((12, 12), int)
    labels[4:8, 4:8] = 1
    st.push(SetParam("g", "region_hints", "1: +=50,T=1,L=1,-=1"))
    st.push(SetParam("g", "regions", format_region_map(labels)))
    r = ev.evaluate(doc)
    assert r.ok, r.errors
    tv = r.output("g")
    after = tv.tiling.tiles
    outside = np.ones((12, 12), bool)
    outside[3:9, 3:9] = False          # region plus a one-cell margin
    assert np.array_equal(after[outside], before[outside])
    assert not np.array_equal(after, before)
    _allowed_everywhere(tv.tiling, tv.tileset)
    plus = tv.tileset.tile_index("+@0")
    assert np.mean(after[4:8, 4:8] == plus) > np.mean(before[4:8, 4:8] == plus)


def test_bad_region_text_fails_the_node_with_its_parameter():
    doc, st = _graph(size=(4, 4))
    st.push(SetParam("g", "regions", "0000;0000"))
    r = Evaluator().evaluate(doc)
    res = r.results["g"]
    assert res.status == "failed" and res.where == "regions" and "2 rows" in res.error
