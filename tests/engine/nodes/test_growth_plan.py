"""GrowthPlan (engine.nodes.growth_plan): run / resume / regrow / replay against the kernels,
and the Grow node's seed parameter."""

import numpy as np
import pytest

import engine.nodes  # noqa: F401  (registers the nodes)
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, ParamError, SetParam, UndoStack, node_type
from engine.graph.node import node_seed
from engine.growth.values import TilingValue
from engine.growth import UNASSIGNED, grow_tiling, load_tileset
from engine.growth.regrow import dilate, regrow_region
from engine.nodes.growth_plan import GrowthPlan, ReplayCursor, tiling_seed

TS = load_tileset("TL+-")


def plan(seed=5, **params):
    return GrowthPlan.from_params(node_type("Grow").validate_params({"size": [7, 6], **params}), TS, seed)


def graph(doc_seed=0, **params):
    doc = GraphDocument(seed=doc_seed)
    undo = UndoStack(doc)
    undo.push(AddNode("TileSet", {}, node_id="ts1"))
    undo.push(AddNode("Grow", {"size": [7, 6], **params}, node_id="grow1"))
    undo.push(Connect("ts1", "tileset", "grow1", "tileset"))
    return doc, undo


def test_run_is_the_kernel_growth():
    p = plan(hints="T=1,L=1,+=2,-=1", availability=1.5)
    tv = p.run()
    ref = grow_tiling(TS, (6, 7), hints={"T": 1, "L": 1, "+": 2, "-": 1}, periodic=True,
                      availability=1.5, rng=5, record_steps=True)
    assert np.array_equal(tv.tiling.tiles, ref.tiles) and np.array_equal(tv.steps, ref.steps)
    assert np.all(tv.start_tiles == UNASSIGNED)


def test_the_node_evaluates_the_plan():
    doc, _ = graph(doc_seed=3)
    tv = Evaluator().evaluate(doc).output("grow1", "tiling")
    ref = plan(seed=node_seed(3, "grow1")).run()
    assert np.array_equal(tv.tiling.tiles, ref.tiling.tiles) and tv.tiling.seed == node_seed(3, "grow1")


def test_seed_param_is_the_tiling_seed_and_minus_one_derives_it():
    assert tiling_seed({"seed": -1}, 77) == 77 and tiling_seed({"seed": 12}, 77) == 12
    assert tiling_seed({}, 77) == 77
    a = Evaluator().evaluate(graph(doc_seed=1, seed=2**62 + 5)[0]).output("grow1", "tiling")
    b = Evaluator().evaluate(graph(doc_seed=9, seed=2**62 + 5)[0]).output("grow1", "tiling")
    assert a.tiling.seed == b.tiling.seed == 2**62 + 5
    assert np.array_equal(a.tiling.tiles, grow_tiling(TS, (6, 7), periodic=True, rng=2**62 + 5).tiles)
    assert node_type("Grow").default_params()["seed"] == -1
    with pytest.raises(ParamError, match=r"seed.*\[-1, 9223372036854775807\]"):
        graph(seed=-2)


def test_replay_ends_in_the_evaluated_tiling():
    doc, _ = graph(doc_seed=4, availability=1.0)
    tv = Evaluator().evaluate(doc).output("grow1", "tiling")
    p = plan(seed=tv.tiling.seed, availability=1.0)
    for value in (tv, TilingValue(tv.tiling, tv.tileset)):   # recorded, and regrown from the plan
        replay = p.replay(value)
        cursor = ReplayCursor(replay)
        assert np.all(cursor.grid == UNASSIGNED) and cursor.n_steps == len(replay.steps)
        counts = []
        while not cursor.done:
            cursor.step(4)
            counts.append(int(np.count_nonzero(cursor.grid != UNASSIGNED)))
        assert counts == sorted(counts) and np.array_equal(cursor.grid, tv.tiling.tiles)
        assert replay.note in ("recorded growth", "")
        cursor.restart()
        assert cursor.pos == 0 and np.all(cursor.grid == UNASSIGNED)


def test_replay_without_record_of_another_tiling_says_so():
    other = grow_tiling(TS, (6, 7), periodic=True, rng=99)
    replay = plan(seed=5).replay(TilingValue(other, TS))
    assert "not grown in one pass" in replay.note
    with pytest.raises(ValueError):
        plan(seed=5, size=[3, 3]).replay(TilingValue(other, TS))


def test_regrow_is_the_kernel_regrowth_and_replays_from_the_kept_tiling():
    p = plan(seed=5)
    before = p.run()
    changed = np.zeros((6, 7), bool)
    changed[2:4, 2:5] = True
    after = p.regrow(before, changed)
    ref = regrow_region(before.tiling, TS, changed, margin=1, rng=5, record_steps=True)
    assert np.array_equal(after.tiling.tiles, ref.tiles)
    kept = ~dilate(changed, 1, periodic=True)
    assert np.array_equal(after.start_tiles[kept], before.tiling.tiles[kept])
    assert np.all(after.start_tiles[~kept] == UNASSIGNED)
    replay = p.replay(after)
    assert "local regrowth" in replay.note
    cursor = ReplayCursor(replay)
    cursor.step(10 ** 6)
    assert np.array_equal(cursor.grid, after.tiling.tiles)


def test_painting_through_the_node_is_the_plans_regrowth():
    doc, undo = graph(doc_seed=2)
    ev = Evaluator()
    before = ev.evaluate(doc).output("grow1", "tiling")
    undo.push(SetParam("grow1", "regions", "0000000;0011000;0011000;0000000;0000000;0000000"))
    undo.push(SetParam("grow1", "region_hints", "1: T=3"))
    after = ev.evaluate(doc).output("grow1", "tiling")
    p = plan(seed=node_seed(2, "grow1"), regions=doc.nodes["grow1"].params["regions"],
             region_hints="1: T=3")
    changed = p.changed_cells(before, {"size": [7, 6], "periodic": True, "hints": "", "availability": 0.0,
                                       "regions": "", "region_hints": ""}, p.seed)
    assert changed is not None and changed.sum() == 4
    assert np.array_equal(after.tiling.tiles, p.regrow(before, changed).tiling.tiles)


def test_resume_grows_what_a_stopped_growth_left():
    p = plan(seed=8)
    partial = p.run(max_steps=10)
    open_cells = partial.tiling.tiles == UNASSIGNED
    assert open_cells.any()
    done = p.resume(partial)
    assert not np.any(done.tiling.tiles == UNASSIGNED)
    assert np.array_equal(done.tiling.tiles[~open_cells], partial.tiling.tiles[~open_cells])
    again = p.resume(done)
    assert again.tiling is done.tiling and len(again.steps) == 0


def test_requested_blocks_weight_the_painted_labels():
    assert np.allclose(plan(hints="T=2,L=1,+=1,-=1").requested_blocks(), [0.4, 0.2, 0.2, 0.2])
    p = plan(regions="1111111;1111111;1111111;0000000;0000000;0000000", region_hints="1: T=1")
    share = p.requested_blocks()
    uniform = plan().requested_blocks()
    assert np.allclose(share, 0.5 * np.array([1, 0, 0, 0]) + 0.5 * uniform)
