"""Studies: resumable row files, determinism across schedulers, the paper's trends."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from engine.batch import StudyFileError, read_study, run_study, sample_seed, sweep_hints
from engine.batch.rows import read_rows
from engine.growth import dirichlet_hints

ROOT = Path(__file__).resolve().parents[3]
SMALL = dict(shape=(6, 6), resolution=10, periodic=True)


def _lines_without_seconds(path):
    """Data rows as comparable tuples, the timing cell left out."""
    rows = read_rows(path)
    return sorted(tuple((k, repr(v)) for k, v in r.items() if k != "seconds") for r in rows)


def test_sample_seeds_are_seedsequence_children():
    kids = np.random.SeedSequence(123).spawn(5)
    for i, kid in enumerate(kids):
        assert sample_seed(123, i) == int(kid.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))
    assert sample_seed(123, 0, 1) != sample_seed(123, 1, 0)


def test_rows_and_summary(tmp_path):
    out = tmp_path / "s.csv"
    s = run_study("TL+-", n_samples=5, seed=3, out_path=out, scheduler="synchronous", **SMALL)
    rows = read_study(out)
    assert [r["index"] for r in rows] == list(range(5))
    assert [r["seed"] for r in rows] == [sample_seed(3, i) for i in range(5)]
    assert s["n_done"] == 5 and s["n_new"] == 5 and not s["cancelled"] and "rows" not in s
    ok = [r for r in rows if r["status"] == "ok"]
    e = np.array([r["E_avg"] for r in ok])
    assert s["E_avg"]["mean"] == pytest.approx(e.mean()) and s["E_avg"]["n"] == len(ok)
    assert s["E_avg"]["std"] == pytest.approx(e.std(ddof=1))
    for r in rows:
        assert r["hints"] == "T=1.0,L=1.0,-=1.0,+=1.0" and r["hint_T"] == 0.25
        assert sum(r[f"p_{b}"] for b in "TL-+") == pytest.approx(1.0)
        # eq. 2 and 5 from the stored C (independent of the constants code)
        C = np.array([[r["C11"], r["C12"], r["C13"]], [r["C12"], r["C22"], r["C23"]],
                      [r["C13"], r["C23"], r["C33"]]])
        S = np.linalg.inv(C)
        assert r["E_avg"] == pytest.approx((1 / S[0, 0] + 1 / S[1, 1]) / 2, rel=1e-9)
        assert r["nu_avg"] == pytest.approx((-S[1, 0] / S[0, 0] - S[0, 1] / S[1, 1]) / 2,
                                            rel=1e-9, abs=1e-12)
        assert r["shape"] == "6x6" and r["periodic"] is True and r["member"] == 2.0
    mem = run_study("TL+-", n_samples=5, seed=3, scheduler="synchronous", **SMALL)
    assert [r["C11"] for r in mem["rows"]] == [r["C11"] for r in rows]


def test_cancel_then_resume_equals_an_uninterrupted_run(tmp_path):
    ref = tmp_path / "ref.csv"
    run_study("TL+-", n_samples=7, seed=11, out_path=ref, scheduler="synchronous", **SMALL)
    part = tmp_path / "part.csv"
    s = run_study("TL+-", n_samples=7, seed=11, out_path=part, scheduler="synchronous",
                  progress=lambda done, total: done < 3, **SMALL)
    assert s["cancelled"] and s["n_done"] == 3 and len(read_rows(part)) == 3
    # a run killed while writing its next row leaves half a line behind
    with open(part, "ab") as f:
        f.write(ref.read_bytes().splitlines(keepends=True)[5][:40])
    s = run_study("TL+-", n_samples=7, seed=11, out_path=part, scheduler="synchronous", **SMALL)
    assert s["n_resumed"] == 3 and s["n_new"] == 4 and s["n_done"] == 7
    assert _lines_without_seconds(part) == _lines_without_seconds(ref)
    seeds = [r["seed"] for r in read_rows(part)]
    assert len(seeds) == len(set(seeds)) == 7
    # nothing left to do: resuming again runs nothing
    s = run_study("TL+-", n_samples=7, seed=11, out_path=part, scheduler="synchronous", **SMALL)
    assert s["n_new"] == 0 and s["n_resumed"] == 7


def test_killed_process_resumes_to_the_same_rows(tmp_path):
    ref = tmp_path / "ref.csv"
    run_study("TL+-", n_samples=8, seed=5, out_path=ref, scheduler="synchronous", **SMALL)
    out = tmp_path / "killed.csv"
    script = textwrap.dedent(f"""
        import time
        from engine.batch import run_study
        run_study("TL+-", n_samples=8, seed=5, out_path={str(out)!r}, scheduler="synchronous",
                  shape=(6, 6), resolution=10, periodic=True,
                  progress=lambda d, t: time.sleep(0.05) or True)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], cwd=ROOT)
    try:
        deadline = time.time() + 120
        while time.time() < deadline:
            if out.exists() and out.read_bytes().count(b"\n") >= 4:   # tag, header + 2 rows
                break
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    written = read_rows(out)
    assert 2 <= len(written) < 8, "the run should have been killed midway"
    s = run_study("TL+-", n_samples=8, seed=5, out_path=out, scheduler="synchronous", **SMALL)
    assert s["n_done"] == 8 and s["n_resumed"] == len(written)
    assert _lines_without_seconds(out) == _lines_without_seconds(ref)


