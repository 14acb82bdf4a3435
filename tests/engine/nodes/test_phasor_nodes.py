"""Phasor infill nodes: MeshImport, PhasorFields (painted strokes), PhasorNoise
(local updates), PhasorSlice; cached == uncached, same seed same slice."""

import json

import numpy as np
import pytest
import trimesh

from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, ParamError, SetParam,
                          UndoStack)
from engine.graph.node import node_seed, node_type
from engine.phasor.field_init import fields_from_spec
from engine.phasor.fields import trilinear
from engine.phasor.sampling import sample_kernels
from engine.phasor.strokes import Stroke, apply_strokes

SPEC = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 60, "centre": [4.0, 4.0, 0.0]},
        "F": {"kind": "linear", "axis": "x", "from": 1.0, "to": 1.4}}
STROKE_F = {"field": "F", "axis": "z", "position": 1.0, "points": [[2.0, 2.0], [4.0, 3.0]],
            "radius": 1.2, "value": 1.6}
STROKE_D = {"field": "D", "axis": "z", "position": 1.0, "points": [[5.0, 6.0], [7.0, 6.5]],
            "radius": 1.0, "strength": 0.7}
STROKE_G = {"field": "Gamma", "axis": "z", "position": 0.5, "points": [[6.0, 2.0]], "radius": 1.5,
            "value": 0.4, "falloff": "linear"}


def _doc(*, strokes=(), lo=(0.0, 0.0, 0.0), hi=(8.0, 8.0, 2.0), resolution=16, spec=SPEC, slice_=False):
    doc = GraphDocument(seed=11)
    st = UndoStack(doc)
    st.push(AddNode("PhasorFields", {"lo": list(lo), "hi": list(hi), "resolution": resolution,
                                     "spec": json.dumps(spec), "strokes": list(strokes)}, node_id="f"))
    st.push(AddNode("PhasorNoise", {}, node_id="n"))
    st.push(Connect("f", "fields", "n", "fields"))
    if slice_:
        st.push(AddNode("PhasorSlice", {"position": 1.0, "pixel": 0.1}, node_id="s"))
        st.push(Connect("n", "infill", "s", "infill"))
    return doc, st


def _arrays(fields):
    return [fields.direction, fields.frequency, fields.spread, fields.lo, fields.hi]


# ------------------------------------------------------------------ PhasorFields

def test_fields_node_with_strokes_equals_apply_strokes_on_the_spec():
    doc, _ = _doc(strokes=[STROKE_F, STROKE_D, STROKE_G])
    r = Evaluator().evaluate(doc, targets=["f"])
    assert r.ok, r.errors
    got = r.output("f").fields
    # 16 cells along the longest side (x, y: 8 mm), z in proportion: 2 / 8 * 16 = 4
    ref = fields_from_spec(SPEC, lo=[0, 0, 0], hi=[8, 8, 2], shape=(4, 16, 16))
    ref, _ = apply_strokes(ref, [Stroke.from_dict(s) for s in (STROKE_F, STROKE_D, STROKE_G)])
    for a, b in zip(_arrays(got), _arrays(ref)):
        assert a.tobytes() == b.tobytes()
    assert r.output("f").n_strokes == 3 and r.output("f").changed is None


def test_appending_strokes_paints_only_them_and_equals_a_fresh_evaluation():
    doc, st = _doc(strokes=[STROKE_F])
    ev = Evaluator()
    first = ev.evaluate(doc, targets=["f"]).output("f")
    st.push(SetParam("f", "strokes", doc.node("f").params["strokes"] + [STROKE_D]))   # one paint stroke
    second = ev.evaluate(doc, targets=["f"]).output("f")
    fresh = Evaluator().evaluate(doc, targets=["f"]).output("f")
    for a, b in zip(_arrays(second.fields), _arrays(fresh.fields)):
        assert a.tobytes() == b.tobytes()
    box = second.changed
    assert box is not None and all(s.stop > s.start for s in box)
    outside = np.ones(first.fields.shape, bool)
    outside[box] = False
    assert np.array_equal(second.fields.direction[outside], first.fields.direction[outside])
    assert not np.array_equal(second.fields.direction[box], first.fields.direction[box])
    # undo restores the previous list (and the cached result)
    st.undo()
    assert doc.node("f").params["strokes"] == [Stroke.from_dict(STROKE_F).to_dict()]
    assert ev.evaluate(doc, targets=["f"]).output("f") is first
    # a list that is no extension is painted afresh; only the differing strokes' cells are reported
    st.redo()
    ev.evaluate(doc, targets=["f"])
    st.push(SetParam("f", "strokes", [STROKE_F, STROKE_G]))
    third = ev.evaluate(doc, targets=["f"]).output("f")
    fields = fields_from_spec(SPEC, lo=[0, 0, 0], hi=[8, 8, 2], shape=(4, 16, 16))
    with_f, _ = apply_strokes(fields, [Stroke.from_dict(STROKE_F)])
    _, box_g = apply_strokes(with_f, [Stroke.from_dict(STROKE_G)])
    union = tuple(slice(min(a.start, b.start), max(a.stop, b.stop)) for a, b in zip(box, box_g))
    assert third.changed == union
    outside = np.ones(first.fields.shape, bool)
    outside[union] = False
    assert np.array_equal(third.fields.spread[outside], second.fields.spread[outside])
    assert np.array_equal(third.fields.direction[outside], second.fields.direction[outside])


