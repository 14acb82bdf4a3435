"""Hints text parsing: names, numbers, and errors that name the entry."""

import pytest

from engine.batch import format_hints, parse_hints
from engine.growth import load_tileset


def test_parse_blocks_and_tiles():
    ts = load_tileset("TL+-")
    assert parse_hints("T=1, L = 1,+=2,-=0.5", ts) == {"T": 1.0, "L": 1.0, "+": 2.0, "-": 0.5}
    assert parse_hints("T@1=3", ts) == {"T@1": 3.0}
    assert parse_hints("   ", ts) is None
    h = {"T": 0.1, "+": 0.3}
    assert parse_hints(format_hints(h), ts) == h


@pytest.mark.parametrize("text, match", [
    ("T=1,Q=2", r"entry 2 'Q=2': 'Q' is not a block of tile set 'TL\+-'"),
    ("T=1,L", r"entry 2 'L': expected name=weight"),
    ("T=x", r"entry 1 'T=x': weight 'x' is not a number"),
    ("T=-1", r"entry 1 'T=-1': weight must be a finite number >= 0"),
    ("T=nan", r"entry 1 'T=nan': weight must be"),
    ("=1", r"entry 1 '=1': the block name before '=' is empty"),
    ("T=1,T=2", r"entry 2 'T=2': 'T' is given twice"),
    ("T=0,L=0", r"at least one weight must be > 0"),
])
def test_errors_name_the_entry(text, match):
    with pytest.raises(ValueError, match=match):
        parse_hints(text, load_tileset("TL+-"))
