"""`mesoforge reconstruct` and `engine.nodes.sdf_fit.NodeFit`: a node's parameters recovered
from an exemplar the `sdf` command wrote; refusals before any work."""

import json

import numpy as np
import pytest

from app import cli
from engine.graph import AddNode, GraphDocument, UndoStack, load_project
from engine.graph.project import save_project
from engine.implicit.exemplar import Exemplar
from engine.nodes.sdf_fit import NodeFit, parse_bounds


def _project(path, **params):
    doc = GraphDocument()
    UndoStack(doc).push(AddNode("PeriodicFunction", {"kind": "gyroid", "level_by": "level", **params},
                                node_id="g"))
    save_project(doc, path)
    return path


def _cli(capsys, *args):
    code = cli.main([*map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_the_cell_and_level_written_by_sdf_are_recovered_and_saved_to_a_copy(tmp_path, capsys):
    truth = _project(tmp_path / "truth.json", cell=0.31, level=0.2)
    guess = _project(tmp_path / "guess.json", cell=0.4, level=0.1)
    before = guess.read_bytes()
    code, out, err = _cli(capsys, "sdf", truth, "--voxels", 24, "--out", tmp_path / "ex.npy", "--json")
    assert code == 0, err
    code, out, err = _cli(capsys, "reconstruct", guess, "--node", "g", "--exemplar", tmp_path / "ex.npy",
                          "--fit", "cell=0.2:0.6", "--fit", "level=-0.5:0.5", "--algorithm", "cmaes",
                          "--max-evaluations", 800, "--loss", "mse", "--out", tmp_path / "fitted.json", "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["params"]["cell"] == pytest.approx(0.31, rel=0.01)
    assert info["params"]["level"] == pytest.approx(0.2, abs=0.01)
    assert info["start"] == {"cell": 0.4, "level": 0.1} and info["evaluations"] <= 800
    assert guess.read_bytes() == before                               # the input is never written
    fitted = load_project(tmp_path / "fitted.json").nodes["g"].params
    assert fitted["cell"] == pytest.approx(info["params"]["cell"])


def test_node_fit_defaults_to_the_nonzero_active_float_parameters_and_skips_refused_candidates():
    fit = NodeFit("Particles", {"cell": 1.0, "distribution": "fixed", "size_a": 0.3, "size_b": 0.0,
                                "shape": "sphere", "jitter": 0.0, "orient": False, "density": 1.0,
                                "graded": False, "density_end": 0.0, "grade_axis": "z", "grade_from": 0.0,
                                "grade_to": 10.0, "offset": 0.0, "warp_amplitude": 0.0,
                                "warp_frequency": 0.0, "seed": 1})
    assert fit.names == ("cell", "size_a", "density")           # not grade_to: the ramp is off
    assert fit.bounds["size_a"] == pytest.approx((0.15, 0.45))
    refused = fit._candidate([0.5, 0.45, 1.0])                  # size 0.45 in a 0.5 mm cell
    assert np.all(np.isnan(refused.distance(np.zeros((3, 3)))))
    # a lattice of spheres recovered from its own samples by MSE
    truth = fit.sdf([1.0, 0.3, 1.0])
    ex = Exemplar.from_sdf(truth, centre=(1.0, 1.0, 1.0), size=2.0, resolution=16)
    only = NodeFit("Particles", fit.params, bounds={"size_a": (0.1, 0.45)})
    result = only.fit(ex, algorithm="powell", max_evaluations=200, loss="mse")
    assert result.params[0] == pytest.approx(0.3, abs=1e-3)


def test_a_default_fit_varies_only_what_takes_effect():
    base = {"kind": "gyroid", "cell": 2.0, "level_by": "volume fraction", "volume_fraction": 0.3,
            "graded": False}
    assert NodeFit("PeriodicFunction", base).names == ("cell", "volume_fraction")
    graded = NodeFit("PeriodicFunction", {**base, "graded": True, "grade_to": 4.0})
    assert graded.names == ("cell", "volume_fraction", "volume_fraction_end", "grade_to")
    by_level = NodeFit("PeriodicFunction", {**base, "level_by": "level", "level": 0.4})
    assert by_level.names == ("cell", "level")
    warped = {"cell": 1.0, "distribution": "fixed", "size_a": 0.3, "warp_amplitude": 0.05, "warp_frequency": 3.0}
    assert NodeFit("Particles", warped).names == ("cell", "size_a", "jitter", "density", "warp_amplitude",
                                                  "warp_frequency")
    assert "warp_gain" in NodeFit("Particles", {**warped, "warp_octaves": 3}).names


@pytest.mark.parametrize("text", ["cell", "cell=1", "cell=2:1", "=1:2", "cell=a:b"])
def test_bounds_text_is_checked(text):
    with pytest.raises(ValueError, match="NAME=LO:HI"):
        parse_bounds(text)


@pytest.mark.parametrize("args, message", [
    (["--node", "nope"], "no such node"),
    (["--node", "g", "--fit", "cell=2:1"], "--fit"),
    (["--node", "g", "--fit", "kind=0:1"], "not a float parameter"),
    (["--node", "g", "--budget", "0"], "--budget"),
    (["--node", "g", "--algorithm", "genetic"], "--algorithm"),
    (["--node", "g", "--out", "@GRAPH"], "is the input project"),
])
def test_bad_input_is_refused_before_any_work(tmp_path, capsys, args, message):
    graph = _project(tmp_path / "g.json", cell=0.3, level=0.0)
    np.save(tmp_path / "ex.npy", np.linspace(-1, 1, 6 ** 3).reshape(6, 6, 6))
    args = [str(graph) if a == "@GRAPH" else a for a in args]
    code, out, err = _cli(capsys, "reconstruct", graph, "--exemplar", tmp_path / "ex.npy", *args)
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_an_exemplar_of_the_wrong_shape_is_refused(tmp_path, capsys):
    graph = _project(tmp_path / "g.json", cell=0.3, level=0.0)
    np.save(tmp_path / "flat.npy", np.zeros((8, 8)))
    code, out, err = _cli(capsys, "reconstruct", graph, "--node", "g", "--exemplar", tmp_path / "flat.npy")
    assert code == 2 and "--exemplar" in err


def test_an_image_exemplar_is_fitted_by_rendering_at_the_same_view(tmp_path, capsys):
    truth = _project(tmp_path / "truth.json", cell=0.31, level=0.1)
    guess = _project(tmp_path / "guess.json", cell=0.4, level=0.1)
    png = tmp_path / "target.png"
    code, out, err = _cli(capsys, "sdf", truth, "--render", png, "--size", "48x48", "--step", "fixed", "--json")
    assert code == 0, err
    camera = json.loads(out)["camera"]
    code, out, err = _cli(capsys, "reconstruct", guess, "--node", "g", "--exemplar", png, "--fit", "cell=0.2:0.6",
                          "--algorithm", "powell", "--max-evaluations", 80, "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["exemplar"] == "image" and info["camera"] == camera      # the sdf command's framing
    assert info["params"]["cell"] == pytest.approx(0.31, rel=0.02)
