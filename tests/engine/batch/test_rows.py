"""Row files: complete rows only, partial last lines cut on resume."""

import math

import pytest

from engine.batch.rows import RowFile, format_row, parse_cell, read_rows

COLS = ["seed", "name", "x", "flag", "note"]


def test_rows_round_trip_exactly(tmp_path):
    p = tmp_path / "r.csv"
    rows = [{"seed": 2 ** 62 + 1, "name": "T=1.0,L=2.0", "x": 0.1 + 0.2, "flag": True,
             "note": "two\nlines"},
            {"seed": 3, "name": "+", "x": math.nan, "flag": False, "note": None}]
    with RowFile(p, COLS, resume=False) as f:
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
    with RowFile(p, COLS, resume=False) as f:
        f.append({"seed": 1, "name": "a", "x": 1.5, "flag": True})
        f.append({"seed": 2, "name": "b", "x": 2.5, "flag": True})
    full = p.read_bytes()
    p.write_bytes(full[:-7])                     # killed while writing row 2
    with RowFile(p, COLS, resume=True) as f:
        assert [r["seed"] for r in f.existing] == [1]
        f.append({"seed": 2, "name": "b", "x": 2.5, "flag": True})
    assert p.read_bytes() == full


def test_partial_header_restarts_the_file(tmp_path):
    p = tmp_path / "r.csv"
    p.write_bytes(b"seed,na")
    with RowFile(p, COLS, resume=True) as f:
        assert f.existing == []
    assert p.read_bytes() == format_row(COLS)


def test_other_columns_or_damaged_rows_are_refused(tmp_path):
    p = tmp_path / "r.csv"
    with RowFile(p, COLS, resume=False) as f:
        f.append({"seed": 1})
    with pytest.raises(ValueError, match="different kind of study"):
        RowFile(p, COLS + ["extra"], resume=True)
    p.write_bytes(p.read_bytes() + b"1,2\n")
    with pytest.raises(ValueError, match="line 3: 2 cells, expected 5"):
        RowFile(p, COLS, resume=True)
    with RowFile(p, COLS + ["extra"], resume=False) as f:     # resume=False starts afresh
        assert f.existing == []
    with pytest.raises(ValueError, match="not in the file header"):
        with RowFile(p, COLS, resume=False) as f:
            f.append({"bogus": 1})


def test_parse_cell_types():
    assert parse_cell("") is None and parse_cell("true") is True
    assert parse_cell("12") == 12 and isinstance(parse_cell("12"), int)
    assert parse_cell("1e-3") == 1e-3 and parse_cell("20x20") == "20x20"
    assert parse_cell("h0123456789abcdef") == "h0123456789abcdef"
