"""RDGrowthSession: the RDGrow node's growth as an object (engine.nodes.rd_session).

Fields are a 24 x 12 .npz with a known rotation, grown on 48 x 24 cells so
that every test runs in a second or two.  The node's result comes from the
Evaluator on a document holding the same fields and parameters; the session
must give the same bytes however its growth is cut into pieces or stopped.
"""

from __future__ import annotations

import numpy as np
import pytest

import engine.nodes  # noqa: F401  (registers the node types)
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, NodeInputError, UndoStack, node_type
from engine.graph.node import node_seed
from engine.nodes.rd_session import RDGrowthSession
from engine.progress import Cancelled

NX, NY = 24, 12
GROW = {"resolution": [48, 24], "gamma": 4.0, "max_steps": 300, "eps": 1e-14}


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


def node_run(path, grow=None, seed=5):
    """(document, fields value, node seed, node structures) from the Evaluator."""
    doc = GraphDocument(seed=seed)
    st = UndoStack(doc)
    st.push(AddNode("RDFields", {"path": str(path)}, node_id="f"))
    st.push(AddNode("RDGrow", {**GROW, **(grow or {})}, node_id="g"))
    st.push(Connect("f", "rdfields", "g", "rdfields"))
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    return doc, report.output("f"), node_seed(seed, "g"), report.output("g")


def params_of(doc):
    return dict(doc.nodes["g"].params)


def same_bytes(a, b):
    """Two RDStructuresValue hold the same structures, states, steps and stop points."""
    assert a.s.tobytes() == b.s.tobytes()
    assert a.steps == b.steps and a.stop_reasons == b.stop_reasons and a.stop_steps == b.stop_steps
    assert all(x.tobytes() == y.tobytes() for x, y in zip(a.g_history, b.g_history))
    for x, y in zip(a.states, b.states):
        assert x.u.tobytes() == y.u.tobytes() and x.v.tobytes() == y.v.tobytes() and x.step == y.step
        assert x.params == y.params and x.inputs == y.inputs
    assert a.edits == b.edits and a.regrown == b.regrown and a.changed == b.changed


def test_a_whole_run_is_the_node_result(fields_path):
    doc, fields, seed, node = node_run(fields_path)
    session = RDGrowthSession(fields, params_of(doc), seed)
    same_bytes(session.grow(), node)


def test_advancing_in_pieces_equals_one_run(fields_path):
    doc, fields, seed, node = node_run(fields_path)
    session = RDGrowthSession(fields, params_of(doc), seed)
    rounds = 0
    while not session.advance(37):
        rounds += 1
        assert all(0 < n <= 300 for n in session.steps)
    assert rounds == 300 // 37 and session.steps == (300, 300)
    same_bytes(session.apply(), node)
    assert session.apply() is session.apply()            # kept


def test_pause_and_resume_equal_an_uninterrupted_growth(fields_path):
    doc, fields, seed, node = node_run(fields_path)
    session = RDGrowthSession(fields, params_of(doc), seed)
    calls = {"n": 0}

    def stop_at_once(done, total):      # the kernel asks after its first complete step(s)
        calls["n"] += 1
        assert 0.0 <= done <= total
        return False
    with pytest.raises(Cancelled):
        session.advance(None, stop_at_once)
    assert calls["n"] == 1
    paused = session.steps
    assert 0 < paused[0] < 300 and paused[1] == 0 and not session.done
    frame = session.frame("paused")
    assert frame.status == "paused" and frame.steps == paused and frame.stop_reasons == ("", "")
    assert np.array_equal(frame.s[0], (1.0 - frame.states[0].u).astype(np.float32))
    with pytest.raises(RuntimeError):
        session.apply()                                    # not finished
    assert session.advance(None, lambda d, t: True)        # resumed: to the end
    same_bytes(session.apply(), node)


def test_progress_runs_over_the_whole_growth(fields_path):
    doc, fields, seed, _ = node_run(fields_path)
    seen = []
    RDGrowthSession(fields, params_of(doc), seed).grow(lambda d, t: seen.append(d / t) or True)
    assert seen and all(0.0 <= f <= 1.0 for f in seen) and seen == sorted(seen)
    assert max(seen) == pytest.approx(1.0) and min(f for f in seen if f > 0) < 0.5 < max(seen)


def test_edits_are_applied_as_the_node_applies_them(fields_path):
    edit = {"mode": "erase", "centre": [24.0, 12.0], "radius": 3.0}
    doc, fields, seed, node = node_run(fields_path, grow={"edits": [edit]})
    assert node.regrown and node.edits == (edit,)
    session = RDGrowthSession(fields, params_of(doc), seed)
    same_bytes(session.grow(), node)
    # the same edit as a stroke after the growth: a local regrowth of the session's value
    plain = RDGrowthSession(fields, {**params_of(doc), "edits": []}, seed)
    plain.grow()
    same_bytes(plain.regrow([edit]), node)
    with pytest.raises(NodeInputError) as err:
        plain.regrow([{"mode": "draw", "centre": [0.5, 0.5], "radius": 1.0}])   # outside rho >= iso
    assert err.value.where == "edits"


def test_refusals_are_the_node_refusals(fields_path):
    doc, fields, seed, _ = node_run(fields_path)
    p = node_type("RDGrow").param
    for name, value, where in (("directions", "third", "directions"), ("resolution", [48, 24, 4], "resolution"),
                               ("dt", 50.0, "dt")):
        params = {**params_of(doc), name: p(name).coerce(value)}
        with pytest.raises(NodeInputError) as err:
            RDGrowthSession(fields, params, seed).grow()
        assert err.value.where == where, (name, err.value)
