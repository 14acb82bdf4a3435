"""The memory budget and its refusals (engine.memory)."""

import pytest

from engine.memory import (ENV_LIMIT, MemoryLimitError, check_budget, format_bytes, memory_budget, parse_bytes,
                           tiled_mesh_bytes)


def test_parse_bytes_reads_suffixes_as_powers_of_1024():
    assert parse_bytes("512M") == 512 * 2**20
    assert parse_bytes("4g") == 4 * 2**30
    assert parse_bytes("1e9") == 10**9
    assert parse_bytes(" 2 KB ") == 2048
    for bad in ("", "lots", "-1G", "0", "nan", "1X", "inf"):
        with pytest.raises(ValueError, match=ENV_LIMIT):
            parse_bytes(bad)


def test_budget_comes_from_the_environment(monkeypatch):
    monkeypatch.setenv(ENV_LIMIT, "3M")
    assert memory_budget() == 3 * 2**20
    monkeypatch.setenv(ENV_LIMIT, "many")
    with pytest.raises(ValueError, match="many"):
        memory_budget()
    monkeypatch.delenv(ENV_LIMIT)
    assert memory_budget() is None or memory_budget() > 0


def test_check_budget_names_estimate_budget_and_what_to_lower(monkeypatch):
    monkeypatch.setenv(ENV_LIMIT, "1M")
    assert check_budget(1000, what="x") == 1000
    with pytest.raises(MemoryLimitError) as info:
        check_budget(26_500_000_000, what="resolution = 512", lower="resolution", where="resolution")
    e = info.value
    assert isinstance(e, ValueError) and e.need == 26_500_000_000 and e.budget == 2**20 and e.where == "resolution"
    assert str(e) == ("resolution = 512 needs about 26.5 GB of memory, more than the 1.05 MB allowed by "
                      "MESOFORGE_MEMORY_LIMIT; lower resolution")
    assert check_budget(10**12, what="x", budget=10**13) == 10**12


def test_format_bytes():
    assert [format_bytes(n) for n in (12, 1500, 2.5e6, 26.5e9, 3e12)] == ["12 B", "1.5 kB", "2.5 MB", "26.5 GB",
                                                                         "3 TB"]


def test_tiled_mesh_bytes_counts_the_tiled_grid_and_faces():
    assert tiled_mesh_bytes((32, 32, 32), (1, 1, 1)) == 0          # the cell's own mesh is reused
    one = tiled_mesh_bytes((32, 32, 32), (2, 1, 1), faces=0)
    assert one == (64 + 3) * 35 * 35 * 32
    assert tiled_mesh_bytes((32, 32, 32), (2, 1, 1), faces=1000) == one + 2000 * 128
    # twenty cells per axis of a 96^3 grid: hundreds of GB, refused long before allocating
    assert tiled_mesh_bytes((96, 96, 96), (20, 20, 20)) > 200e9
