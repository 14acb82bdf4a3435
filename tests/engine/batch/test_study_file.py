"""Study files: a file the program did not write is never changed, studies never mix.

Tiny studies (4 x 4 blocks at 8 px, 2 samples, in this process) so the
whole module takes seconds.
"""

import csv
import io
import json
import os
import shutil
import tempfile
from functools import lru_cache
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import engine.batch.study as study_mod
from engine.batch import StudyFileError, read_params, read_rows, run_study, sweep_hints
from engine.batch.study_groups import study_hint_groups

TINY = dict(shape=(4, 4), resolution=8, periodic=True, scheduler="synchronous")
OLD = 946684800_000_000_000            # 2000-01-01, the mtime a refused file must keep


def _study(out, **kw):
    args = dict(n_samples=2, seed=1, out_path=out, **TINY)
    args.update(kw)
    return run_study("TL+-", **args)


def _freeze(p: Path):
    """Give the file a mode and mtime no run of ours would set; return its state."""
    os.chmod(p, 0o640)
    os.utime(p, ns=(OLD, OLD))
    return _state(p)


def _state(p: Path):
    st = os.stat(p)
    return p.read_bytes(), st.st_mode, st.st_mtime_ns


def _rows(path):
    return sorted(tuple((k, repr(v)) for k, v in r.items() if k != "seconds")
                  for r in read_rows(path))


@pytest.fixture
def no_growth(monkeypatch):
    """Fail the test if any sample is grown (the shared files are made first)."""
    for kind in ("ref", "other seed", "other hints", "groups"):
        _made(kind)

    def refuse(*a, **k):
        raise AssertionError("a sample was grown before the output was checked")
    monkeypatch.setattr(study_mod, "run_samples", refuse)


@lru_cache(maxsize=None)
def _made(kind: str) -> bytes:
    """Bytes of small study files, made once per session."""
    folder = Path(tempfile.mkdtemp(prefix="mesoforge-study-file-"))
    try:
        out = folder / "s.csv"
        if kind == "ref":
            _study(out)
        elif kind == "other seed":
            _study(out, seed=2)
        elif kind == "other hints":
            _study(out, hints={"T": 3, "L": 1, "+": 1, "-": 1})
        elif kind == "groups":
            study_hint_groups("TL+-", [None], samples_per_group=2, seed=1, out_path=out, **TINY)
        return out.read_bytes()
    finally:
        shutil.rmtree(folder)


def _head_len(data: bytes, lines: int) -> int:
    """Bytes in the first ``lines`` lines of ``data``."""
    at = 0
    for _ in range(lines):
        at = data.index(b"\n", at) + 1
    return at


# ------------------------------------------------------------------ the tag line

def test_the_file_names_its_study(tmp_path):
    out = tmp_path / "s.csv"
    _study(out, hints={"T": 2, "L": 1})
    first = out.read_bytes().split(b"\n", 1)[0]
    assert first.startswith(b"# mesoforge-study v1 {")
    p = read_params(out)
    assert p == json.loads(first.split(b" ", 3)[3])
    assert (p["mode"], p["tileset"], p["shape"], p["seed"], p["hints"]) == \
        ("hints", "TL+-", "4x4", 1, ["T=2.0,L=1.0"])
    assert (p["periodic"], p["E"], p["nu"], p["resolution"]) == (True, 1.0, 0.46, 8)
    assert len(read_rows(out)) == 2


# ------------------------------------------------------------------ files not ours

NOT_OURS = {
    "notes": b"a,b\n1,2\n3,4",                      # the reported data loss: a half last line
    "empty": b"",
    "one line": b"set,index,seed",
    "text": "Grüße\nline two\n".encode(),
    "binary": bytes(range(256)),
    "comment": b"# my notes\nset,index\n",
    "other tag": b"# mesoforge-study v9 {}\nx\n",
    "damaged tag": b"# mesoforge-study v1 {not json\nx\n",
}


