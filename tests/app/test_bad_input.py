"""Every bad command-line value is refused cleanly (issue #12).

Exit 2 with one line on stderr naming the flag, before any work and before
any file is written; Ctrl-C exits 130 with one line; requests too large for
the memory budget are refused before allocating.  A generated corpus runs
every subcommand's flags over their ranges (taken from the node schemas,
where the ranges live): in range, on the bounds, just outside, wrong type,
NaN / inf and huge, in-process with tiny inputs and a low memory budget.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import sys
import tempfile
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from app import cli
from engine.graph import AddNode, Connect, GraphDocument, UndoStack, node_type, save_project

from .graphs import straight_beam_graph

LIMIT = "300M"     # the memory budget of this module's runs: tiny inputs fit, big requests do not


@pytest.fixture(scope="module", autouse=True)
def low_budget():
    old = os.environ.get("MESOFORGE_MEMORY_LIMIT")
    os.environ["MESOFORGE_MEMORY_LIMIT"] = LIMIT
    yield
    if old is None:
        os.environ.pop("MESOFORGE_MEMORY_LIMIT", None)
    else:
        os.environ["MESOFORGE_MEMORY_LIMIT"] = old


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Tiny inputs: a beam graph, a phasor project, a voxel grid."""
    d = tmp_path_factory.mktemp("inputs")
    save_project(straight_beam_graph(resolution=12), d / "beam.json")
    doc = GraphDocument(seed=3)
    s = UndoStack(doc)
    s.push(AddNode("PhasorFields", {"lo": [0, 0, 0], "hi": [4, 4, 0.6], "resolution": 8,
                                    "spec": json.dumps({"D": {"kind": "spiral", "axis": "z", "angle_deg": 60}, "F": 1.0})},
                   node_id="f"))
    s.push(AddNode("PhasorNoise", {"iterations": 2}, node_id="n"))
    s.push(Connect("f", "fields", "n", "fields"))
    save_project(doc, d / "infill.json")
    grid = np.zeros((6, 6, 6))
    grid[:, 2:4, :] = 1.0
    grid[2:4, :, :] = 1.0
    np.save(d / "cell.npy", grid)
    return d


