"""Reaction-diffusion nodes through the evaluator: TopOpt -> RDFields -> RDGrow -> RDCompile."""

import json

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, ParamError, SetParam, SetSeed,
                          UndoStack, load_project, save_project)
from engine.geometry.values import Field, Solid
from engine.rd.values import ContourValue, RDFieldsValue, RDStructuresValue
from engine.topopt.values import DesignValue

# small enough for a few seconds: gamma = 4 halves the pattern's wavelength so
# that stripes form in the thin members of a 32 x 16 design grown on 96 x 48
TOPOPT = {"preset": "cantilever", "resolution": [32, 16], "max_iter": 15}
GROW = {"resolution": [96, 48], "gamma": 4.0, "max_steps": 1500}


def _doc(seed=0, topopt=None, grow=None, compile_=True):
    doc = GraphDocument(seed=seed)
    st = UndoStack(doc)
    st.push(AddNode("TopOpt", {**TOPOPT, **(topopt or {})}, node_id="to"))
    st.push(AddNode("RDFields", {}, node_id="f"))
    st.push(AddNode("RDGrow", {**GROW, **(grow or {})}, node_id="g"))
    st.push(Connect("to", "design", "f", "design"))
    st.push(Connect("f", "rdfields", "g", "rdfields"))
    if compile_:
        st.push(AddNode("RDCompile", {}, node_id="c"))
        st.push(Connect("g", "structures", "c", "structures"))
    return doc, st


def _ok(report):
    assert report.ok, report.errors
    return report


# ------------------------------------------------------------------ TopOpt

def test_topopt_cached_equals_uncached():
    doc, _ = _doc(compile_=False)
    ev = Evaluator()
    a = _ok(ev.evaluate(doc, targets=["to"])).output("to")
    b = _ok(ev.evaluate(doc, targets=["to"]))
    assert b.results["to"].status == "cached" and b.output("to") is a
    c = _ok(Evaluator().evaluate(doc, targets=["to"])).output("to")
    assert isinstance(a, DesignValue) and a.rho.shape == (16, 32) and a.sigma.shape == (1, 16, 32, 2, 2)
    for name in ("rho", "sigma", "sigma_combined", "rotation", "principal"):
        assert np.array_equal(getattr(a, name), getattr(c, name)), name
    # rotation columns are the principal directions: sigma = R diag(values) R^T
    rebuilt = np.einsum("...ik,...k,...jk->...ij", a.rotation, a.principal, a.rotation)
    assert np.allclose(rebuilt, a.sigma_combined, atol=1e-9 * np.abs(a.sigma_combined).max())
    assert a.problem.name == "cantilever_2d" and 0.3 < a.rho.mean() < 0.5


def test_topopt_refusals_name_the_parameter():
    doc, st = _doc(compile_=False)
    for name, value in (("resolution", [32, 16, 4]), ("preset", "lbeam")):
        st.push(SetParam("to", name, value))
        r = Evaluator().evaluate(doc, targets=["to"])
        assert r.results["to"].status == "failed" and r.results["to"].where == "resolution", r.errors
        st.undo()
    st.push(SetParam("to", "problem", {"load_cases": [[{"node": [99, 0], "force": [0.0, -1.0]}]]}))
    r = Evaluator().evaluate(doc, targets=["to"])
    assert r.results["to"].where == "problem" and "outside the node grid" in r.results["to"].error
    with pytest.raises(ParamError, match="problem"):
        st.push(SetParam("to", "problem", {"loads": []}))


# ------------------------------------------------------------------ RDFields

