"""`mesoforge grow` / `study` and the window give the same bytes: both evaluate
the growth nodes' graph (TileSet → Grow → ...) through the Evaluator.

The window's document is built here as the window builds it (undo commands,
ids chosen by the document), evaluated by a fresh Evaluator and written with
the kernel's writers; the command's files must be byte-identical.
"""

import io

import numpy as np
import pytest

from app import cli
from engine.batch import format_hints, read_study, sample_seed
from engine.batch.blas_threads import blas_threads
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, UndoStack
from engine.growth import save_tiling


def _window_doc(seed, grow_params, *, image=False, properties=None, tileset=None):
    doc = GraphDocument(seed=seed)
    undo = UndoStack(doc)
    ts = undo.push(AddNode("TileSet", dict(tileset or {}), (0, 0))).node_id
    grow = undo.push(AddNode("Grow", dict(grow_params), (240, 0))).node_id
    undo.push(Connect(ts, "tileset", grow, "tileset"))
    ids = {"grow": grow}
    if image:
        ids["image"] = undo.push(AddNode("TilingImage", {}, (480, 0))).node_id
        undo.push(Connect(grow, "tiling", ids["image"], "tiling"))
    if properties is not None:
        ids["props"] = undo.push(AddNode("TilingProperties", dict(properties), (480, 120))).node_id
        undo.push(Connect(grow, "tiling", ids["props"], "tiling"))
    with blas_threads(1):      # as a study worker solves (one BLAS thread: the same last bits)
        report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    return report, ids


def _png(values):
    from PIL import Image
    buf = io.BytesIO()
    Image.fromarray(np.where(values > 0, 0, 255).astype(np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


@pytest.mark.parametrize("seed, flags, params", [
    (0, ["--size", "8x8"], {"size": [8, 8]}),
    (7, ["--size", "12x9", "--hints", "T=1,L=1,+=2,-=1"], {"size": [12, 9], "hints": "T=1,L=1,+=2,-=1"}),
    (3, ["--size", "6x5", "--no-periodic", "--availability", "1"],
     {"size": [6, 5], "periodic": False, "availability": 1.0}),
    (2, ["--size", "5x5", "--tiling-seed", "12345"], {"size": [5, 5], "seed": 12345}),
])
def test_grow_bytes_equal_the_window_graph(tmp_path, capsys, seed, flags, params):
    out, png = tmp_path / "t.json", tmp_path / "t.png"
    code = cli.main(["grow", "TL+-", *flags, "--seed", str(seed), "--out", str(out), "--png", str(png)])
    assert code == 0, capsys.readouterr().err
    report, ids = _window_doc(seed, params, image=True)
    tv = report.outputs[ids["grow"]]["tiling"]
    ref = tmp_path / "ref.json"
    save_tiling(ref, tv.tiling, tv.tileset)
    assert out.read_bytes() == ref.read_bytes()
    assert png.read_bytes() == _png(report.outputs[ids["image"]]["image"].values)


def test_grow_3d_bytes_equal_the_window_graph(tmp_path, capsys):
    out = tmp_path / "c.json"
    assert cli.main(["grow", "cubic-beams", "--size", "3x3x2", "--seed", "5", "--out", str(out)]) == 0
    report, ids = _window_doc(5, {"size": [3, 3, 2]}, tileset={"name": "cubic-beams"})
    tv = report.outputs[ids["grow"]]["tiling"]
    ref = tmp_path / "ref.json"
    save_tiling(ref, tv.tiling, tv.tileset)
    assert out.read_bytes() == ref.read_bytes()


def test_study_rows_equal_graph_evaluations_with_the_seed_param(tmp_path, capsys):
    out = tmp_path / "s.csv"
    hints = "T=2,L=1,+=1,-=1"
    code = cli.main(["study", "TL+-", "--n", "3", "--size", "5x5", "--resolution", "10",
                     "--scheduler", "synchronous", "--seed", "3", "--hints", hints, "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    rows = read_study(out)
    assert len(rows) == 3
    text = format_hints({"T": 2.0, "L": 1.0, "+": 1.0, "-": 1.0})
    for r in rows:
        assert r["seed"] == sample_seed(3, r["index"])        # the seed column is the tiling seed
        # any document seed: the explicit seed parameter decides the tiling
        report, ids = _window_doc(99, {"size": [5, 5], "hints": text, "seed": r["seed"]},
                                  properties={"resolution": 10})
        tv = report.outputs[ids["grow"]]["tiling"]
        st = report.outputs[ids["props"]]["stiffness"]
        assert tv.tiling.seed == r["seed"] and r["n_defects"] == tv.tiling.n_defects
        C = np.asarray(st.C)
        for i in range(3):
            for j in range(i, 3):
                assert r[f"C{i + 1}{j + 1}"] == float(C[i, j])
        assert r["density"] == float(st.density) and r["iterations"] == st.iterations