def run(argv):
    """``(code, stdout, stderr)`` of ``mesoforge argv`` run in-process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def refused(argv, flag, *needles):
    """Run ``argv``: exit 2, one stderr line naming ``flag`` (and ``needles``)."""
    code, _, err = run(argv)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, (code, err)
    assert flag in lines[0] and all(n in lines[0] for n in needles), lines[0]
    return lines[0]


# ------------------------------------------------------------------ the cases of issue #12

def test_rd_iso_out_of_the_node_range(tmp_path):
    line = refused(["rd", "--iso", 0.995, "--out", tmp_path / "a.png"], "--iso 0.995", "[0.01, 0.99]")
    assert line.startswith("mesoforge rd: --iso 0.995: ")
    assert not list(tmp_path.iterdir())


def test_rd_res_whose_default_growth_grid_is_too_big(tmp_path, monkeypatch):
    refused(["rd", "--res", "1024x1024", "--out", tmp_path / "b.png"], "--res 1024x1024", "at most")
    refused(["rd", "--res", "500x250", "--out", tmp_path / "b.png"], "--res 500x250", "needs about")
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "100G")    # the optimisation fits, the growth grid does not
    refused(["rd", "--res", "500x250", "--out", tmp_path / "b.png"], "--res 500x250",
            "growth grid 5000x2500", "[2, 4096]")
    assert not list(tmp_path.iterdir())


def test_eval_tile_too_large_is_refused_before_allocating(inputs, tmp_path, monkeypatch):
    import app.evaluation

    # refused from the parameters alone: not even the cell is evaluated
    monkeypatch.setattr(app.evaluation, "evaluate_document",
                        lambda *a, **k: pytest.fail("evaluated before refusing"))
    refused(["eval", inputs / "beam.json", "--tile", 20, 20, 20, "--out", tmp_path / "x.stl"],
            "--tile 20 20 20", "needs about", "MESOFORGE_MEMORY_LIMIT")
    assert not list(tmp_path.iterdir())
    refused(["eval", inputs / "beam.json", "--tile", 21, 1, 1], "--tile 21 1 1", "[1, 20]")


def test_render_tile_out_of_range_and_png_without_suffix(inputs, tmp_path):
    refused(["render", inputs / "beam.json", "--png", tmp_path / "a.png", "--tile", 100, 100, 100],
            "--tile 100 100 100", "[1, 20]")
    refused(["render", inputs / "beam.json", "--png", tmp_path / "noext"], "--png", "no extension", ".png")
    refused(["render", inputs / "beam.json", "--png", tmp_path / "a.png", "--out", tmp_path / "a.png"], "--out")
    assert not list(tmp_path.iterdir())


def test_grow_checks_every_output_before_writing_any(tmp_path):
    refused(["grow", "TL+-", "--size", "4x4", "--out", tmp_path / "t.json", "--png", tmp_path / "x.jpgx"],
            "--png", ".jpgx")
    refused(["grow", "TL+-", "--size", "4x4", "--out", tmp_path / "nodir" / "t.json"], "--out", "does not exist")
    assert not list(tmp_path.iterdir())


def test_eval_empty_out_is_refused(inputs):
    refused(["eval", inputs / "beam.json", "--out", ""], "--out ''", "empty path")


def test_ctrl_c_exits_130_with_one_line(inputs, monkeypatch, tmp_path):
    import app.evaluation

    def interrupted(*_a, **_k):
        raise KeyboardInterrupt
    monkeypatch.setattr(app.evaluation, "evaluate_document", interrupted)
    for argv in (["eval", inputs / "beam.json", "--out", tmp_path / "x.stl"],
                 ["render", inputs / "beam.json", "--png", tmp_path / "x.png"]):
        code, _, err = run(argv)
        assert code == 130 and err.strip() == f"mesoforge {argv[0]}: interrupted"
    assert not list(tmp_path.iterdir())


def test_homogenize_huge_grid_refused_from_the_header(tmp_path):
    path = tmp_path / "huge.npy"
    np.lib.format.open_memmap(path, mode="w+", dtype=np.uint8, shape=(1000, 1000, 1000))  # sparse on disk
    tracemalloc.start()
    try:
        refused(["homogenize", path], "INPUT", "1000^3", "needs about")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 50e6, peak          # the 1 GB grid was never read: the header decided


def test_homogenize_material_ranges_are_the_voxel_nodes(inputs):
    nu = node_type("Voxel").param("nu")
    refused(["homogenize", inputs / "cell.npy", "--nu", 0.5], "--nu 0.5", f"{nu.maximum:g}")
    refused(["homogenize", inputs / "cell.npy", "--E", "nan"], "--E nan", "finite")
    refused(["homogenize", inputs / "missing.npy"], "INPUT", "no such file")


def test_phasor_pixel_range_and_memory(inputs, tmp_path):
    project = inputs / "infill.json"
    refused(["phasor", project, "--slice", "z=0.3", "--png", tmp_path / "a.png", "--px", 1e-6],
            "--px 1e-06", "[0.001, 10]")
    refused(["phasor", project, "--slice", "z=0.3", "--png", tmp_path / "a.png", "--px", 0.001],
            "--px 0.001", "needs about")
    refused(["phasor", project, "--gcode", tmp_path / "a.gcode", "--layer", 1e-6], "--layer 1e-06",
            "needs about")
    refused(["phasor", project, "--gcode", tmp_path / "a.txt"], "--gcode", ".gcode")
    assert not list(tmp_path.iterdir())


def test_grow_and_study_size_memory(tmp_path, monkeypatch):
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "50M")
    refused(["grow", "TL+-", "--size", "1000x1000", "--out", tmp_path / "t.json"], "--size 1000x1000",
            "needs about")
    refused(["study", "TL+-", "--size", "1000x1000", "--scheduler", "synchronous"], "--size 1000x1000",
            "needs about")
    assert not list(tmp_path.iterdir())


def test_bare_project_refused_before_writing(inputs, tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.chdir(tmp_path)
    code, _, err = run([tmp_path / "missing.json"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "missing.json" in err
    doc = straight_beam_graph(resolution=12)
    UndoStack(doc).push(__import__("engine.graph", fromlist=["SetParam"]).SetParam("obj1", "resolution", 512))
    save_project(doc, tmp_path / "big.json")
    code, _, err = run([tmp_path / "big.json"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "needs about" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.json"]      # no mesoforge-out


def test_argparse_errors_are_one_line(inputs):
    refused(["eval", inputs / "beam.json", "--tile", "a", 1, 1], "--tile", "invalid int value")
    refused(["rd", "--preset", "nope", "--out", "x.png"], "--preset", "invalid choice")
    code, _, err = run(["grow", "TL+-"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--size" in err


def test_a_malformed_budget_is_refused(monkeypatch):
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "lots")
    refused(["eval", "x.json"], "MESOFORGE_MEMORY_LIMIT")


# ------------------------------------------------------------------ the generated corpus

def _range(type_name, param):
    p = node_type(type_name).param(param)
    return p.minimum, p.maximum, p.kind


def _numbers(lo, hi, kind):
    """Texts of values for a flag of range [lo, hi]: inside, bounds, just outside,
    wrong type, NaN / inf, huge."""
    integer = kind in ("int", "int_list")
    inside = st.integers(int(lo), int(min(hi, lo + 50))) if integer else st.floats(lo, hi)
    step = 1 if integer else max(abs(lo), abs(hi), 1.0) * 1e-6
    edges = [lo, hi, lo - step, hi + step]
    odd = ["abc", "nan", "inf", "-inf", "1e300", "10" * 12, ""] + ([] if integer else ["1e-300"])
    return st.one_of(inside.map(str), st.sampled_from([str(int(v)) if integer else repr(float(v)) for v in edges]),
                     st.sampled_from(odd))


def _sizes(lo, hi, dims):
    n = st.sampled_from([int(lo), int(lo) + 1, 3, int(hi), int(hi) + 1, int(lo) - 1, 0])
    return st.one_of(st.lists(n, min_size=dims, max_size=dims).map(lambda v: "x".join(map(str, v))),
                     st.sampled_from(["4by4", "4x", "x", "", "1e3x4", "-3x4", "4x4x4x4"]))


def _check(argv, outdir: Path):
    code, _, err = run(argv)
    assert code in (0, 1, 2), (argv, code, err)
    if os.environ.get("CORPUS_TRACE"):
        print("CORPUS", code, argv[0], " ".join(map(str, argv[2:]))[-80:], file=sys.__stdout__)
    assert "Traceback" not in err
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1, (argv, err)
        flag = next((a for a in argv if isinstance(a, str) and a.startswith("--") and a in lines[0]), None)
        assert flag is not None or "INPUT" in lines[0] or "TILESET" in lines[0], (argv, lines[0])
        assert not list(outdir.iterdir()), (argv, list(outdir.iterdir()))
    return code


CORPUS = settings(max_examples=40, deadline=None, derandomize=True, database=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


def _outdir(root) -> Path:
    return Path(tempfile.mkdtemp(dir=root))


@CORPUS
@given(data=st.data())
def test_corpus_eval_and_render(inputs, tmp_path, data):
    lo, hi, kind = _range("Object", "resolution")
    flag = data.draw(st.sampled_from(["--resolution", "--tile", "--out", "--node"]))
    out = _outdir(tmp_path)
    if flag == "--resolution":
        value = [data.draw(_numbers(lo, min(hi, 24), kind))]
    elif flag == "--tile":
        value = data.draw(st.lists(st.sampled_from(["1", "2", "20", "21", "0", "-1", "x", "1e9"]),
                                   min_size=3, max_size=3))
    elif flag == "--out":
        value = [str(out / data.draw(st.sampled_from(["a.stl", "a.obj", "a.xyz", "noext", "d/a.stl"])))]
    else:
        value = [data.draw(st.sampled_from(["obj1", "nope", ""]))]
    cmd = data.draw(st.sampled_from(["eval", "render"]))
    argv = [cmd, str(inputs / "beam.json"), flag, *value]
    if cmd == "render":
        if flag in ("--node", "--resolution"):
            argv = argv[:2]
        argv += ["--png", str(out / "r.png")]
    _check(argv, out)


@CORPUS
@given(data=st.data())
def test_corpus_homogenize(inputs, tmp_path, data):
    flag = data.draw(st.sampled_from(["--E", "--nu", "--res"]))
    if flag == "--res":
        value = data.draw(st.sampled_from(["6", "2", "1", "0", "5000", "x", "nan"]))
    else:
        value = data.draw(_numbers(*_range("Voxel", flag[2:])))
    _check(["homogenize", str(inputs / "cell.npy"), flag, value], _outdir(tmp_path))


@CORPUS
@given(data=st.data())
def test_corpus_grow(tmp_path, data):
    out = _outdir(tmp_path)
    flag = data.draw(st.sampled_from(["--size", "--availability", "--seed", "--png", "--out"]))
    args = {"--size": "4x4", "--out": str(out / "t.json")}
    lo, hi, _ = _range("Grow", "size")
    if flag == "--size":
        args[flag] = data.draw(_sizes(lo, hi, 2))
    elif flag == "--availability":
        args[flag] = data.draw(_numbers(*_range("Grow", "availability")))
    elif flag == "--seed":
        args[flag] = data.draw(st.sampled_from(["0", "7", "-1", "x", "1e3", str(2**70)]))
    else:
        args[flag] = str(out / data.draw(st.sampled_from(["a.png", "a.jpgx", "noext", "t.json", "d/a.png"])))
    argv = ["grow", "TL+-"] + [v for kv in args.items() for v in kv]
    os.environ["MESOFORGE_MEMORY_LIMIT"] = "20M"     # a valid big grid is refused by its estimate
    try:
        _check(argv, out)
    finally:
        os.environ["MESOFORGE_MEMORY_LIMIT"] = LIMIT


@CORPUS
@given(data=st.data())
def test_corpus_study_arguments(tmp_path, data):
    out = _outdir(tmp_path)
    flag = data.draw(st.sampled_from(["--n", "--E", "--nu", "--resolution", "--size", "--sweep",
                                      "--min-distance", "--workers", "--out"]))
    args = {"--n": "1", "--size": "3x3", "--resolution": "4", "--scheduler": "synchronous"}
    if flag in ("--E", "--nu", "--resolution"):
        args[flag] = data.draw(_numbers(*_range("TilingProperties", flag[2:])))
        if flag == "--resolution" and args[flag] in ("0", "1", "2", "3", "4", "5"):
            args[flag] = "4"      # in range: keep the valid run tiny
    elif flag == "--size":
        args[flag] = data.draw(_sizes(1, 1000, 2))
        if args[flag] not in ("1x1", "2x2", "3x3", "1x2", "2x1", "3x2", "2x3"):
            args["--n"] = "0"     # only refusals: a valid study of a big grid is not tiny
    elif flag == "--out":
        args[flag] = str(out / data.draw(st.sampled_from(["s.csv", "s.txt", "", "d/s.csv"])))
    else:
        args[flag] = data.draw(st.sampled_from(["0", "-1", "nan", "inf", "x", "1e300"]))
    argv = ["study", "TL+-"] + [v for kv in args.items() for v in kv]
    _check(argv, out)


@CORPUS
@given(data=st.data())
def test_corpus_phasor(inputs, tmp_path, data):
    out = _outdir(tmp_path)
    flag = data.draw(st.sampled_from(["--px", "--slice", "--png", "--layer", "--nozzle", "--perimeters"]))
    base = ["phasor", str(inputs / "infill.json")]
    if flag == "--px":
        lo, hi, kind = _range("PhasorSlice", "pixel")
        argv = base + ["--slice", "z=0.3", "--json", "--engine", "numpy", "--px",
                       data.draw(_numbers(0.05, hi, kind) | st.sampled_from([repr(lo), "1e-4", "0"]))]
    elif flag == "--slice":
        argv = base + ["--json", "--engine", "numpy", "--slice",
                       data.draw(st.sampled_from(["z=0.3", "z=0", "q=1", "z=nan", "z=1e300", "z", ""]))]
    elif flag == "--png":
        argv = base + ["--slice", "z=0.3", "--engine", "numpy", "--png",
                       str(out / data.draw(st.sampled_from(["a.png", "a.jpg", "noext", "d/a.png"])))]
    else:
        argv = base + ["--printability", "--engine", "numpy", "--px", "0.1", flag,
                       data.draw(st.sampled_from(["0.2", "0", "-1", "nan", "inf", "x", "5", "1e300"]))]
    _check(argv, out)


@settings(max_examples=20, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_corpus_rd(tmp_path, data):
    out = _outdir(tmp_path)
    flags = {"--iso": ("RDCompile", "iso"), "--gamma": ("RDGrow", "gamma"), "--max-iter": ("TopOpt", "max_iter"),
             "--max-steps": ("RDGrow", "max_steps")}
    flag = data.draw(st.sampled_from(sorted(flags) + ["--res", "--grow-res", "--out", "--seed"]))
    args = {"--res": "8x4", "--grow-res": "16x8", "--max-iter": "2", "--max-steps": "20", "--gamma": "4",
            "--out": str(out / "a.png")}
    if flag in flags:
        lo, hi, kind = _range(*flags[flag])
        value = data.draw(_numbers(lo, hi, kind))
        if kind == "int" and value.isdigit() and int(value) > 50:
            value = "50" if int(value) <= hi else value     # valid runs stay short
        args[flag] = value
    elif flag in ("--res", "--grow-res"):
        lo, hi, _ = _range("TopOpt" if flag == "--res" else "RDGrow", "resolution")
        value = data.draw(_sizes(lo, hi, 2))
        parts = value.split("x")
        if all(p.isdigit() for p in parts) and len(parts) == 2 and all(2 <= int(p) <= hi for p in parts):
            value = "x".join(str(min(int(p), 16)) for p in parts)     # in range: keep it tiny
        args[flag] = value
    elif flag == "--out":
        args[flag] = str(out / data.draw(st.sampled_from(["a.png", "a.stl", "a.jpg", "", "d/a.png"])))
    else:
        args[flag] = data.draw(st.sampled_from(["0", "-1", "x", "nan"]))
    argv = ["rd"] + [v for kv in args.items() for v in kv]
    _check(argv, out)