def test_a_bad_stroke_is_refused_and_leaves_the_list_alone():
    doc, st = _doc(strokes=[STROKE_F])
    before = doc.node("f").params["strokes"]
    bad = dict(STROKE_F, radius=-1.0)
    with pytest.raises(ParamError) as err:
        st.push(SetParam("f", "strokes", before + [bad]))
    assert err.value.where == "strokes" and "stroke 1" in str(err.value) and "radius" in str(err.value)
    assert doc.node("f").params["strokes"] == before
    with pytest.raises(ParamError, match="list of brush strokes"):
        st.push(SetParam("f", "strokes", {"not": "a list"}))
    with pytest.raises(ParamError, match="JSON data"):
        st.push(SetParam("f", "strokes", [float("nan")]))


@pytest.mark.parametrize("spec, match", [
    ({"D": [0.0, 0.0, 0.0]}, "zero vector"),
    ({"D": {"kind": "constant", "value": [float("nan"), 0, 1]}}, "finite"),
    ({"F": -1.0}, "F.value"),
    ({"F": 0.0}, "F.value"),
    ({"Gamma": 2.0}, "Gamma.value"),
    ("{not json", "not valid JSON"),
])
def test_bad_spec_fails_the_node_naming_spec(spec, match):
    text = spec if isinstance(spec, str) else json.dumps(spec)
    doc, st = _doc()
    st.push(SetParam("f", "spec", text))
    res = Evaluator().evaluate(doc, targets=["f"]).results["f"]
    assert res.status == "failed" and res.where == "spec" and match in res.error, res.error


def test_box_corners_must_be_ordered():
    doc, _ = _doc(lo=(0, 0, 0), hi=(8, -1, 2))
    res = Evaluator().evaluate(doc, targets=["f"]).results["f"]
    assert res.status == "failed" and res.where == "hi"


# ------------------------------------------------------------------ MeshImport

def test_mesh_import_refuses_an_open_mesh_and_gives_the_domain_box(tmp_path):
    box = trimesh.creation.box(extents=(6.0, 4.0, 2.0))
    closed = tmp_path / "part.stl"
    box.export(closed)
    open_ = tmp_path / "open.stl"
    trimesh.Trimesh(box.vertices, box.faces[:-1], process=False).export(open_)
    doc = GraphDocument(seed=1)
    st = UndoStack(doc)
    st.push(AddNode("MeshImport", {"path": str(open_)}, node_id="m"))
    st.push(AddNode("PhasorFields", {"margin": 0.5, "resolution": 14}, node_id="f"))
    st.push(Connect("m", "mesh", "f", "domain"))
    r = Evaluator().evaluate(doc)
    assert r.results["m"].status == "failed" and r.results["m"].where == "path"
    assert "not closed" in r.results["m"].error and r.results["f"].status == "blocked"
    st.push(SetParam("m", "path", str(closed)))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    fv = r.output("f")
    assert np.allclose(fv.fields.lo, [-3.5, -2.5, -1.5]) and np.allclose(fv.fields.hi, [3.5, 2.5, 1.5])
    assert fv.fields.shape == (6, 10, 14)      # 14 cells along x (7 mm), y 5 mm -> 10, z 3 mm -> 6
    assert fv.domain.path == str(closed) and len(fv.domain.faces) == len(box.faces)
    st.push(SetParam("m", "path", ""))
    res = Evaluator().evaluate(doc).results["m"]
    assert res.status == "failed" and res.where == "path"


# ------------------------------------------------------------------ PhasorNoise

