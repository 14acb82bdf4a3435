"""Evaluator.adopt: a result computed outside an evaluation, stored as if the node had evaluated.

Small test nodes (tests/engine/graph/conftest.py, counting their calls)
show what re-runs; the RD chain (24 x 12 fields from an .npz grown on
48 x 24 cells, as in tests/engine/nodes/test_rd_session.py) shows a real
stateful node: its own `RDGrowthSession` grown in pieces outside the
evaluator, adopted, then compared byte for byte with an evaluation.
"""

from __future__ import annotations

import numpy as np
import pytest

import engine.nodes  # noqa: F401  (registers the node types)
from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack, load_project,
                          save_project)
from engine.graph.node import node_seed
from engine.nodes.rd import RDGrowNode
from engine.nodes.rd_session import RDGrowthSession

from .conftest import CALLS

NX, NY = 24, 12
GROW = {"resolution": [48, 24], "gamma": 4.0, "max_steps": 200, "eps": 1e-14}


# -- small nodes ------------------------------------------------------------------------------
def chain():
    """a (number 2) -> s (sum, scale 3) -> t (sum, scale 10)."""
    doc = GraphDocument(seed=1)
    st = UndoStack(doc)
    st.push(AddNode("_TestNumber", {"value": 2.0}, node_id="a"))
    st.push(AddNode("_TestSum", {"scale": 3.0}, node_id="s"))
    st.push(AddNode("_TestSum", {"scale": 10.0}, node_id="t"))
    st.push(Connect("a", "value", "s", "terms"))
    st.push(Connect("s", "value", "t", "terms"))
    return doc, st


@pytest.fixture
def small():
    CALLS.clear()
    doc, st = chain()
    ev = Evaluator()
    assert ev.evaluate(doc, targets=["a"]).ok          # a cached, s and t never evaluated
    return doc, st, ev


def test_adopted_outputs_are_served_as_cached_and_downstream_evaluates_from_them(small):
    doc, _, ev = small
    assert ev.adopt(doc, "s", {"value": 42.0}) is True
    report = ev.evaluate(doc)
    assert report.results["s"].status == "cached" and report.results["a"].status == "cached"
    assert report.results["t"].status == "evaluated"
    assert report.output("t") == 420.0                 # computed from the adopted value, not 3 * 2
    assert CALLS["s"] == 0 and CALLS["t"] == 1


def test_the_adopted_key_is_the_evaluated_key(small):
    doc, _, ev = small
    ev.adopt(doc, "s", {"value": 6.0})
    adopted_key = ev.evaluate(doc).results["s"].key
    evaluated = Evaluator().evaluate(doc)
    assert evaluated.results["s"].status == "evaluated" and evaluated.results["s"].key == adopted_key


def test_after_a_parameter_change_the_adopted_entry_is_not_used(small):
    doc, st, ev = small
    assert ev.adopt(doc, "s", {"value": 42.0})
    st.push(SetParam("s", "scale", 4.0))
    report = ev.evaluate(doc)
    assert report.results["s"].status == "evaluated" and report.output("s") == 8.0
    assert CALLS["s"] == 1
    st.undo()                                          # the adopted entry's own parameters again
    assert ev.evaluate(doc).output("s") == 42.0


def test_refused_when_an_upstream_node_is_not_cached_for_this_snapshot(small):
    doc, st, _ = small
    assert Evaluator().adopt(doc, "s", {"value": 42.0}) is False       # nothing evaluated at all
    ev = Evaluator()
    ev.evaluate(doc, targets=["a"])
    st.push(SetParam("a", "value", 5.0))                               # a's cached result is for 2.0
    assert ev.adopt(doc, "s", {"value": 42.0}) is False
    assert ev.adopt(doc, "t", {"value": 1.0}) is False                 # s is not cached either
    report = ev.evaluate(doc)
    assert report.results["s"].status == "evaluated" and report.output("t") == 150.0


@pytest.mark.parametrize("node_id, outputs, inputs", [
    ("s", {}, None),                                   # an output port missing
    ("s", {"wrong": 1.0}, None),
    ("s", {"value": 42.0}, {"terms": [3.0]}),          # not the object the cache feeds
    ("s", {"value": 42.0}, {"terms": []}),
    ("nope", {"value": 42.0}, None),                   # no such node
])
def test_refused_without_storing_anything(small, node_id, outputs, inputs):
    doc, _, ev = small
    assert ev.adopt(doc, node_id, outputs, inputs=inputs) is False
    report = ev.evaluate(doc)
    assert report.results["s"].status == "evaluated" and report.output("t") == 60.0


def test_inputs_that_are_the_cached_ones_are_accepted(small):
    doc, _, ev = small
    fed = ev.evaluate(doc, targets=["a"]).output("a")
    assert ev.adopt(doc, "s", {"value": 42.0}, inputs={"terms": [fed]}) is True
    assert ev.evaluate(doc).results["s"].status == "cached"


def test_a_refused_parameter_is_refused(small):
    doc, _, ev = small
    snap = doc.snapshot()
    snap.nodes["s"] = ("_TestSum", {"scale": 1e9})                    # outside the schema's range
    assert ev.adopt(snap, "s", {"value": 42.0}) is False


def test_a_queued_adoption_is_taken_when_the_next_evaluation_starts(small):
    doc, st, ev = small
    ev.queue_adoption(doc, "s", {"value": 42.0})
    report = ev.evaluate(doc)
    assert report.results["s"].status == "cached" and report.output("t") == 420.0
    # taken once: a refused one (a changed since) is dropped and the node evaluates
    st.push(SetParam("a", "value", 5.0))
    ev.queue_adoption(doc, "s", {"value": 1.0})
    ev2 = Evaluator()
    ev2.queue_adoption(doc, "s", {"value": 1.0})
    assert ev2.evaluate(doc).output("s") == 15.0


