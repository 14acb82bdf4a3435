"""Virtual growth nodes through the evaluator."""

import numpy as np
import pytest
import trimesh

import engine.nodes.growth  # noqa: F401  (registers the nodes)
from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, ParamError, SetParam,
                          SetSeed, UndoStack)
from engine.geometry.values import Field, Skeleton
from engine.growth.values import TilingValue
from engine.physics.values import Stiffness
from engine.growth import grow_tiling, load_tileset, realised_probabilities, tiling_image


def _grow_graph(tileset="TL+-", size=(6, 5), seed=0, **grow):
    doc = GraphDocument(seed=seed)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", {"name": tileset}, node_id="ts"))
    st.push(AddNode("Grow", {"size": list(size), **grow}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    return doc, st


def _tiles(doc, ev=None):
    r = (ev or Evaluator()).evaluate(doc)
    assert r.ok, r.errors
    return r, np.asarray(r.output("g").tiling.tiles)


def test_grow_is_deterministic_under_the_document_seed():
    doc, st = _grow_graph(size=(8, 7), seed=4)
    _, a = _tiles(doc)
    _, b = _tiles(doc)                                  # uncached, same seed
    assert a.shape == (7, 8) and np.array_equal(a, b)
    ev = Evaluator()
    r1, _ = _tiles(doc, ev)
    r2, c = _tiles(doc, ev)
    assert r2.results["g"].status == "cached" and np.array_equal(a, c)
    st.push(SetSeed(5))
    r3, d = _tiles(doc, ev)
    assert r3.results["g"].status == "evaluated" and not np.array_equal(a, d)
    st.undo()
    _, e = _tiles(doc, ev)
    assert np.array_equal(a, e)
    # the node's tiling is grow_tiling with the node seed: same bytes
    seed = r1.output("g").tiling.seed
    ref = grow_tiling(load_tileset("TL+-"), (7, 8), periodic=True, rng=seed)
    assert np.array_equal(ref.tiles, a)


def test_grow_hints_and_availability_reach_the_kernel():
    doc, st = _grow_graph(size=(12, 12), hints="T=0,L=0,-=0,+=1")
    r, tiles = _tiles(doc)
    ts = load_tileset("TL+-")
    assert realised_probabilities(r.output("g").tiling, ts).tolist() == [0, 0, 0, 1]
    st.push(SetParam("g", "hints", "T=1,L=1,-=1,+=1"))
    st.push(SetParam("g", "availability", 1.0))
    r, _ = _tiles(doc)
    assert "remaining" in r.output("g").tiling.stats


def test_grow_refuses_bad_hints_and_sizes_by_name():
    doc, st = _grow_graph(hints="T=1,Q=2")
    r = Evaluator().evaluate(doc)
    assert r.results["g"].status == "failed" and r.results["g"].where == "hints"
    assert "entry 2 'Q=2'" in r.errors["g"]
    st.push(SetParam("g", "hints", ""))
    st.push(SetParam("g", "size", [4, 4, 4]))
    r = Evaluator().evaluate(doc)
    assert r.results["g"].where == "size" and "2D" in r.errors["g"]
    with pytest.raises(ParamError, match=r"'size'.*\[1, 1000\]"):
        st.push(SetParam("g", "size", [0, 4]))


def test_tileset_node_by_name_and_by_path(tmp_path):
    doc, st = _grow_graph()
    r = Evaluator().evaluate(doc)
    assert r.output("ts").name == "TL+-"
    st.push(SetParam("ts", "path", str(tmp_path / "missing.json")))
    r = Evaluator().evaluate(doc)
    assert r.results["ts"].status == "failed" and r.results["ts"].where == "path"
    assert r.results["g"].status == "blocked"
    with pytest.raises(ParamError, match="'name'"):
        st.push(SetParam("ts", "name", "nope"))


def test_tiling_image_is_a_field_over_the_blocks():
    doc, st = _grow_graph(size=(5, 3))
    st.push(AddNode("TilingImage", {"resolution": 10, "line_width": 2.0}, node_id="img"))
    st.push(Connect("g", "tiling", "img", "tiling"))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    f, tv = r.output("img"), r.output("g")
    assert isinstance(f, Field) and isinstance(tv, TilingValue)
    assert f.grid_shape == (30, 50) and f.lo.tolist() == [0, 0] and f.hi.tolist() == [5, 3]
    np.testing.assert_allclose(f.spacing, [0.1, 0.1])
    ref = tiling_image(tv.tiling, tv.tileset, resolution=10, line_width=2.0)
    assert np.array_equal(f.values, ref)


def test_tiling_beams_feed_object_to_a_watertight_mesh():
    doc, st = _grow_graph(tileset="cubic-beams", size=(3, 3, 3), seed=2)
    st.push(AddNode("TilingBeams", {"radius": 0.2}, node_id="b"))
    st.push(Connect("g", "tiling", "b", "tiling"))
    st.push(AddNode("Object", {"resolution": 48}, node_id="o"))
    st.push(Connect("b", "skeleton", "o", "skeleton"))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    skel = r.output("b")
    assert isinstance(skel, Skeleton) and len(skel.lines) > 0
    pts = np.concatenate([e.polyline for e in skel.lines])
    assert pts.min() >= -1e-12 and pts.max() <= 1 + 1e-12          # the unit cell
    assert all(np.allclose(e.thickness, 2 * 0.2 / 3) for e in skel.lines)
    solid = r.output("o")
    mesh = trimesh.Trimesh(solid.vertices, solid.faces, process=False)
    assert mesh.is_watertight and mesh.volume > 0
    # the solid's volume fraction is near the beams' (overlaps at joints lower it,
    # rounded ends raise it)
    beam_volume = sum(np.pi * (0.2 / 3) ** 2 * np.linalg.norm(np.diff(e.polyline, axis=0), axis=1).sum()
                      for e in skel.lines)
    assert 0.5 * beam_volume < solid.volume_fraction < 1.5 * beam_volume


def test_tiling_properties_gives_a_stiffness_2d():
    doc, st = _grow_graph(size=(2, 2), hints="+=1")
    st.push(AddNode("TilingProperties", {"resolution": 20, "nu": 0.3}, node_id="p"))
    st.push(Connect("g", "tiling", "p", "tiling"))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    s = r.output("p")
    assert isinstance(s, Stiffness) and s.C.shape == (3, 3) and s.resolution == 20
    # square grid of 4-px bars in 20-px blocks: E_x between A = 0.2 and the layer bound
    assert 0.2 <= s.constants["E_x"] <= 1 / (1 - 0.3 ** 2) / (0.2 + 4)
    assert s.symmetry == "tetragonal" and s.density == pytest.approx(0.36)


def test_tiling_properties_3d_and_bad_shape():
    doc, st = _grow_graph(tileset="cubic-beams", size=(2, 2, 2), hints="+3=1")
    st.push(AddNode("TilingProperties", {"resolution": 8, "nu": 0.3}, node_id="p"))
    st.push(Connect("g", "tiling", "p", "tiling"))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    s = r.output("p")
    assert s.C.shape == (6, 6) and s.symmetry == "cubic"
    st.push(SetParam("g", "size", [2, 2, 3]))
    r = Evaluator().evaluate(doc)
    assert r.results["p"].status == "failed" and "cubic tiling" in r.errors["p"]


def test_editing_a_tileset_file_on_disk_re_evaluates_the_nodes(tmp_path):
    import json
    import os

    from engine.growth import list_tilesets

    data = json.loads(list_tilesets()["TL+-"].read_text(encoding="utf-8"))
    data["name"] = "edited-on-disk"
    path = tmp_path / "set.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    doc, st = _grow_graph(size=(6, 5))
    st.push(SetParam("ts", "path", str(path)))
    ev = Evaluator()
    r1, _ = _tiles(doc, ev)
    assert _tiles(doc, ev)[0].results["g"].status == "cached"
    before = r1.output("ts").weights.copy()
    blocks = data["blocks"]
    first = blocks[0] if isinstance(blocks, list) else next(iter(blocks.values()))
    first["weight"] = 7.0
    path.write_text(json.dumps(data), encoding="utf-8")
    os.utime(path, ns=(1, 1))        # a changed file with an old time stamp still counts
    r2, _ = _tiles(doc, ev)
    assert r2.results["ts"].status == "evaluated" and r2.results["g"].status == "evaluated"
    assert not np.array_equal(before, r2.output("ts").weights)