@pytest.mark.parametrize("resume", [True, False])
@pytest.mark.parametrize("name", sorted(NOT_OURS))
def test_a_file_not_ours_is_refused_and_left_exactly_as_it_was(tmp_path, no_growth, name,
                                                               resume):
    out = tmp_path / "notes.csv"
    out.write_bytes(NOT_OURS[name])
    before = _freeze(out)
    with pytest.raises(StudyFileError) as info:
        _study(out, resume=resume)
    assert _state(out) == before
    assert str(info.value).startswith(f"out_path {str(out)!r}: ")
    assert "left as it is" in info.value.reason
    assert os.listdir(tmp_path) == ["notes.csv"]


# ------------------------------------------------------------------ another study

@pytest.mark.parametrize("change, match", [
    (dict(seed=2), "seed is 1 in the file, 2 in this run"),
    (dict(hints={"T": 2, "L": 1}), "hints is 'T=1.0,L=1.0,-=1.0,[+]=1.0' in the file, "
                                   "'T=2.0,L=1.0' in this run"),
    (dict(shape=(5, 4)), "shape is '4x4' in the file, '4x5' in this run"),
    (dict(periodic=False), "periodic is True in the file, False in this run"),
    (dict(E=2.0), "E is 1.0 in the file, 2.0 in this run"),
    (dict(nu=0.3), "nu is 0.46 in the file, 0.3 in this run"),
    (dict(resolution=10), "resolution is 8 in the file, 10 in this run"),
    (dict(void="soft"), "void is 'removed' in the file, 'soft' in this run"),
    (dict(availability=2.0), "availability is None in the file, 2.0 in this run"),
])
def test_resuming_another_study_names_the_parameter_and_both_values(tmp_path, no_growth,
                                                                    change, match):
    out = tmp_path / "s.csv"
    out.write_bytes(_made("ref"))
    before = _freeze(out)
    with pytest.raises(StudyFileError, match=match) as info:
        _study(out, **change)
    assert "holds another study" in str(info.value)
    assert _state(out) == before and os.listdir(tmp_path) == ["s.csv"]


def test_another_mode_or_tile_set_is_refused(tmp_path, no_growth):
    out = tmp_path / "s.csv"
    out.write_bytes(_made("ref"))
    before = _freeze(out)
    with pytest.raises(StudyFileError, match="mode is 'hints' in the file, 'groups' in this run"):
        study_hint_groups("TL+-", [None], samples_per_group=2, seed=1, out_path=out, **TINY)
    with pytest.raises(StudyFileError, match="mode is 'hints' in the file, 'sweep' in this run"):
        sweep_hints("TL+-", n_hint_sets=1, samples_per_set=2, seed=1, out_path=out, **TINY)
    with pytest.raises(StudyFileError, match="tileset is 'TL[+]-' in the file, 'TL[+]-OV"):
        run_study("TL+-OV\\", n_samples=2, seed=1, out_path=out, **TINY)
    assert _state(out) == before


def test_more_samples_extend_a_study_and_fewer_leave_its_rows(tmp_path):
    out = tmp_path / "s.csv"
    out.write_bytes(_made("ref"))
    s = _study(out, n_samples=3)
    assert (s["n_resumed"], s["n_new"]) == (2, 1) and len(read_rows(out)) == 3
    s = _study(out, n_samples=1)
    assert (s["n_resumed"], s["n_new"], s["n_done"]) == (1, 0, 1) and len(read_rows(out)) == 3


def test_hint_groups_go_on_with_more_groups_but_not_other_ones(tmp_path):
    out = tmp_path / "g.csv"
    a, b = {"T": 1, "L": 1}, {"T": 1, "+": 3}
    study_hint_groups("TL+-", [a], samples_per_group=1, seed=1, out_path=out, **TINY)
    s = study_hint_groups("TL+-", [a, b], samples_per_group=1, seed=1, out_path=out, **TINY)
    assert (s["n_resumed"], s["n_new"]) == (1, 1)
    assert read_params(out)["hints"] == ["T=1.0,L=1.0", "T=1.0,+=3.0"]   # the tag grew
    before = _freeze(out)
    with pytest.raises(StudyFileError, match="the hints of group 2 are 'T=1.0,[+]=3.0' in the "
                                             "file, 'T=2.0' in this run"):
        study_hint_groups("TL+-", [a, {"T": 2}], samples_per_group=1, seed=1, out_path=out,
                          **TINY)
    assert _state(out) == before
    s = study_hint_groups("TL+-", [a], samples_per_group=1, seed=1, out_path=out, **TINY)
    assert s["n_new"] == 0 and read_params(out)["hints"] == ["T=1.0,L=1.0", "T=1.0,+=3.0"]


