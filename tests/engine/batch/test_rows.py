"""Row files: complete rows only, partial last lines cut on resume, nothing else touched."""

import math
import os

import pytest

from engine.batch.rows import (RowFile, StudyFileError, format_row, parse_cell, read_rows,
                               scan_rows)

COLS = ["seed", "name", "x", "flag", "note"]


def _state(p):
    st = os.stat(p)
    return p.read_bytes(), st.st_mode, st.st_mtime_ns


def test_rows_round_trip_exactly(tmp_path):
    p = tmp_path / "r.csv"
    rows = [{"seed": 2 ** 62 + 1, "name": "T=1.0,L=2.0", "x": 0.1 + 0.2, "flag": True,
             "note": "two\nlines"},
            {"seed": 3, "name": "+", "x": math.nan, "flag": False, "note": None}]
    with RowFile.open(p, COLS, resume=False) as f:
        for r in rows:
            f.append(r)
    back = read_rows(p, columns=COLS)
    assert back[0]["seed"] == 2 ** 62 + 1 and back[0]["x"] == 0.1 + 0.2   # repr round-trips
    assert back[0]["name"] == "T=1.0,L=2.0" and back[0]["flag"] is True
    assert back[0]["note"] == "two lines"                               # a newline never splits a row
    assert math.isnan(back[1]["x"]) and back[1]["note"] is None and back[1]["flag"] is False
    assert p.read_bytes().count(b"\n") == 3


def test_resume_cuts_a_partial_last_line_and_keeps_complete_rows(tmp_path):
    p = tmp_path / "r.csv"
    with RowFile.open(p, COLS, resume=False, tag="test v1 {}") as f:
        f.append({"seed": 1, "name": "a", "x": 1.5, "flag": True})
        f.append({"seed": 2, "name": "b", "x": 2.5, "flag": True})
    full = p.read_bytes()
    assert full.startswith(b"# test v1 {}\nseed,name,x,flag,note\n")
    p.write_bytes(full[:-7])                     # killed while writing row 2
    with RowFile.open(p, COLS, resume=True) as f:
        assert [r["seed"] for r in f.existing] == [1]
        f.append({"seed": 2, "name": "b", "x": 2.5, "flag": True})
    assert p.read_bytes() == full
    assert scan_rows(p).tag == "test v1 {}"


def test_a_new_tag_rewrites_the_file_whole_keeping_rows_and_mode(tmp_path):
    p = tmp_path / "r.csv"
    with RowFile.open(p, COLS, resume=False) as f:
        f.append({"seed": 1, "name": "a"})
    os.chmod(p, 0o640)
    p.write_bytes(p.read_bytes() + b"2,half")
    with RowFile.open(p, COLS, resume=True, tag="t v1 [1]") as f:
        assert [r["seed"] for r in f.existing] == [1]
    assert p.read_bytes() == b"# t v1 [1]\n" + format_row(COLS) + format_row([1, "a"] + [None] * 3)
    assert os.stat(p).st_mode & 0o777 == 0o640
    assert sorted(x.name for x in tmp_path.iterdir()) == ["r.csv"]     # no temporary left


def test_a_partial_header_or_other_columns_are_refused_untouched(tmp_path):
    p = tmp_path / "r.csv"
    p.write_bytes(b"seed,na")
    before = _state(p)
    with pytest.raises(StudyFileError, match="no complete header line"):
        RowFile.open(p, COLS, resume=True)
    assert _state(p) == before
    with RowFile.open(p, COLS, resume=False) as f:     # resume=False: the caller said replace
        f.append({"seed": 1})
    p.write_bytes(p.read_bytes() + b"2,half a r")       # a partial last line...
    before = _state(p)
    with pytest.raises(StudyFileError, match="different kind of study"):
        RowFile.open(p, COLS + ["extra"], resume=True)
    assert _state(p) == before                          # ...is not cut off before refusing
    p.write_bytes(p.read_bytes() + b"ow\n1,2\n")
    before = _state(p)
    with pytest.raises(StudyFileError, match="line 3: 2 cells, expected 5"):
        RowFile.open(p, COLS, resume=True)
    assert _state(p) == before
    with pytest.raises(ValueError, match="not in the file header"):
        with RowFile.open(p, COLS, resume=False) as f:
            f.append({"bogus": 1})


@pytest.mark.parametrize("data, match", [
    (b"\xff\xfe\x00a,b\n", "line 1 is not UTF-8"),
    (b'a,"b\n', "not CSV"),
])
def test_bytes_that_are_not_csv_are_refused(tmp_path, data, match):
    p = tmp_path / "r.csv"
    p.write_bytes(data)
    with pytest.raises(StudyFileError, match=match):
        RowFile.open(p, COLS, resume=True)
    assert p.read_bytes() == data


def test_create_never_clobbers_and_needs_its_folder(tmp_path):
    p = tmp_path / "r.csv"
    p.write_bytes(b"mine\n")
    with pytest.raises(StudyFileError, match="left as it is"):
        RowFile.create(p, COLS)
    assert p.read_bytes() == b"mine\n"
    with pytest.raises(StudyFileError, match="cannot create files in the folder"):
        RowFile.create(tmp_path / "no" / "r.csv", COLS)
    assert not (tmp_path / "no").exists()
    assert sorted(x.name for x in tmp_path.iterdir()) == ["r.csv"]


def test_discard_removes_only_an_unused_file_it_created(tmp_path):
    p = tmp_path / "r.csv"
    RowFile.create(p, COLS).discard_if_unused()
    assert not p.exists()
    f = RowFile.create(p, COLS)
    f.append({"seed": 1})
    f.discard_if_unused()
    assert len(read_rows(p)) == 1
    RowFile.open(p, COLS, resume=True).discard_if_unused()        # resumed: kept
    assert len(read_rows(p)) == 1


def test_errors_name_the_file_and_survive_pickling(tmp_path):
    import pickle
    e = StudyFileError(tmp_path / "a.csv", "is bad").named("out_path")
    assert str(e) == f"out_path {str(tmp_path / 'a.csv')!r}: is bad"
    back = pickle.loads(pickle.dumps(e))
    assert (back.path, back.reason, back.param, str(back)) == (e.path, e.reason, e.param, str(e))
    assert isinstance(e, ValueError)


def test_parse_cell_types():
    assert parse_cell("") is None and parse_cell("true") is True
    assert parse_cell("12") == 12 and isinstance(parse_cell("12"), int)
    assert parse_cell("1e-3") == 1e-3 and parse_cell("20x20") == "20x20"
    assert parse_cell("h0123456789abcdef") == "h0123456789abcdef"
