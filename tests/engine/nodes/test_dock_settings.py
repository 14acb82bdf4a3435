"""The docks' own settings (#14): each schema refuses what the engine code that consumes the
value refuses, so the range a field shows is the engine's rule."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from engine.batch.study_params import SAMPLE, SEED, STUDY_PARAMS, check_resolution, expected
from engine.graph import ParamError, node_type
from engine.growth.regions import paint_disc
from engine.growth.tileset import TILESET_DIR, parse_tileset
from engine.nodes.growth_tools import BLOCK_WEIGHT, REGION_BRUSH_RADIUS, block_weight_check, region_brush_check
from engine.nodes.phasor_brush import BRUSH_PARAMS, brush_check
from engine.nodes.rd_brush import BRUSH_RADIUS, LIVE_EVERY, SOLID_VALUE, brush_check as rd_check
from engine.phasor.strokes import Stroke


def _takes(param, check, value) -> bool:
    try:
        v = param.coerce(value)
        if check is not None:
            check(v)
    except (ParamError, ValueError):
        return False
    return True


def _stroke_takes(name, value) -> bool:
    """Whether a Stroke takes ``value`` (in the dock's units) for brush setting ``name``."""
    kw = dict(field="F", axis="z", position=0.0, points=[[0.0, 0.0], [1.0, 0.0]], radius=1.0, value=1.0)
    if name in ("radius", "strength", "depth"):
        kw[name] = value
    elif name in ("F", "Gamma"):
        kw.update(field=name, value=value if name == "F" else math.radians(value))
    elif name == "tilt":
        kw.update(field="D", value=None, tilt=math.radians(value))
    try:
        Stroke(**kw)
    except ValueError:
        return False
    return True


@pytest.mark.parametrize("name", ["radius", "strength", "F", "Gamma", "tilt", "depth"])
@pytest.mark.parametrize("value", [-100.0, -90.0, -1e-9, 0.0, 1e-9, 0.5, 1.0, 1.5, 89.999, 90.0, 90.001, 1e6,
                                   math.inf, math.nan])
def test_the_phasor_brush_fields_take_what_a_stroke_takes(name, value):
    if name == "depth" and value == 0.0:    # 0 is "= radius" (the field's special value), sent as None
        assert _takes(BRUSH_PARAMS[name], None, value) and _stroke_takes(name, None)
        return
    assert _takes(BRUSH_PARAMS[name], brush_check(name), value) == _stroke_takes(name, value)


@pytest.mark.parametrize("value", [-1.0, 0.0, 1e-6, 2.5, 1e9, math.inf, math.nan])
def test_the_rd_brush_radius_and_value_are_the_nodes_rule(value):
    edits, gamma = node_type("RDGrow").param("edits"), node_type("RDFields").param("gamma_c")
    node_radius = _takes(edits, None, [{"mode": "draw", "centre": [1.0, 1.0], "radius": value}])
    assert _takes(BRUSH_RADIUS, rd_check("radius"), value) == node_radius
    node_value = _takes(gamma, None, [[{"centre": [1.0, 1.0], "radius": 1.0, "value": value}]])
    assert _takes(SOLID_VALUE, rd_check("value", solid=True), value) == node_value
    assert LIVE_EVERY.maximum == node_type("RDGrow").param("max_steps").maximum


@pytest.mark.parametrize("value", [-1.0, 0.0, 0.5, 1e6, math.inf, math.nan])
def test_growth_brush_radius_and_block_weight_are_the_kernels_rules(value):
    try:
        paint_disc(np.zeros((2, 2), np.int64), [[0.5, 0.5]], value, 1)
        painted = True
    except ValueError:
        painted = False
    assert _takes(REGION_BRUSH_RADIUS, region_brush_check, value) == painted
    data = json.loads((TILESET_DIR / "tl_basic.json").read_text())
    data["blocks"][0]["weight"] = value
    try:
        parse_tileset(data)
        loaded = True
    except ValueError:
        loaded = False
    assert _takes(BLOCK_WEIGHT, block_weight_check, value) == loaded


def test_study_settings_ranges_and_words():
    assert SEED.coerce(2**64 - 1) == 2**64 - 1 and SEED.coerce(2**40) == 2**40
    with pytest.raises(ParamError):
        SEED.coerce(2**64)
    assert expected(STUDY_PARAMS["sweep"]) == "a number of hint vectors >= 1"
    assert expected(STUDY_PARAMS["samples"]) == "a number of samples >= 1"
    assert SAMPLE.coerce(-1) == -1
    check_resolution(0)
    check_resolution(2)
    with pytest.raises(ValueError, match=">= 2"):
        check_resolution(1)