def test_fields_paint_solid_regions_and_import_files(tmp_path):
    from engine.rd.field_io import RDFields, save_fields

    doc, st = _doc(compile_=False)
    ev = Evaluator()
    plain = _ok(ev.evaluate(doc, targets=["f"])).output("f")
    assert isinstance(plain, RDFieldsValue) and plain.gamma.shape == (16, 32)
    stroke = [{"centre": [28.0, 8.0], "radius": 2.0, "value": 1.0}]
    st.push(SetParam("f", "gamma_c", [stroke]))
    painted = _ok(ev.evaluate(doc, targets=["f"])).output("f")
    assert painted.gamma[8, 28] == 1.0 and np.array_equal(painted.rotation, plain.rotation)
    assert (painted.gamma >= plain.gamma).all() and (painted.gamma > plain.gamma).sum() >= 9
    with pytest.raises(ParamError, match="gamma_c"):
        st.push(SetParam("f", "gamma_c", [[{"centre": [1, 2], "radius": -1, "value": 1}]]))
    # the same fields from a file, without a design: R and magnitudes come from sigma
    path = tmp_path / "fields.npz"
    design = ev.evaluate(doc, targets=["to"]).output("to")
    save_fields(path, RDFields(design.rho, design.sigma_combined))
    other = GraphDocument()
    UndoStack(other).push(AddNode("RDFields", {"path": str(path)}, node_id="f"))
    imported = _ok(Evaluator().evaluate(other)).output("f")
    assert np.allclose(imported.rho, plain.rho) and np.allclose(np.abs(imported.magnitude), plain.magnitude)
    # a file with a NaN tensor is refused naming the path
    sigma = np.array(design.sigma_combined)
    sigma[3, 4, 0, 0] = np.nan
    np.savez(tmp_path / "bad.npz", rho=design.rho, sigma=sigma)
    UndoStack(other).push(SetParam("f", "path", str(tmp_path / "bad.npz")))
    r = Evaluator().evaluate(other)
    assert r.results["f"].where == "path" and "NaN" in r.results["f"].error
    sigma[3, 4] = [[1.0, 2.0], [-2.0, 1.0]]                       # not a stress: refused too
    np.savez(tmp_path / "skew.npz", rho=design.rho, sigma=sigma)
    UndoStack(other).push(SetParam("f", "path", str(tmp_path / "skew.npz")))
    r = Evaluator().evaluate(other)
    assert r.results["f"].where == "path" and "symmetric" in r.results["f"].error


# ------------------------------------------------------------------ RDGrow

def test_grow_same_seed_same_bytes_and_refusals():
    doc, st = _doc(compile_=False)
    a = _ok(Evaluator().evaluate(doc)).output("g")
    b = _ok(Evaluator().evaluate(doc)).output("g")
    assert isinstance(a, RDStructuresValue) and a.s.shape == (2, 48, 96) and a.directions == (0, 1)
    assert a.s.tobytes() == b.s.tobytes() and a.steps == b.steps
    assert all(r in ("converged", "max_steps") for r in a.stop_reasons)
    assert a.cell_updates_per_second > 0 and all(len(h) for h in a.g_history)
    inside = a.fields.rho >= a.iso
    assert (a.s[:, inside] > 0.3).mean() > 0.2          # stripes grew in the infill space
    far = distance_transform_edt(~inside) > 4            # u diffuses out of it a little
    assert a.s[:, far].mean() < 0.2 * a.s[:, inside].mean()
    for name, value, where in (("directions", "third", "directions"),
                               ("resolution", [96, 48, 4], "resolution"), ("dt", 50.0, "dt")):
        st.push(SetParam("g", name, value))
        r = Evaluator().evaluate(doc)
        assert r.results["g"].status == "failed" and r.results["g"].where == where, (name, r.errors)
        st.undo()
    with pytest.raises(ParamError, match="edits"):
        st.push(SetParam("g", "edits", [{"mode": "smudge", "centre": [1, 1], "radius": 2}]))


def test_a_cancelled_growth_is_not_kept():
    from engine.graph import CancelToken

    doc, _ = _doc(compile_=False, grow={"max_steps": 100_000, "eps": 1e-15})
    ev = Evaluator()
    token = CancelToken()

    def on_progress(node_id, fraction):
        if node_id == "g" and fraction > 0.0:
            token.cancel()
    r = ev.evaluate(doc, cancel=token, on_progress=on_progress)
    assert r.cancelled and r.results["g"].status == "cancelled"
    assert "g" not in ev.export_state()


def test_grow_refuses_an_empty_infill_space(tmp_path):
    path = tmp_path / "thin.npz"
    np.savez(path, rho=np.full((8, 12), 0.2), R=np.broadcast_to(np.eye(2), (8, 12, 2, 2)))
    doc = GraphDocument()
    st = UndoStack(doc)
    st.push(AddNode("RDFields", {"path": str(path)}, node_id="f"))
    st.push(AddNode("RDGrow", {"max_steps": 10}, node_id="g"))
    st.push(Connect("f", "rdfields", "g", "rdfields"))
    r = Evaluator().evaluate(doc)
    assert r.results["g"].where == "iso" and "empty" in r.results["g"].error


def test_grow_several_seeds_follow_the_document_seed():
    doc, st = _doc(compile_=False, grow={"seeds": "several", "n_seeds": 3, "max_steps": 300})
    a = _ok(Evaluator().evaluate(doc)).output("g").s
    st.push(SetSeed(7))
    b = _ok(Evaluator().evaluate(doc)).output("g").s
    assert not np.array_equal(a, b)