def test_resume_false_replaces_a_study_of_ours(tmp_path):
    out = tmp_path / "s.csv"
    out.write_bytes(_made("other seed"))
    s = _study(out, resume=False)
    assert s["n_new"] == 2 and read_params(out)["seed"] == 1
    assert _rows(out) == _rows_of(_made("ref"), tmp_path)


def _rows_of(data: bytes, folder: Path):
    p = folder / "ref-copy.csv"
    p.write_bytes(data)
    try:
        return _rows(p)
    finally:
        p.unlink()


# ------------------------------------------------------------------ older files (no tag line)

def test_an_older_file_resumes_and_gets_its_tag_line(tmp_path):
    ref = _made("ref")
    legacy = ref[_head_len(ref, 1):]                   # the format before tag lines
    out = tmp_path / "old.csv"
    out.write_bytes(legacy[:_head_len(legacy, 2) + 10])   # header, one row, half a row
    s = _study(out)
    assert (s["n_resumed"], s["n_new"]) == (1, 1)
    assert out.read_bytes().startswith(b"# mesoforge-study v1 ")
    assert _rows(out) == _rows_of(ref, tmp_path)


def test_an_older_file_of_another_study_is_refused(tmp_path, no_growth):
    other = _made("other seed")
    out = tmp_path / "old.csv"
    out.write_bytes(other[_head_len(other, 1):])
    before = _freeze(out)
    with pytest.raises(StudyFileError, match="no mesoforge-study tag line .* line 2 .* is not a "
                                             "sample of this run"):
        _study(out)
    assert _state(out) == before


# ------------------------------------------------------------------ where --out points

def test_unusable_places_are_refused_before_growing_and_leave_nothing(tmp_path, no_growth):
    (tmp_path / "dir.csv").mkdir()
    (tmp_path / "file").write_bytes(b"x")
    os.mkfifo(tmp_path / "fifo.csv")
    cases = [(tmp_path / "dir.csv", "is a folder, not a file"),
             (tmp_path / "missing" / "s.csv", "the folder .*missing' does not exist"),
             (tmp_path / "file" / "s.csv", "file' is not a folder"),
             (tmp_path / "fifo.csv", "is not a regular file"),
             (Path("/proc/mesoforge-test.csv"), "cannot create files in the folder '/proc'")]
    for path, match in cases:
        with pytest.raises(StudyFileError, match=match) as info:
            _study(path)
        assert info.value.path == str(path) and info.value.param == "out_path"
    assert sorted(os.listdir(tmp_path)) == ["dir.csv", "fifo.csv", "file"]
    assert os.listdir(tmp_path / "dir.csv") == [] and (tmp_path / "file").read_bytes() == b"x"


def test_a_run_that_fails_before_its_first_row_leaves_no_file(tmp_path):
    out = tmp_path / "s.csv"
    with pytest.raises(ValueError, match="scheduler must be"):
        run_study("TL+-", n_samples=1, out_path=out, scheduler=42, shape=(4, 4), resolution=8)
    assert os.listdir(tmp_path) == []


def test_parquet_output_is_only_replaced_when_ours(tmp_path, no_growth):
    pytest.importorskip("pyarrow")
    import pyarrow as pa
    import pyarrow.parquet as pq
    out = tmp_path / "s.parquet"
    out.write_bytes(b"PAR1 not really")
    before = _freeze(out)
    with pytest.raises(StudyFileError, match="not a Parquet file written by Mesoforge"):
        _study(out, resume=False)
    assert _state(out) == before and os.listdir(tmp_path) == ["s.parquet"]
    pq.write_table(pa.table({"a": [1, 2]}), out)          # someone's Parquet file
    before = _freeze(out)
    with pytest.raises(StudyFileError, match="is a Parquet file but not a study"):
        _study(out, resume=False)
    assert _state(out) == before and os.listdir(tmp_path) == ["s.parquet"]


