"""`mesoforge grow` and `mesoforge study`."""

import json

import numpy as np
import pytest

from app import cli
from engine.batch import read_study
from engine.graph.node import node_seed
from engine.growth import grow_tiling, load_tileset, load_tiling, tiling_image


def _run(capsys, *args):
    code = cli.main([*map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_grow_writes_the_tiling_and_its_image(tmp_path, capsys):
    from PIL import Image
    out, png = tmp_path / "t.json", tmp_path / "t.png"
    code, stdout, err = _run(capsys, "grow", "TL+-", "--size", "12x9", "--periodic", "--seed", 7,
                             "--out", out, "--png", png, "--hints", "T=1,L=1,+=2,-=1", "--json")
    assert code == 0, err
    info = json.loads(stdout)
    ts = load_tileset("TL+-")
    # --seed is the document seed: the Grow node (id grow1) derives the tiling seed from it
    seed = node_seed(7, "grow1")
    ref = grow_tiling(ts, (9, 12), periodic=True, rng=seed,
                      hints={"T": 1, "L": 1, "+": 2, "-": 1})
    til = load_tiling(out)
    assert np.array_equal(til.tiles, ref.tiles) and til.periodic and til.seed == seed
    assert info["seed"] == 7 and info["tiling_seed"] == seed
    assert info["n_defects"] == ref.n_defects and info["shape"] == [9, 12]
    assert sum(info["realised_probabilities"].values()) == pytest.approx(1.0)
    img = np.asarray(Image.open(png))
    assert np.array_equal(img == 0, tiling_image(ref, ts) == 1)        # black = solid
    assert info["seconds"] >= 0 and info["png"].endswith("t.png")


def test_grow_3d_and_text_output(tmp_path, capsys):
    code, stdout, err = _run(capsys, "grow", "cubic-beams", "--size", "3x3x2", "--out",
                             tmp_path / "c.json", "--availability", 1.5)
    assert code == 0, err
    assert "defects" in stdout and load_tiling(tmp_path / "c.json").shape == (2, 3, 3)


def test_grow_defaults_are_the_node_defaults_and_tiling_seed_is_used_as_is(tmp_path, capsys):
    """Periodic is on unless --no-periodic (the node's default); --tiling-seed
    sets the Grow node's seed parameter, the tiling seed used as is."""
    ts = load_tileset("TL+-")
    code, stdout, err = _run(capsys, "grow", "TL+-", "--size", "5x4", "--tiling-seed", 7,
                             "--out", tmp_path / "a.json", "--json")
    assert code == 0, err
    til = load_tiling(tmp_path / "a.json")
    assert til.periodic and til.seed == 7
    assert np.array_equal(til.tiles, grow_tiling(ts, (4, 5), periodic=True, rng=7).tiles)
    code, stdout, err = _run(capsys, "grow", "TL+-", "--size", "5x4", "--no-periodic",
                             "--out", tmp_path / "b.json", "--json")
    assert code == 0, err
    assert not load_tiling(tmp_path / "b.json").periodic and not json.loads(stdout)["periodic"]


def test_grow_help_shows_the_schema(capsys):
    try:
        assert cli.main(["grow", "--help"]) in (0, None)
    except SystemExit as exc:
        assert exc.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "allowed: integers in [1, 1000]" in text and "blocks" in text
    assert "allowed: a finite number in [0, 1e+06]" in text and "--no-periodic" in text


@pytest.mark.parametrize("args, match", [
    (["grow", "nope", "--size", "4x4"], "TILESET 'nope'"),
    (["grow", "TL+-", "--size", "0x4"], "--size 0x4: out of range (allowed: integers in [1, 1000])"),
    (["grow", "TL+-", "--size", "4x4x4"], "--size 4x4x4: the tile set is 2D"),
    (["grow", "TL+-", "--size", "4by4"], "--size 4by4"),
    (["grow", "TL+-", "--size", "2000x1000"], "--size 2000x1000: out of range"),
    (["grow", "TL+-", "--size", "1000x999x2"], "--size 1000x999x2: the tile set is 2D"),
    (["grow", "TL+-", "--size", "4x4", "--tiling-seed", "-2"], "--tiling-seed -2: out of range"),
    (["grow", "TL+-", "--size", "4x4", "--hints", "T=1,X=2"], "--hints: hints entry 2 'X=2'"),
    (["grow", "TL+-", "--size", "4x4", "--availability", "-1"], "--availability -1"),
    (["grow", "cubic-beams", "--size", "2x2x2", "--png", "x.png"], "--png"),
    (["study", "TL+-", "--n", "0"], "--n 0"),
    (["study", "TL+-", "--hints", "T=x"], "weight 'x' is not a number"),
    (["study", "TL+-", "--size", "3x0"], "--size 3x0"),
    (["study", "TL+-", "--nu", "0.5"], "--nu 0.5: out of range (allowed: a finite number in [-0.999, 0.499])"),
    (["study", "TL+-", "--size", "3x3", "--n", "1", "--out", "s.txt",
      "--scheduler", "synchronous"], "--out s.txt: unsupported extension '.txt' (allowed: a file "
                                      "ending in .csv, .parquet)"),
])
def test_bad_input_exits_2_naming_it(tmp_path, capsys, args, match):
    if args[0] == "grow" and "--out" not in args:
        args = args + ["--out", str(tmp_path / "t.json")]
    code, out, err = _run(capsys, *args)
    assert code == 2
    assert match in err and err.startswith(f"mesoforge {args[0]}: ")


def test_study_summary_matches_its_rows(tmp_path, capsys):
    out = tmp_path / "s.csv"
    code, stdout, err = _run(capsys, "study", "TL+-", "--n", 6, "--size", "6x6",
                             "--resolution", 10, "--out", out, "--scheduler", "synchronous",
                             "--seed", 3, "--hints", "T=2,L=1,+=1,-=1", "--json")
    assert code == 0, err
    s = json.loads(stdout)
    rows = read_study(out)
    ok = [r for r in rows if r["status"] == "ok"]
    assert s["n_done"] == len(rows) == 6 and s["size"] == "6x6"
    e = np.array([r["E_avg"] for r in ok])
    nu = np.array([r["nu_avg"] for r in ok])
    assert s["E_avg"]["mean"] == pytest.approx(e.mean()) and s["E_avg"]["std"] == pytest.approx(e.std(ddof=1))
    assert s["nu_avg"]["mean"] == pytest.approx(nu.mean())
    assert s["hints"] == pytest.approx({"T": 0.4, "L": 0.2, "+": 0.2, "-": 0.2})
    for b in "TL+-":
        assert s["realised_probabilities"][b] == pytest.approx(np.mean([r[f"p_{b}"] for r in rows]))
    # text output of a resumed run: nothing new to compute
    code, stdout, err = _run(capsys, "study", "TL+-", "--n", 6, "--size", "6x6",
                             "--resolution", 10, "--out", out, "--scheduler", "synchronous",
                             "--seed", 3, "--hints", "T=2,L=1,+=1,-=1")
    assert code == 0, err
    assert "6/6 samples" in stdout and "E_avg/E_s =" in stdout and "realised probabilities" in stdout