def _noise_doc():
    # F = 2 everywhere, R = 4.5 / 2 = 2.25 mm: a 20 mm box has sites far from a corner stroke
    return _doc(lo=(0, 0, 0), hi=(20, 20, 2), resolution=20, spec={"D": [1, 0.3, 0], "F": 2.0})


def test_noise_update_keeps_far_phases_and_resamples_near_sites():
    doc, st = _noise_doc()
    ev = Evaluator()
    before = ev.evaluate(doc).output("n")
    stroke = {"field": "F", "axis": "z", "position": 1.0, "points": [[3.0, 3.0], [4.0, 4.0]],
              "radius": 1.5, "value": 2.6}            # raises F: F_min and R stay
    st.push(SetParam("f", "strokes", [stroke]))
    r = ev.evaluate(doc)
    assert r.ok, r.errors
    after, fv = r.output("n"), r.output("f")
    k0, k1 = before.kernels, after.kernels
    assert k1.radius == k0.radius and np.array_equal(k1.positions, k0.positions)
    # an independent bound on what may change: the painted cells' box, grown by one
    # cell (trilinear reach) and then by the re-alignment margin of one kernel radius
    f = fv.fields
    cells = [np.arange(s.start, s.stop) for s in fv.changed[::-1]]           # x, y, z
    lo = np.array([f.lo[a] + (c[0] - 0.5) * f.spacing[a] for a, c in enumerate(cells)])
    hi = np.array([f.lo[a] + (c[-1] + 1.5) * f.spacing[a] for a, c in enumerate(cells)])
    lo[2], hi[2] = -np.inf, np.inf                    # the stroke spans the whole (thin) z range
    near = np.all((k0.positions >= lo - k0.radius - 1e-9) & (k0.positions <= hi + k0.radius + 1e-9), axis=1)
    assert 0 < near.sum() < 0.5 * k0.n
    assert np.array_equal(k1.phase_v[~near], k0.phase_v[~near])
    assert np.array_equal(k1.phase_w[~near], k0.phase_w[~near])
    assert not np.array_equal(k1.phase_v[near], k0.phase_v[near])
    # every site's oscillator is what a fresh sample of the painted fields gives
    fresh = sample_kernels(f, per_cell=8, c=4.5, rng=node_seed(doc.seed, "n"))
    assert np.array_equal(k1.frequency, fresh.frequency)
    assert np.array_equal(k1.direction_v, fresh.direction_v)
    assert np.array_equal(k1.direction_w, fresh.direction_w)
    moved = k1.frequency != k0.frequency
    assert moved.any() and np.all(near[moved])
    assert np.allclose(k1.frequency[moved], trilinear(f.frequency, f.lo, f.hi, k1.positions[moved]))
    lo_r, hi_r = after.changed_region
    assert np.all(lo_r <= hi_r) and np.all(hi_r - lo_r < f.hi - f.lo + 1e-9)


def test_lowering_f_min_or_changing_c_samples_afresh():
    doc, st = _noise_doc()
    ev = Evaluator()
    ev.evaluate(doc)
    stroke = {"field": "F", "axis": "z", "position": 1.0, "points": [[3.0, 3.0]], "radius": 1.5,
              "value": 1.5}                          # lowers F_min: a new kernel radius
    st.push(SetParam("f", "strokes", [stroke]))
    after = ev.evaluate(doc).output("n")
    fresh = Evaluator().evaluate(doc).output("n")
    assert after.changed_region is None
    assert np.array_equal(after.kernels.phase_v, fresh.kernels.phase_v)


def test_toggling_the_filter_keeps_the_kernels():
    doc, st = _doc()
    ev = Evaluator()
    a = ev.evaluate(doc).output("n")
    st.push(SetParam("n", "filtered", False))
    b = ev.evaluate(doc).output("n")
    assert not b.filtered and a.filtered
    assert np.array_equal(a.kernels.phase_v, b.kernels.phase_v)


def test_stored_noise_round_trips_through_the_project_state():
    doc, st = _doc(strokes=[STROKE_F])
    ev = Evaluator()
    ev.evaluate(doc)
    st.push(SetParam("f", "strokes", doc.node("f").params["strokes"] + [STROKE_D]))
    painted = ev.evaluate(doc).output("n")          # phases with a local re-alignment in their history
    states = json.loads(json.dumps(ev.export_state()))
    assert set(states) == {"n"}
    other = Evaluator()
    assert other.import_state(states) == []
    r = other.evaluate(doc)
    assert r.results["n"].status == "cached" and not r.warnings
    k = r.output("n").kernels
    assert np.array_equal(k.phase_v, painted.kernels.phase_v)
    assert np.array_equal(k.phase_w, painted.kernels.phase_w)
    assert np.array_equal(k.direction_v, painted.kernels.direction_v)
    with pytest.raises(ValueError, match="fields changed"):
        node_type("PhasorNoise")().decode_state(states["n"]["value"],
                                                {"fields": Evaluator().evaluate(_doc()[0]).output("f")})


