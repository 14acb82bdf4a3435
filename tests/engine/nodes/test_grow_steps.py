"""The Grow node's growth record: replaying `steps` onto `start_tiles` gives the tiling."""

from __future__ import annotations

import numpy as np
import pytest

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack
from engine.growth.regions import format_region_map
from engine.growth.tiling import DEFECT, UNASSIGNED

SHAPE = (12, 12)


def _graph(**params):
    doc = GraphDocument(seed=4)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", node_id="ts"))
    st.push(AddNode("Grow", {"size": [SHAPE[1], SHAPE[0]], **params}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    return doc, st


def _replay(start, steps):
    """Write each recorded decision into a copy of the start grid, one by one."""
    grid = np.array(start, dtype=np.int64).ravel()
    for cell, tile in np.asarray(steps).tolist():
        assert grid[cell] == UNASSIGNED, f"cell {cell} decided twice or was not cleared"
        grid[cell] = DEFECT if tile == -1 else tile
    return grid.reshape(np.shape(start))


def _grow(ev, doc):
    report = ev.evaluate(doc)
    assert report.ok, report.errors
    return report.output("g")


@pytest.mark.parametrize("hints", ["", "T=1"])        # "T=1" leaves defects on this grid
def test_fresh_growth_replays_from_an_empty_grid(hints):
    doc, _ = _graph(hints=hints)
    tv = _grow(Evaluator(), doc)
    assert tv.start_tiles.shape == SHAPE and tv.start_tiles.dtype == np.int32
    assert np.all(tv.start_tiles == UNASSIGNED)
    assert tv.steps.dtype == np.int32 and tv.steps.shape == (SHAPE[0] * SHAPE[1], 2)
    assert np.array_equal(_replay(tv.start_tiles, tv.steps), tv.tiling.tiles)
    assert (hints == "T=1") == bool(np.any(tv.tiling.tiles == DEFECT))
    assert not tv.steps.flags.writeable and not tv.start_tiles.flags.writeable


def test_regrowth_replays_from_the_previous_tiling_with_the_region_cleared():
    doc, st = _graph()
    ev = Evaluator()
    before = np.array(_grow(ev, doc).tiling.tiles)
    labels = np.zeros(SHAPE, int)
    labels[2:5, 6:10] = 1
    st.push(SetParam("g", "region_hints", "1: +=50,T=1,L=1,-=1"))
    st.push(SetParam("g", "regions", format_region_map(labels)))
    tv = _grow(ev, doc)
    cleared = np.zeros(SHAPE, bool)
    cleared[1:6, 5:11] = True                     # the region plus a one-cell margin
    start = tv.start_tiles
    assert np.all(start[cleared] == UNASSIGNED)
    assert np.array_equal(start[~cleared], before[~cleared])
    assert np.array_equal(start[~cleared], tv.tiling.tiles[~cleared])   # differs only inside
    assert len(tv.steps) == cleared.sum()
    assert np.array_equal(_replay(start, tv.steps), tv.tiling.tiles)


def test_unchanged_regions_keep_the_tiling_with_no_steps():
    doc, st = _graph()
    ev = Evaluator()
    before = _grow(ev, doc)
    st.push(SetParam("g", "regions", format_region_map(np.zeros(SHAPE, int))))   # same labels, new text
    tv = _grow(ev, doc)
    assert np.array_equal(tv.tiling.tiles, before.tiling.tiles)
    assert tv.steps.shape == (0, 2) and np.array_equal(tv.start_tiles, tv.tiling.tiles)