def test_grown_state_round_trips_through_the_project_file(tmp_path):
    doc, _ = _doc(compile_=False)
    ev = Evaluator()
    grown = _ok(ev.evaluate(doc)).output("g")
    doc.node_state = ev.export_state()
    assert set(doc.node_state) == {"g"}
    path = tmp_path / "rd.json"
    save_project(doc, path)
    opened = load_project(path)
    fresh = Evaluator()
    assert fresh.import_state(opened.node_state) == []
    r = _ok(fresh.evaluate(opened))
    assert r.results["g"].status == "cached" and not r.warnings      # restored, not regrown
    again = r.output("g")
    assert again.s.tobytes() == grown.s.tobytes() and again.steps == grown.steps
    assert again.stop_reasons == grown.stop_reasons
    blob = json.dumps(doc.node_state["g"]["value"])
    assert len(blob) < 60_000
    # a stored growth does not fit other fields
    from engine.graph import node_type
    other, st = _doc(compile_=False, topopt={"volfrac": 0.5})
    fields = Evaluator().evaluate(other, targets=["f"]).output("f")
    with pytest.raises(ValueError, match="fields changed"):
        node_type("RDGrow")().decode_state(doc.node_state["g"]["value"], {"rdfields": fields})


def _point_inside(structures, frac=0.3):
    """A growth-grid point (x, y) well inside the infill space."""
    inside = structures.fields.rho >= structures.iso
    deep = distance_transform_edt(inside) >= 3
    ys, xs = np.nonzero(deep)
    i = int(frac * len(ys))
    return [float(xs[i]) + 0.5, float(ys[i]) + 0.5]


def test_an_appended_erase_regrows_locally_and_faster():
    doc, st = _doc(compile_=False)
    ev = Evaluator()
    r1 = _ok(ev.evaluate(doc))
    before = r1.output("g")
    edit = {"mode": "erase", "centre": _point_inside(before), "radius": 5.0}
    st.push(SetParam("g", "edits", [edit]))
    r2 = _ok(ev.evaluate(doc))
    after = r2.output("g")
    assert after.regrown and after.edits == (edit,) and after.changed is not None
    box = tuple(slice(a, b) for a, b in after.changed)
    outside = np.ones(after.fields.grid_shape, bool)
    outside[box] = False
    assert outside.sum() > 0.8 * outside.size                     # a local window ...
    assert np.array_equal(after.s[:, outside], before.s[:, outside])   # ... outside it nothing moved
    assert not np.array_equal(after.s[:, ~outside], before.s[:, ~outside])
    assert all(b < n < 2 * b for n, b in zip(after.steps, before.steps))   # regrowth: fewer steps than a growth
    # history matters only through the edits: growing afresh with the edit gives the same bytes
    fresh = _ok(Evaluator().evaluate(doc)).output("g")
    assert fresh.s.tobytes() == after.s.tobytes()
    # undo: the cached result before the edit comes back as it was
    st.undo()
    r3 = ev.evaluate(doc)
    assert r3.results["g"].status == "cached" and r3.output("g") is before
    # a draw outside the infill space is refused, naming the edits
    far = distance_transform_edt(before.fields.rho < before.iso) > 3
    ys, xs = np.nonzero(far)
    st.push(SetParam("g", "edits", [{"mode": "draw", "centre": [xs[0] + 0.5, ys[0] + 0.5], "radius": 1.5}]))
    r4 = ev.evaluate(doc)
    assert r4.results["g"].where == "edits" and "outside the infill space" in r4.results["g"].error


def test_edits_after_reopening_regrow_from_the_stored_state(tmp_path):
    doc, st = _doc(compile_=False)
    ev = Evaluator()
    grown = _ok(ev.evaluate(doc)).output("g")
    first = {"mode": "erase", "centre": _point_inside(grown, 0.3), "radius": 4.0}
    st.push(SetParam("g", "edits", [first]))
    _ok(ev.evaluate(doc))
    doc.node_state = ev.export_state()
    save_project(doc, tmp_path / "p.json")
    second = {"mode": "draw", "centres": [_point_inside(grown, 0.7)], "radius": 3.0}
    st.push(SetParam("g", "edits", [first, second]))
    in_session = _ok(ev.evaluate(doc)).output("g")
    opened = load_project(tmp_path / "p.json")
    fresh = Evaluator()
    fresh.import_state(opened.node_state)
    assert _ok(fresh.evaluate(opened)).results["g"].status == "cached"
    UndoStack(opened).push(SetParam("g", "edits", [first, second]))
    r = _ok(fresh.evaluate(opened))
    reopened = r.output("g")
    assert reopened.regrown and reopened.s.tobytes() == in_session.s.tobytes()


# ------------------------------------------------------------------ RDCompile