def test_local_cluster_and_synchronous_rows_are_identical(tmp_path):
    a, b = tmp_path / "cluster.csv", tmp_path / "sync.csv"
    run_study("TL+-", n_samples=6, seed=2, out_path=a, scheduler=None, **SMALL)
    run_study("TL+-", n_samples=6, seed=2, out_path=b, scheduler="synchronous", **SMALL)
    assert _lines_without_seconds(a) == _lines_without_seconds(b)


def test_cancel_on_a_cluster_keeps_whole_rows_and_resumes(tmp_path, dask_client):
    ref = tmp_path / "ref.csv"
    run_study("TL+-", n_samples=10, seed=8, out_path=ref, scheduler=dask_client, **SMALL)
    part = tmp_path / "part.csv"
    s = run_study("TL+-", n_samples=10, seed=8, out_path=part, scheduler=dask_client,
                  progress=lambda done, total: done < 2, **SMALL)
    assert s["cancelled"] and 2 <= s["n_done"] < 10
    assert len(read_rows(part)) == s["n_done"]
    s = run_study("TL+-", n_samples=10, seed=8, out_path=part, scheduler=dask_client, **SMALL)
    assert s["n_done"] == 10
    assert _lines_without_seconds(part) == _lines_without_seconds(ref)


def test_resume_refuses_rows_of_a_different_study(tmp_path):
    out = tmp_path / "s.csv"
    run_study("TL+-", n_samples=2, seed=1, out_path=out, scheduler="synchronous", **SMALL)
    before = out.read_bytes()
    with pytest.raises(StudyFileError, match="hints is 'T=1.0,L=1.0,-=1.0,[+]=1.0' in the file, "
                                             "'T=2.0,L=1.0,[+]=1.0,-=1.0' in this run"):
        run_study("TL+-", hints={"T": 2, "L": 1, "+": 1, "-": 1}, n_samples=2, seed=1,
                  out_path=out, scheduler="synchronous", **SMALL)
    with pytest.raises(StudyFileError, match="tileset is 'TL[+]-' in the file"):
        run_study("TL+-OV\\", n_samples=2, seed=1, out_path=out, scheduler="synchronous",
                  **SMALL)
    assert out.read_bytes() == before


@pytest.mark.parametrize("kwargs, match", [
    ({"n_samples": 0}, "n_samples must be an integer >= 1"),
    ({"shape": (0, 5)}, "shape must be 2 integers >= 1"),
    ({"shape": (5, 5, 5)}, "shape must be 2 integers"),
    ({"hints": {"Q": 1}}, "hints key 'Q'"),
    ({"out_path": "x.txt"}, r"must end in \.csv or \.parquet"),
    ({"scheduler": 42}, "scheduler must be"),
    ({"nu": 0.5}, r"nu must be a number in \(-1.0, 0.5\)"),
    ({"void": "air"}, "void must be one of"),
    ({"seed": -1}, "seed must be an integer >= 0"),
])
def test_bad_input_is_refused_by_name(kwargs, match):
    args = dict(n_samples=2, scheduler="synchronous", **SMALL)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        run_study("TL+-", **args)
    with pytest.raises(ValueError, match="neither a file nor a known set"):
        run_study("no-such-set", n_samples=1)


