"""`mesoforge study` for the window: hint groups, sweeps, progress lines, SIGTERM, study_argv,
and --out files that must not be written."""

import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from app import cli
from engine.batch.study_process import parse_progress_line, study_argv, study_process
import engine.batch.study as study_mod
from engine.batch import read_study, run_study, sample_seed, sweep_hints

ROOT = Path(__file__).resolve().parents[2]
SMALL = ["--size", "5x5", "--resolution", "10", "--scheduler", "synchronous"]


def _run(capsys, *args):
    code = cli.main([*map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_hint_groups_go_to_one_file_with_progress_lines(tmp_path, capsys):
    out = tmp_path / "g.csv"
    code, stdout, err = _run(capsys, "study", "TL+-", "--n", 2, *SMALL, "--seed", 4,
                             "--group", "T=1,L=1,+=1,-=1", "--group", "T=3,L=1,+=1,-=1",
                             "--out", out, "--progress-lines", "--json")
    assert code == 0, err
    progress = [parse_progress_line(line) for line in err.splitlines()]
    assert progress == [(d, 4) for d in range(5)]
    s = json.loads(stdout)
    assert s["n_groups"] == 2 and s["n_done"] == 4 and [x["set"] for x in s["sets"]] == [0, 1]
    rows = read_study(out)
    assert [(r["set"], r["index"], r["seed"]) for r in rows] == \
        [(j, i, sample_seed(4, j, i)) for j in (0, 1) for i in (0, 1)]
    assert rows[2]["hint_T"] == pytest.approx(0.5)
    # text output of the resumed run lists each set
    code, stdout, err = _run(capsys, "study", "TL+-", "--n", 2, *SMALL, "--seed", 4,
                             "--group", "T=1,L=1,+=1,-=1", "--group", "T=3,L=1,+=1,-=1",
                             "--out", out)
    assert code == 0, err
    assert "4/4 samples" in stdout and "set 1: E_avg/E_s" in stdout and err == ""


def test_sweep_matches_the_engine_sweep(tmp_path, capsys):
    out, ref = tmp_path / "s.csv", tmp_path / "ref.csv"
    code, stdout, err = _run(capsys, "study", "TL+-", "--n", 1, *SMALL, "--seed", 2,
                             "--sweep", 3, "--min-distance", 0.1, "--out", out, "--json")
    assert code == 0, err
    sweep_hints("TL+-", n_hint_sets=3, samples_per_set=1, min_distance=0.1, seed=2,
                out_path=ref, scheduler="synchronous", shape=(5, 5), resolution=10)
    strip = lambda rows: [{k: repr(v) for k, v in r.items() if k != "seconds"} for r in rows]
    assert strip(read_study(out)) == strip(read_study(ref))
    assert json.loads(stdout)["n_hint_sets"] == 3


@pytest.mark.parametrize("args, match", [
    (["--hints", "T=1", "--group", "T=1"], "--hints and --group: give only one of"),
    (["--group", "T=1", "--sweep", "2"], "--group and --sweep"),
    (["--group", "T=1", "--group", "T=1,Q=2"], "--group 2 'T=1,Q=2': hints entry 2 'Q=2'"),
    (["--sweep", "0"], "--sweep 0: expected a number of hint vectors >= 1"),
    (["--sweep", "2", "--min-distance", "-1"], "--min-distance -1.0"),
    (["--sweep", "5", "--min-distance", "1.5"], "min_distance"),
])
def test_bad_study_modes_exit_2_naming_them(capsys, args, match):
    code, _out, err = _run(capsys, "study", "TL+-", "--n", 1, *SMALL, *args)
    assert code == 2 and match in err and err.startswith("mesoforge study: ")


def _stop_after_two_rows(command, signum):
    """Run a study with --progress-lines, send `signum` once two rows are done;
    (exit code, the rest of stderr)."""
    proc = subprocess.Popen(command, cwd=ROOT, stderr=subprocess.PIPE, text=True)
    try:
        for line in proc.stderr:
            p = parse_progress_line(line)
            if p is not None and p[0] >= 2:
                proc.send_signal(signum)
                break
        rest = proc.stderr.read()
        return proc.wait(timeout=30), rest
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_sigterm_stops_with_whole_rows_and_a_rerun_resumes(tmp_path):
    out = tmp_path / "t.csv"
    argv = ["study", "TL+-", "--n", "60", "--size", "8x8", "--resolution", "10",
            "--scheduler", "synchronous", "--group", "T=1", "--out", str(out), "--progress-lines"]
    program, args = study_process(argv)
    code, rest = _stop_after_two_rows([program, *args], signal.SIGTERM)
    assert code == 130, rest
    assert "stopped; rows so far are in" in rest
    kept = read_study(out)
    assert 2 <= len(kept) < 60 and out.read_bytes().endswith(b"\n")
    r = subprocess.run([program, *args[:-1], "--json"], cwd=ROOT, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["n_resumed"] == len(kept)
    rows = read_study(out)
    assert [row["index"] for row in rows] == list(range(60))


def test_sigint_leaves_whole_rows_and_a_rerun_resumes(tmp_path):
    out = tmp_path / "i.csv"
    args = ["-m", "app.cli", "study", "TL+-", "--n", "40", "--size", "6x6", "--resolution", "8",
            "--scheduler", "synchronous", "--out", str(out)]
    code, rest = _stop_after_two_rows([sys.executable, *args, "--progress-lines"], signal.SIGINT)  # Ctrl-C
    assert code == 130 and "interrupted; rows so far are in" in rest, rest
    kept = read_study(out)
    assert 2 <= len(kept) < 40 and out.read_bytes().endswith(b"\n")
    args[args.index("--n") + 1] = str(len(kept) + 1)     # a rerun resumes, one more sample
    r = subprocess.run([sys.executable, *args, "--json"], cwd=ROOT, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert (s["n_resumed"], s["n_new"]) == (len(kept), 1)


def _state(p):
    st = os.stat(p)
    return p.read_bytes(), st.st_mode, st.st_mtime_ns


def _bad_out_cases(tmp_path):
    notes = tmp_path / "notes.csv"
    notes.write_bytes(b"a,b\n1,2\n3,4")
    other = tmp_path / "other.csv"
    run_study("TL+-", n_samples=1, seed=9, shape=(5, 5), resolution=10, out_path=other,
              scheduler="synchronous")
    (tmp_path / "dir.csv").mkdir()
    # the reason as the engine words it; the CLI may refuse a folder or a missing folder
    # itself, before the engine sees the path, so those two are matched loosely
    return [(notes, r"is not a study file written by Mesoforge \(its first line is 'a,b'\)"),
            (other, "holds another study: seed is 9 in the file, 0 in this run"),
            (tmp_path / "dir.csv", "is a (folder|directory)"),
            (tmp_path / "no" / "s.csv", f"{re.escape(repr(str(tmp_path / 'no')))} does not exist"),
            (Path("/proc/mesoforge-x.csv"), "cannot create files in the folder '/proc'")]


def test_unusable_out_files_exit_2_before_any_sample_and_stay_untouched(tmp_path, capsys,
                                                                        monkeypatch):
    cases = _bad_out_cases(tmp_path)
    before = {p: _state(p) for p, _ in cases if p.is_file()}
    listing = sorted(os.listdir(tmp_path))

    def grown(*a, **k):
        raise AssertionError("a sample was grown before --out was checked")
    monkeypatch.setattr(study_mod, "run_samples", grown)
    for path, reason in cases:
        code, _out, err = _run(capsys, "study", "TL+-", "--n", 2, *SMALL, "--out", path)
        assert code == 2, err
        assert err.count("\n") == 1 and err.startswith("mesoforge study: ")
        assert re.search(f"{re.escape(str(path))}'?: .*{reason}", err), err
    assert {p: _state(p) for p in before} == before
    assert sorted(os.listdir(tmp_path)) == listing and os.listdir(tmp_path / "dir.csv") == []


def test_unusable_out_files_are_reported_as_out(tmp_path, capsys):
    notes = tmp_path / "notes.csv"
    notes.write_bytes(b"a,b\n1,2\n")
    code, _out, err = _run(capsys, "study", "TL+-", "--n", 1, *SMALL, "--out", notes)
    assert code == 2 and re.match(f"mesoforge study: --out '?{re.escape(str(notes))}'?: is not a "
                                  f"study file", err), err


def test_study_argv_is_what_the_parser_reads(tmp_path):
    out = str(tmp_path / "db.csv")
    argv = study_argv("TL+-", n=3, size="6x6", groups=["T=1,L=1", ""],
                      out=out, seed=7, workers=1, resolution=10, resume=False)
    assert argv[:2] == ["study", "TL+-"] and argv[-2:] == ["--progress-lines", "--json"]
    a = cli.build_parser().parse_args(argv)
    assert (a.n, a.size, a.seed, a.workers, a.resolution, a.out) == (3, "6x6", 7, 1, 10, out)
    assert a.group == ["T=1,L=1", ""] and a.no_resume and not a.bounded and a.scheduler is None
    b = cli.build_parser().parse_args(study_argv("TL+-", n=2, size="4x4", sweep=5,
                                                 min_distance=0.05, periodic=False,
                                                 scheduler="tcp://h:8786", void="soft"))
    assert (b.sweep, b.min_distance, b.bounded, b.scheduler, b.void) == \
        (5, 0.05, True, "tcp://h:8786", "soft")
    assert not b.no_resume and b.out is None and b.group is None
    program, args = study_process(argv)
    assert program == sys.executable and args[:2] == ["-m", "app.cli"] and args[2:] == argv


@pytest.mark.parametrize("kwargs, match", [
    (dict(groups=["T=1", "T=1,X=2"]), "hint group 2 'T=1,X=2': hints entry 2 'X=2'"),
    (dict(groups=[]), "no hint groups"),
    (dict(groups=["T=1"], sweep=3), "not both"),
    (dict(sweep=4, min_distance=2.0), "--sweep 4 --min-distance 2.0"),
    (dict(groups=["T=1"], size="4x"), "--size '4x'"),
    (dict(groups=["T=1"], n=0), "--n 0"),
    (dict(groups=["T=1"], seed=2**64), "--seed 18446744073709551616: expected an integer in [0, 18446744073709551615]"),
    (dict(groups=["T=1"], resolution=1), "--resolution 1: expected 0 (the default"),
    (dict(groups=["T=1"], workers=0), "--workers 0: expected"),
    (dict(groups=["T=1"], out="x.txt"), "--out 'x.txt'"),
    (dict(groups=["T=1"], void="air"), "--void 'air'"),
])
def test_study_argv_refuses_bad_values_by_name(kwargs, match):
    args = dict(n=2, size="4x4")
    args.update(kwargs)
    with pytest.raises(ValueError) as info:
        study_argv("TL+-", **args)
    assert match in str(info.value)


def test_parse_progress_line():
    assert parse_progress_line("progress 3 10\n") == (3, 10)
    for bad in ("progress 3", "progress -1 4", "progress a b", "study: 3/10", ""):
        assert parse_progress_line(bad) is None


def test_module_entry_runs_the_cli():
    r = subprocess.run([sys.executable, "-m", "app.cli", "study", "--help"], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and "--progress-lines" in r.stdout and "--group" in r.stdout