def test_compile_2d_gives_field_contours_and_slab():
    doc, st = _doc()
    r = _ok(Evaluator().evaluate(doc))
    field, solid, contour = (r.output("c", p) for p in ("field", "solid", "contour"))
    assert isinstance(field, Field) and field.values.shape == (48, 96)
    assert 0.0 <= field.values.min() and field.values.max() <= 1.0
    assert isinstance(contour, ContourValue) and len(contour.polylines) >= 1
    assert all(np.allclose(p[0], p[-1]) for p in contour.polylines)             # closed loops
    assert isinstance(solid, Solid) and not solid.periodic and len(solid.faces)
    # without the infill space cut nothing is solid outside it
    inside = r.output("g").fields.rho >= 0.5
    assert (field.values[~inside] <= 0.5).all()
    st.push(SetParam("c", "combine", "lattice"))
    assert Evaluator().evaluate(doc).results["c"].where == "combine"
    st.undo()
    st.push(SetParam("c", "rescale", True))
    st.push(SetParam("c", "mu", [0.2, 0.3, 0.3]))
    assert Evaluator().evaluate(doc).results["c"].where == "mu"
    with pytest.raises(ParamError, match="mu"):
        st.push(SetParam("c", "mu", [0.2]))


def test_compile_filters_reach_the_density():
    doc, st = _doc()
    ev = Evaluator()
    plain = _ok(ev.evaluate(doc)).output("c", "field").values
    outs = {}
    for name, value in (("rescale", True), ("variable_thickness", True), ("min_member", 2.0)):
        st.push(SetParam("c", name, value))
        outs[name] = _ok(ev.evaluate(doc)).output("c", "field").values
    # the paper's mu (0.15, 0.4) thin the members of iso 0.7 (mu = 0.3) in one direction, widen the other
    assert not np.array_equal(outs["rescale"], plain)
    # graded thickness never exceeds the uniform one
    assert (outs["variable_thickness"] <= outs["rescale"] + 1e-12).all()
    assert (outs["min_member"] >= outs["variable_thickness"] - 1e-12).all()


@pytest.mark.parametrize("preset, resolution", [("lbeam", [20, 20]), ("lbeam_stress", [20, 20]),
                                                ("bridge", [24, 16]), ("bridge_multi", [24, 16]),
                                                ("mbb3d", [16, 8, 4])])
def test_every_preset_gives_a_consistent_design(preset, resolution):
    doc = GraphDocument()
    UndoStack(doc).push(AddNode("TopOpt", {"preset": preset, "resolution": resolution, "max_iter": 3},
                                node_id="t"))
    d = _ok(Evaluator().evaluate(doc)).output("t")
    dim = len(resolution)
    assert d.rho.shape == tuple(resolution[::-1]) and d.rotation.shape == d.rho.shape + (dim, dim)
    assert np.allclose(np.swapaxes(d.rotation, -1, -2) @ d.rotation, np.eye(dim), atol=1e-9)
    rebuilt = np.einsum("...ik,...k,...jk->...ij", d.rotation, d.principal, d.rotation)
    assert np.allclose(rebuilt, d.sigma_combined, atol=1e-9 * np.abs(d.sigma_combined).max())
    assert d.sigma.shape[0] == (5 if preset == "bridge_multi" else 1)
    if preset.startswith("bridge"):                 # the optimised material angle is the first direction
        theta = np.asarray(d.result.theta)
        assert np.allclose(d.rotation[..., :, 0], np.stack([np.cos(theta), np.sin(theta)], -1))


def test_the_rd_example_is_generated_and_evaluates(tmp_path):
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    spec = importlib.util.spec_from_file_location("make_examples", root / "tools" / "make_examples.py")
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    stored = sorted((root / "resources" / "examples").glob("rd_*.json"))
    assert [p.stem for p in stored] == sorted(generator.RD_EXAMPLES)
    generator.write_rd_examples(tmp_path)
    for path in stored:
        assert json.loads((tmp_path / path.name).read_text()) == json.loads(path.read_text()), \
            f"{path.name} differs from tools/make_examples.py: regenerate it"
        doc = load_project(path)
        assert doc.node("fields").params["gamma_c"]
        st = UndoStack(doc)          # smaller than the example, to stay quick
        st.push(SetParam("topopt", "resolution", [32, 16]))
        st.push(SetParam("topopt", "max_iter", 15))
        st.push(SetParam("grow", "resolution", [96, 48]))
        st.push(SetParam("grow", "gamma", 4.0))
        st.push(SetParam("grow", "max_steps", 1500))
        r = _ok(Evaluator().evaluate(doc))
        density = r.output("compile", "field").values
        assert 0.05 < (density > 0.5).mean() < 0.5