def test_parquet_needs_pyarrow(tmp_path):
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        with pytest.raises(ValueError, match="needs pyarrow"):
            run_study("TL+-", n_samples=1, out_path=tmp_path / "s.parquet", **SMALL)
    else:
        run_study("TL+-", n_samples=2, out_path=tmp_path / "s.parquet",
                  scheduler="synchronous", **SMALL)
        import pyarrow.parquet as pq
        assert pq.read_table(tmp_path / "s.parquet").num_rows == 2


def test_sweep_hints_database(tmp_path):
    out = tmp_path / "db.csv"
    s = sweep_hints("TL+-", n_hint_sets=3, samples_per_set=2, min_distance=0.2, seed=4,
                    out_path=out, scheduler="synchronous", shape=(5, 5), resolution=10)
    expect = dirichlet_hints(4, 3, min_distance=0.2, rng=4)
    rows = read_study(out)
    assert len(rows) == 6 and s["n_done"] == 6 and len(s["sets"]) == 3
    for r in rows:
        w = np.array([r[f"hint_{b}"] for b in ("T", "L", "-", "+")])
        np.testing.assert_allclose(w, expect[r["set"]], rtol=1e-12)
        assert r["seed"] == sample_seed(4, r["set"], r["index"])
    d = np.linalg.norm(expect[:, None] - expect[None], axis=-1)[np.triu_indices(3, 1)]
    assert d.min() > 0.2
    assert {r["status"] for r in rows} <= {"ok", "singular"}
    for st in s["sets"]:
        e = [r["E_avg"] for r in rows if r["set"] == st["set"] and r["status"] == "ok"]
        assert st["E_avg"]["n"] == len(e)
        if e:
            assert st["E_avg"]["mean"] == pytest.approx(np.mean(e))
        else:                           # every sample of the set was a mechanism
            assert np.isnan(st["E_avg"]["mean"])
    again = sweep_hints("TL+-", n_hint_sets=3, samples_per_set=2, min_distance=0.2, seed=4,
                        out_path=out, scheduler="synchronous", shape=(5, 5), resolution=10)
    assert again["n_new"] == 0 and again["n_resumed"] == 6


def _groups(client, n, shape, resolution, seed=0):
    hints = {"base": {"T": 1, "L": 1, "-": 1, "+": 1},
             "more T": {"T": 4, "L": 1, "-": 1, "+": 1},
             "more +": {"T": 1, "L": 1, "-": 1, "+": 4}}
    out = {}
    for k, (name, h) in enumerate(hints.items()):
        s = run_study("TL+-", hints=h, n_samples=n, shape=shape, resolution=resolution,
                      seed=seed + k, scheduler=client)
        ok = [r for r in s["rows"] if r["status"] == "ok"]
        assert len(ok) >= 0.9 * n
        out[name] = {"E": np.array([r["E_avg"] for r in ok]),
                     "nu": np.array([r["nu_avg"] for r in ok]),
                     "p": s["realised_probabilities"]}
    return out


def _check_fig3b_trends(g):
    # more "T" lowers nu_avg (towards auxetic); more "+" raises E_avg (Fig. 3B).
    # One-sided Welch t-tests at p < 1e-3, so a lucky draw cannot pass them.
    assert g["more T"]["p"]["T"] > g["base"]["p"]["T"] + 0.15
    assert g["more +"]["p"]["+"] > g["base"]["p"]["+"] + 0.15
    t_nu = stats.ttest_ind(g["more T"]["nu"], g["base"]["nu"], equal_var=False,
                           alternative="less")
    t_e = stats.ttest_ind(g["more +"]["E"], g["base"]["E"], equal_var=False,
                          alternative="greater")
    assert t_nu.pvalue < 1e-3, t_nu
    assert t_e.pvalue < 1e-3, t_e


def test_fig3b_trends_on_small_sves(dask_client):
    # 30 samples per group of 10 x 10 blocks at 10 px: the trends are already
    # significant at p < 1e-3 and the test takes seconds.
    _check_fig3b_trends(_groups(dask_client, 30, (10, 10), 10))


@pytest.mark.slow
def test_fig3b_trends_paper_size(dask_client):
    # the paper's setting: 100 samples of 20 x 20 blocks at 20 px per block
    _check_fig3b_trends(_groups(dask_client, 100, (20, 20), 20))