def test_an_import_pending_empties_the_cache_first(small):
    doc, _, ev = small
    ev.import_state({})
    assert ev.adopt(doc, "s", {"value": 42.0}) is False                # the cache is gone with the import


# -- a real stateful node: RDGrow ----------------------------------------------------------------
@pytest.fixture(scope="module")
def fields_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("rd") / "f.npz"
    rho = np.zeros((NY, NX))
    rho[2:10, 2:22] = 1.0
    theta = 0.3 + 0.02 * np.arange(NX)[None, :] + 0.0 * np.arange(NY)[:, None]
    c, s = np.cos(theta), np.sin(theta)
    R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    np.savez(path, rho=rho, R=R)
    return path


def rd_document(path, grow=None):
    """f (RDFields) -> g (RDGrow) -> c (RDCompile), seed 5."""
    doc = GraphDocument(seed=5)
    st = UndoStack(doc)
    st.push(AddNode("RDFields", {"path": str(path)}, node_id="f"))
    st.push(AddNode("RDGrow", {**GROW, **(grow or {})}, node_id="g"))
    st.push(AddNode("RDCompile", {"iso": 0.6}, node_id="c"))
    st.push(Connect("f", "rdfields", "g", "rdfields"))
    st.push(Connect("g", "structures", "c", "structures"))
    return doc, st


@pytest.fixture
def grow_calls(monkeypatch):
    """How often RDGrow's evaluate runs."""
    calls = []
    real = RDGrowNode.evaluate

    def counting(self, inputs, params, ctx):
        calls.append(ctx.node_id)
        return real(self, inputs, params, ctx)

    monkeypatch.setattr(RDGrowNode, "evaluate", counting)
    return calls


def grown_outside(ev, doc):
    """The fields cached by ``ev`` and the RDGrow node's value grown by its session in pieces."""
    fields = ev.evaluate(doc, targets=["f"]).output("f")
    session = RDGrowthSession(fields, dict(doc.nodes["g"].params), node_seed(doc.seed, "g"))
    while not session.advance(60):
        pass
    return fields, session.apply()


def same_structures(a, b):
    assert a.s.tobytes() == b.s.tobytes() and a.steps == b.steps and a.edits == b.edits
    for x, y in zip(a.states, b.states):
        assert x.u.tobytes() == y.u.tobytes() and x.v.tobytes() == y.v.tobytes() and x.step == y.step


def test_an_adopted_growth_is_cached_and_compiles_to_the_evaluated_bytes(fields_path, grow_calls):
    doc, _ = rd_document(fields_path)
    ev = Evaluator()
    fields, value = grown_outside(ev, doc)
    assert ev.adopt(doc, "g", {"structures": value}, inputs={"rdfields": fields}) is True
    report = ev.evaluate(doc)
    assert report.ok, report.errors
    assert report.results["g"].status == "cached" and report.results["c"].status == "evaluated"
    assert grow_calls == []
    fresh = Evaluator().evaluate(doc)
    assert grow_calls == ["g"]
    same_structures(report.output("g"), fresh.output("g"))
    assert report.output("c", "field").values.tobytes() == fresh.output("c", "field").values.tobytes()


def test_the_saved_project_is_the_one_a_real_evaluation_saves(fields_path, tmp_path):
    doc, _ = rd_document(fields_path)
    ev = Evaluator()
    fields, value = grown_outside(ev, doc)
    assert ev.adopt(doc, "g", {"structures": value}, inputs={"rdfields": fields})
    real = Evaluator()
    real.evaluate(doc)
    adopted_state, real_state = ev.export_state(), real.export_state()
    assert set(adopted_state) == {"g"} and set(real_state) == {"g"}
    # the growth's wall time is measured, so two runs never store the same seconds: copy them over
    timed = ("seconds", "cell_updates_per_second")
    assert set(adopted_state["g"]["value"]) == set(real_state["g"]["value"])
    adopted_state["g"]["value"].update({k: real_state["g"]["value"][k] for k in timed})
    assert adopted_state == real_state
    paths = []
    for name, state in (("adopted", adopted_state), ("real", real_state)):
        doc.node_state = state
        paths.append(tmp_path / f"{name}.json")
        save_project(doc, paths[-1])
    assert paths[0].read_bytes() == paths[1].read_bytes()
    reopened = load_project(paths[0])
    again = Evaluator()
    assert again.import_state(reopened.node_state) == []
    assert again.evaluate(reopened).results["g"].status == "cached"


def test_an_edit_after_adoption_regrows_from_the_adopted_result(fields_path, grow_calls):
    """The adopted result is the node's ``ctx.previous``: appending an edit regrows locally."""
    edit = {"mode": "erase", "centre": [24.0, 12.0], "radius": 3.0}
    doc, st = rd_document(fields_path)
    ev = Evaluator()
    fields, value = grown_outside(ev, doc)
    ev.adopt(doc, "g", {"structures": value}, inputs={"rdfields": fields})
    st.push(SetParam("g", "edits", [edit]))
    report = ev.evaluate(doc)
    assert report.results["g"].status == "evaluated" and report.output("g").regrown
    real_doc, real_st = rd_document(fields_path)
    real = Evaluator()
    real.evaluate(real_doc)
    real_st.push(SetParam("g", "edits", [edit]))
    same_structures(report.output("g"), real.evaluate(real_doc).output("g"))
