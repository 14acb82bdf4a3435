"""`mesoforge phasor`: slice PNG, singularity energies and G-code of a project's infill."""

import json

import numpy as np
import pytest

from app import cli, phasor_cmd
from engine.fab import read_gcode_paths
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, UndoStack, save_project
from engine.phasor.infill import infill_slice

SPEC = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 60}, "F": 1.0}


def _project(path, *, noise_nodes=1, spec=None):
    doc = GraphDocument(seed=3)
    st = UndoStack(doc)
    st.push(AddNode("PhasorFields", {"lo": [0, 0, 0], "hi": [8, 8, 1], "resolution": 16,
                                     "spec": spec if spec is not None else json.dumps(SPEC)}, node_id="f"))
    for k in range(noise_nodes):
        st.push(AddNode("PhasorNoise", {}, node_id=f"n{k + 1}"))
        st.push(Connect("f", "fields", f"n{k + 1}", "fields"))
    save_project(doc, path)
    return doc


@pytest.fixture
def project(tmp_path):
    path = tmp_path / "infill.json"
    return path, _project(path)


def _run(capsys, *args):
    code = cli.main(["phasor", *map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_png_is_the_diamond_slice(project, tmp_path, capsys):
    from PIL import Image
    path, doc = project
    png = tmp_path / "s.png"
    code, out, err = _run(capsys, path, "--slice", "z=0.5", "--png", png, "--px", 0.1, "--engine", "numpy")
    assert code == 0, err
    assert "wrote" in out and "diamonds" in out
    infill = Evaluator().evaluate(doc).output("n1")
    ref = infill_slice(infill, "z", 0.5, 0.1, engine="numpy").diamonds
    img = np.asarray(Image.open(png))
    assert img.shape == (80, 80)
    assert np.array_equal(img[::-1] == 0, ref)                 # black = diamond, y up


def test_json_energies_fall_with_alignment(project, capsys):
    path, _ = project
    code, out, err = _run(capsys, path, "--slice", "z=0.5", "--json")
    assert code == 0, err
    info = json.loads(out)
    e = info["energy"]
    assert set(e) == {"raw", "aligned", "aligned+filtered"} and info["node"] == "n1"
    assert e["aligned"]["F_S"] < e["raw"]["F_S"]
    assert all(v["pixels"] == 78 * 78 for v in e.values()) and info["q"] == 2.0


def test_gcode_parses_with_one_path_set_per_layer(project, tmp_path, capsys):
    path, _ = project
    gcode = tmp_path / "p.gcode"
    code, out, err = _run(capsys, path, "--gcode", gcode, "--layer", 0.25, "--nozzle", 0.4, "--json")
    assert code == 0, err
    info = json.loads(out)["gcode"]
    assert info["layers"] == 4 and "layer 4/4" in err
    layers = read_gcode_paths(gcode, offset=(100.0, 100.0))
    assert [round(layer.z, 3) for layer in layers] == [0.25, 0.5, 0.75, 1.0]
    assert all(layer.paths for layer in layers)
    pts = np.concatenate([p for layer in layers for p in layer.paths])
    assert pts.min() >= -1e-6 and pts.max() <= 8 + 1e-6


def test_ctrl_c_leaves_no_gcode(project, tmp_path, capsys, monkeypatch):
    path, _ = project
    gcode = tmp_path / "p.gcode"

    def interrupting(stream):
        def cb(done, total):
            if done >= 2:
                raise KeyboardInterrupt
            return True
        return cb

    monkeypatch.setattr(phasor_cmd, "_gcode_progress", interrupting)
    code, out, err = _run(capsys, path, "--gcode", gcode)
    assert code == 130 and "interrupted" in err and "not written" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["infill.json"]


def test_the_noise_node_is_found_or_named(tmp_path, capsys):
    path = tmp_path / "two.json"
    _project(path, noise_nodes=2)
    code, _, err = _run(capsys, path, "--slice", "z=0.5", "--json")
    assert code == 2 and "2 PhasorNoise nodes (n1, n2)" in err and "--node" in err
    code, out, err = _run(capsys, path, "--slice", "z=0.5", "--json", "--node", "n2")
    assert code == 0, err
    assert json.loads(out)["node"] == "n2"
    code, _, err = _run(capsys, path, "--slice", "z=0.5", "--json", "--node", "f")
    assert code == 2 and "PhasorFields node, not PhasorNoise" in err


@pytest.mark.parametrize("args, match", [
    (["--slice", "q=1", "--json"], "--slice 'q=1'"),
    (["--slice", "z=abc", "--json"], "--slice 'z=abc'"),
    (["--slice", "z=5", "--json"], "lies outside the part's box"),
    (["--slice", "z=0.5", "--json", "--px", "0.5"], "--px 0.5: pixel 0.5 mm is too coarse"),
    (["--png", "x.png"], "--png needs --slice"),
    ([], "nothing to do"),
    (["--gcode", "x.gcode", "--layer", "0.6"], "--layer 0.6: layer_height"),
    (["--gcode", "x.gcode", "--px", "0.25"], "below half the nozzle"),
    (["--printability", "--px", "0.25"], "below half the nozzle"),
    (["--printability", "--nozzle", "-1"], "--nozzle -1.0: nozzle_diameter"),
])
def test_bad_arguments_exit_2_naming_them(project, capsys, args, match):
    path, _ = project
    code, _, err = _run(capsys, path, *args)
    assert code == 2 and match in err, err
    assert len(err.strip().splitlines()) == 1


def test_missing_project_and_failing_node(tmp_path, capsys):
    code, _, err = _run(capsys, tmp_path / "none.json", "--slice", "z=0.5", "--json")
    assert code == 2 and "no such file" in err
    bad = tmp_path / "bad.json"
    _project(bad, spec=json.dumps({"F": -1.0}))
    code, _, err = _run(capsys, bad, "--slice", "z=0.5", "--json")
    assert code == 1 and "F.value" in err and "[spec]" in err


# ------------------------------------------------------------------ printability (paper 5.1)

def _reference_report(layers):
    from engine.fab import printability
    return printability(layers, nozzle_diameter=0.4)


def _check_printability(info, report):
    p = info["printability"]
    assert set(p) >= {"layers", "pieces", "bin_edges", "overhang", "overlap", "min_support", "max_overlap"}
    assert p["min_support"] == 0.4 and p["max_overlap"] == 0.1 and p["layers"] == 4
    assert p["pieces"] == len(report.segment_length)
    assert np.allclose(p["bin_edges"], report.bin_edges)
    for kind in ("overhang", "overlap"):
        assert set(p[kind]) >= {"segments", "length", "counts"}
        assert p[kind]["counts"] == getattr(report, f"{kind}_histogram").tolist()
        lengths = getattr(report, f"{kind}_segments")
        assert p[kind]["segments"] == len(lengths) == sum(p[kind]["counts"])
        assert p[kind]["length"] == pytest.approx(lengths.sum())


def test_printability_json_counts_the_toolpaths_violations(project, capsys):
    from engine.fab import PrintSettings, layer_stack_toolpaths
    from engine.phasor.infill import print_layers

    path, doc = project
    code, out, err = _run(capsys, path, "--printability", "--layer", 0.25, "--engine", "numpy", "--json")
    assert code == 0, err
    info = json.loads(out)
    assert "gcode" not in info and "slice" not in info
    infill = Evaluator().evaluate(doc).output("n1")
    settings = PrintSettings(layer_height=0.25)
    layers = list(layer_stack_toolpaths(print_layers(infill, layer_height=0.25, pixel=0.1, engine="numpy"),
                                        settings=settings))
    report = _reference_report(layers)
    assert report.overhang_count > 0 and report.overlap_count > 0     # something to count
    _check_printability(info, report)


def test_printability_with_gcode_measures_the_written_file(project, tmp_path, capsys):
    path, _ = project
    gcode = tmp_path / "p.gcode"
    code, out, err = _run(capsys, path, "--gcode", gcode, "--printability", "--layer", 0.25, "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["gcode"]["layers"] == 4
    _check_printability(info, _reference_report(read_gcode_paths(gcode, offset=(100.0, 100.0))))


def test_printability_text_is_a_table(project, capsys):
    path, _ = project
    code, out, err = _run(capsys, path, "--printability", "--layer", 0.25, "--engine", "numpy")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("printability of 4 layers")
    oh = int(lines[1].split("overhang:")[1].split()[0])
    ov = int(lines[2].split("overlap:")[1].split()[0])
    assert "segment length (mm)" in lines[3]
    rows = [line.split() for line in lines[4:]]
    assert all(r[1] == ".." for r in rows)
    assert sum(int(r[3]) for r in rows) == oh and sum(int(r[4]) for r in rows) == ov


def test_memory_is_checked_before_the_fields_are_evaluated(project, tmp_path, capsys, monkeypatch):
    from engine.nodes.phasor import PhasorFieldsNode

    path, _ = project
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "1M")
    monkeypatch.setattr(PhasorFieldsNode, "evaluate", lambda *a, **k: pytest.fail("evaluated before refusing"))
    code, _, err = _run(capsys, path, "--slice", "z=0.5", "--png", tmp_path / "a.png", "--px", 0.002)
    assert code == 2 and "--px 0.002" in err and "needs about" in err
    code, _, err = _run(capsys, path, "--gcode", tmp_path / "a.gcode", "--layer", 1e-4)
    assert code == 2 and "--layer 0.0001" in err and "needs about" in err
    assert not (tmp_path / "a.png").exists() and not (tmp_path / "a.gcode").exists()
