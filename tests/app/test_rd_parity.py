"""`mesoforge rd` and the RD nodes give the same bytes.

The document is built as the window builds one (AddNode / Connect on the
undo stack, the node defaults for every parameter the flags leave alone)
and evaluated by the Evaluator; its RDCompile field written as the command
writes it must be the command's PNG, byte for byte.  The RD dock's live
growth (the node's RDGrowthSession, run in pieces) must grow the same
structures as the node.
"""

from __future__ import annotations

import contextlib
import io

import numpy as np

from app import cli
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, UndoStack
from engine.graph.node import node_seed

SEED = 3
TOPOPT = {"preset": "cantilever", "resolution": [16, 8], "max_iter": 6}
GROW = {"resolution": [48, 24], "gamma": 4.0, "max_steps": 400}
COMPILE = {"iso": 0.6}


def window_document():
    """TopOpt -> RDFields -> RDGrow -> RDCompile as a user adds them (ids chosen by the document)."""
    doc = GraphDocument(seed=SEED)
    undo = UndoStack(doc)
    ids = [undo.push(AddNode(t, dict(p))).node_id
           for t, p in (("TopOpt", TOPOPT), ("RDFields", {}), ("RDGrow", GROW), ("RDCompile", COMPILE))]
    for (a, out), (b, inp) in zip(zip(ids, ("design", "rdfields", "structures")),
                                  zip(ids[1:], ("design", "rdfields", "structures"))):
        undo.push(Connect(a, out, b, inp))
    return doc, ids


def test_the_command_writes_the_bytes_of_the_nodes(tmp_path):
    from engine.rd.compile import LEVEL, save_structure_png

    out = tmp_path / "cli.png"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(["rd", "--preset", "cantilever", "--res", "16x8", "--max-iter", "6", "--grow-res", "48x24",
                         "--gamma", "4", "--max-steps", "400", "--iso", "0.6", "--seed", str(SEED),
                         "--out", str(out)])
    assert code == 0, err.getvalue()

    doc, ids = window_document()
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    node_png = tmp_path / "node.png"
    save_structure_png(node_png, report.output(ids[3], "field").values, level=LEVEL)
    assert out.read_bytes() == node_png.read_bytes()


def test_the_docks_live_growth_is_the_nodes_growth():
    from engine.nodes.rd_session import RDGrowthSession

    doc, ids = window_document()
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    grow = doc.nodes[ids[2]]
    session = RDGrowthSession(report.output(ids[1]), dict(grow.params), node_seed(doc.seed, grow.id))
    while not session.advance(70):            # the dock's rounds of "every" steps
        pass
    node = report.output(ids[2])
    live = session.apply()
    assert live.s.tobytes() == node.s.tobytes() and live.steps == node.steps
    assert all(np.array_equal(a.u, b.u) and np.array_equal(a.v, b.v) for a, b in zip(live.states, node.states))