def test_parquet_studies_resume_and_keep_their_tag(tmp_path, monkeypatch):
    pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq
    out = tmp_path / "s.parquet"
    journal = tmp_path / "s.parquet.rows.csv"
    _study(out, n_samples=1)
    s = _study(out)
    assert (s["n_resumed"], s["n_new"]) == (1, 1) and pq.read_table(out).num_rows == 2
    meta = pq.read_schema(out).metadata[b"mesoforge-study"].decode()
    assert meta == journal.read_text().split("\n", 1)[0][2:]
    with pytest.raises(StudyFileError, match="seed is 1 in the file, 2 in this run"):
        _study(out, seed=2)
    journal.unlink()
    before = _freeze(out)
    with pytest.raises(StudyFileError, match="without its row journal"):
        _study(out)
    assert _state(out) == before and os.listdir(tmp_path) == ["s.parquet"]


# ------------------------------------------------------------------ any bytes at --out

def _csv_bytes(rows, end):
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue().encode() + end


CELLS = st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=6)
# where a file is cut: at the start of line k, plus a few bytes
CUT = st.tuples(st.integers(0, 5), st.sampled_from([0, 0, 1, 17, 150]))
JUNK = st.sampled_from([b"", b"0,1,half", b"\xff"])       # a half row, no newline
STRATEGY = {
    "bytes": st.binary(max_size=200),
    "csv": st.builds(_csv_bytes, st.lists(st.lists(CELLS, min_size=1, max_size=4), max_size=4),
                     st.sampled_from([b"", b"\n", b"x,y"])),
    "other seed": CUT, "other hints": CUT, "groups": CUT,
    "ref": st.tuples(CUT, JUNK), "ref legacy": st.tuples(CUT, JUNK),
}

def _contents(kinds):
    return st.sampled_from(kinds).flatmap(lambda k: st.tuples(st.just(k), STRATEGY[k]))


def _materialise(case) -> tuple:
    """(bytes, resumable?) for a drawn case."""
    kind, drawn = case
    if kind in ("bytes", "csv"):
        return drawn, False
    cut, junk = drawn if kind.startswith("ref") else (drawn, b"")
    data = _made("ref" if kind == "ref legacy" else kind)
    head = 2
    if kind == "ref legacy":
        data, head = data[_head_len(data, 1):], 1
    line, extra = cut
    starts = [0] + [i + 1 for i, b in enumerate(data) if b == 10]
    cut = min(starts[min(line, len(starts) - 1)] + extra, len(data))
    if kind.startswith("ref"):
        # a cut anywhere past the header, then bytes without a newline (a half row):
        # still this study's file
        return data[:cut] + junk, cut >= _head_len(data, head)
    return data[:cut], False


def _resume_or_refuse(case):
    """Run the reference study onto the drawn file: either it resumes to the
    reference rows (only a file of this study) or it is refused, unchanged."""
    data, resumable = _materialise(case)
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "s.csv"
        out.write_bytes(data)
        before = _freeze(out)
        try:
            s = _study(out)
        except StudyFileError as exc:
            event(f"{case[0]}: refused")
            assert not resumable, f"refused a resumable file: {exc}"
            assert _state(out) == before, "a refused file was changed"
        else:
            event(f"{case[0]}: resumed")
            assert resumable, "resumed a file that is not this study's"
            assert s["n_done"] == 2
            assert _rows(out) == _rows_of(_made("ref"), Path(folder))
            assert read_params(out)["seed"] == 1
            assert os.stat(out).st_mode & 0o777 == 0o640       # its mode is kept
        assert os.listdir(folder) == ["s.csv"]


SETTINGS = settings(max_examples=40, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(case=_contents(["bytes", "csv", "other seed", "other hints", "groups"]))
def test_files_of_others_at_out_are_refused_untouched(case):
    _resume_or_refuse(case)


@SETTINGS
@given(case=_contents(["ref", "ref legacy"]))
def test_cut_files_of_this_study_resume_to_its_rows_or_are_refused_untouched(case):
    _resume_or_refuse(case)
