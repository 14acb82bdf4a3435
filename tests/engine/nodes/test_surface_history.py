"""The energy history a Surface node's report carries for the Surfaces dock's chart."""

import json

import numpy as np

from engine.graph import Evaluator, SetParam, UndoStack, load_project
from engine.nodes.surfaces import HISTORY_POINTS, boundary_schematic, energy_history
from tests.resources.example_files import EXAMPLES_DIR


def _surface_report(doc, node_id):
    report = Evaluator().evaluate(doc, targets=[node_id])
    assert report.ok, report.errors
    return report.output(node_id, "report")


def test_conjugate_schwarz_p_history_ends_on_the_reported_energy():
    doc = load_project(EXAMPLES_DIR / "tpms_schwarz_p.json")
    rep = _surface_report(doc, "s_hexagon")
    assert rep.solver == "conjugate"
    h = np.asarray(rep.details["energy_history"])
    assert 2 <= h.size <= HISTORY_POINTS
    assert np.all(np.isfinite(h))
    assert h[-1] == rep.energy
    # the lowest energy found so far: never rises over the Nelder-Mead search
    assert np.all(np.diff(h[-10:]) <= 0.0)
    assert h[0] >= h[-1]
    json.loads(json.dumps(rep.summary(), allow_nan=False))


def test_direct_history_is_the_shell_energy_per_iteration():
    doc = load_project(EXAMPLES_DIR / "tpms_schwarz_p.json")
    UndoStack(doc).push(SetParam("s_hexagon", "type", "direct"))
    rep = _surface_report(doc, "s_hexagon")
    h = rep.details["energy_history"]
    assert h[-1] == rep.energy and len(h) == rep.iterations + 1


def test_energy_history_thins_evenly_and_keeps_the_ends():
    values = np.linspace(10.0, 1.0, 1001)
    values[3] = np.nan
    h = energy_history(values, 1.0, limit=50)
    assert len(h) == 50 and h[0] == 10.0 and h[-1] == 1.0
    assert np.all(np.diff(h) < 0.0)
    assert energy_history([3.0, 2.0], 1.5) == [3.0, 2.0, 1.5]     # the report's value closes it
    assert energy_history([], 1.5) == [1.5]


def test_boundary_schematic_of_the_schwarz_p_hexagon():
    doc = load_project(EXAMPLES_DIR / "tpms_schwarz_p.json")
    report = Evaluator().evaluate(doc, targets=["e_hexagon"])
    points, owners, segment_chain, smooth = boundary_schematic([report.output("e_hexagon", "chain")])
    assert points.shape == (6, 3)
    np.testing.assert_allclose(points[0], doc.nodes["v_hexagon0"].params["position"])
    assert owners == [(0, j) for j in range(6)]
    assert segment_chain.tolist() == [0] * 6 and smooth == [True]