# ------------------------------------------------------------------ PhasorSlice

def test_slice_cached_equals_uncached_and_same_seed_same_bytes():
    doc, st = _doc(slice_=True)
    ev = Evaluator()
    r1 = ev.evaluate(doc)
    assert r1.ok, r1.errors
    r2 = ev.evaluate(doc)
    assert all(res.status == "cached" for res in r2.results.values())
    assert r2.output("s", "image") is r1.output("s", "image")
    fresh = Evaluator().evaluate(doc)
    a, b = r1.output("s", "image"), fresh.output("s", "image")
    assert a.values.tobytes() == b.values.tobytes()
    assert np.array_equal(a.lo, [0, 0]) and np.array_equal(a.hi, [8, 8]) and a.values.shape == (80, 80)
    assert set(np.unique(a.values)) == {0.0, 1.0}
    e = r1.output("s", "energy")
    assert e == fresh.output("s", "energy") and 0 <= e.value <= 1 and e.pixels == 78 * 78
    assert e.state == "aligned+filtered" and e.q == 2.0
    assert e.value >= max(e.v, e.w)
    st.push(SetParam("s", "show", "p_v"))
    pv = ev.evaluate(doc).output("s", "image").values
    assert pv.min() >= 0 and pv.max() < 1 and len(np.unique(pv)) > 100
    st.push(SetParam("s", "show", "singularity"))
    s = ev.evaluate(doc).output("s", "image").values
    assert np.all(np.isfinite(s)) and s.min() >= 0 and s.max() <= 10


def test_slice_refusals_name_the_parameter():
    doc, st = _doc(slice_=True, spec={"F": 2.0})
    st.push(SetParam("s", "pixel", 0.2))            # F = 2 needs a pixel <= 1 / (4 * 2) = 0.125 mm
    res = Evaluator().evaluate(doc).results["s"]
    assert res.status == "failed" and res.where == "pixel"
    assert "F up to 2 cells/mm" in res.error and "0.2 mm" in res.error and "F <= 1.25" in res.error
    st.push(SetParam("s", "pixel", 0.1))
    st.push(SetParam("s", "position", 5.0))         # the box spans z 0 .. 2
    res = Evaluator().evaluate(doc).results["s"]
    assert res.status == "failed" and res.where == "position" and "[0, 2]" in res.error


def test_numpy_and_gpu_slices_agree():
    pytest.importorskip("moderngl")
    from engine.gpu import gpu_available
    if not gpu_available():
        pytest.skip("no EGL context")
    doc, st = _doc(slice_=True)
    ev = Evaluator()
    gpu = ev.evaluate(doc).output("s", "image").values
    st.push(SetParam("s", "engine", "numpy"))
    cpu = ev.evaluate(doc).output("s", "image").values
    assert np.mean(gpu != cpu) < 0.002


# ------------------------------------------------------------------ the example project

def test_the_phasor_example_is_generated_and_evaluates(tmp_path):
    import importlib.util
    from pathlib import Path

    from engine.graph import load_project

    root = Path(__file__).resolve().parents[3]
    spec = importlib.util.spec_from_file_location("make_examples", root / "tools" / "make_examples.py")
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    stored = sorted((root / "resources" / "examples").glob("phasor_*.json"))
    assert [p.stem for p in stored] == sorted(generator.PHASOR_EXAMPLES)
    generator.write_phasor_examples(tmp_path)
    for path in stored:
        assert json.loads((tmp_path / path.name).read_text()) == json.loads(path.read_text()), \
            f"{path.name} differs from tools/make_examples.py: regenerate it"
        doc = load_project(path)
        assert len(doc.node("fields").params["strokes"]) >= 3
        st = UndoStack(doc)
        st.push(SetParam("slice", "pixel", 0.2))
        st.push(SetParam("slice", "engine", "numpy"))
        r = Evaluator().evaluate(doc)
        assert r.ok, r.errors
        e = r.output("slice", "energy")
        assert 0 < e.value < 0.2 and e.pixels > 10000
        image = r.output("slice", "image").values
        assert 0.3 < image.mean() < 0.7
