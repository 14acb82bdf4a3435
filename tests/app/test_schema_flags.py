"""app.schema_flags and app.graph_run: flags made from node schemas, graphs run for the CLI."""

from __future__ import annotations

import argparse
import json

import pytest

import engine.nodes  # noqa: F401  (registers the nodes)
from app.flags import FlagError
from app.graph_run import GraphRunFailed, build, evaluate, part_of
from app.schema_flags import add_param_flags, param_values
from engine.graph import Evaluator, node_type


def parser(type_name, params, **kw):
    p = argparse.ArgumentParser(prog="mesoforge test")
    return p, add_param_flags(p, type_name, params, **kw)


def test_help_shows_the_schema_doc_range_unit_and_default():
    p, _ = parser("Grow", {"size": "--size", "periodic": "--periodic", "availability": "--availability"})
    text = " ".join(p.format_help().split())
    grow = node_type("Grow")
    size, avail = grow.param("size"), grow.param("availability")
    assert size.doc.split()[0] in text and f"allowed: {size.allowed()}" in text
    assert "default: 20x20 blocks" in text and "--no-periodic" in text and "default: on" in text
    assert f"allowed: {avail.allowed()}" in text and "default: 0.0" in text


def test_given_flags_become_node_params_and_the_rest_keep_the_node_defaults():
    p, g = parser("Grow", ["size", "periodic", "hints"])
    args = p.parse_args(["--size", "8x6", "--no-periodic"])
    assert param_values(args, g) == {"size": [8, 6], "periodic": False}
    full = param_values(args, g, only_given=False)
    assert full == {"size": [8, 6], "periodic": False, "hints": node_type("Grow").param("hints").default}
    for text in ("8,6", "8 6"):
        assert param_values(p.parse_args(["--size", text]), g)["size"] == [8, 6]


@pytest.mark.parametrize("argv, flag, reason", [
    (["--size", "8x0"], "--size 8x0", "out of range (allowed: integers in [1, 1000])"),
    (["--size", "8xq"], "--size 8xq", "not integers like 8x8"),
    (["--availability", "-1"], "--availability -1", "out of range (allowed: a finite number in [0, 1e+06])"),
    (["--availability", "lots"], "--availability lots", "not a number"),
    (["--availability", "nan"], "--availability nan", "expected a finite number"),
])
def test_bad_values_are_refused_by_the_schema_naming_flag_value_and_range(argv, flag, reason):
    p, g = parser("Grow", ["size", "availability"])
    with pytest.raises(FlagError) as exc:
        param_values(p.parse_args(argv), g)
    assert str(exc.value).startswith(flag) and reason in str(exc.value)


def test_enum_int_json_forms_required_and_typed_flags(tmp_path):
    p, g = parser("TilingProperties", {"void": "--void", "resolution": "--resolution"}, typed=("resolution",))
    args = p.parse_args(["--void", "soft", "--resolution", "12"])
    assert args.resolution == 12 and param_values(args, g) == {"void": "soft", "resolution": 12}
    with pytest.raises(FlagError, match="one of"):
        param_values(p.parse_args(["--void", "glass"]), g)
    p, g = parser("Grow", ["size"], required=("size",))
    with pytest.raises(SystemExit):
        p.parse_args([])
    strokes = tmp_path / "strokes.json"
    strokes.write_text(json.dumps([]))
    p, g = parser("PhasorFields", ["strokes"])
    assert param_values(p.parse_args(["--strokes", f"@{strokes}"]), g) == {"strokes": []}
    with pytest.raises(FlagError, match="not JSON"):
        param_values(p.parse_args(["--strokes", "[1,"]), g)


def test_graph_run_builds_evaluates_and_names_the_failing_flag():
    doc = build(3, {"ts1": ("TileSet", {}), "grow1": ("Grow", {"size": [4, 4]})},
                [("ts1", "tileset", "grow1", "tileset")])
    report = evaluate(doc, quiet=True)
    ref = Evaluator().evaluate(doc)
    assert report.output("grow1", "tiling").tiling.tiles.tobytes() == \
        ref.output("grow1", "tiling").tiling.tiles.tobytes()
    nodes, edges = part_of(doc, "grow1")
    assert list(nodes) == ["ts1", "grow1"] and edges == [("ts1", "tileset", "grow1", "tileset")]
    bad = build(0, {"ts1": ("TileSet", {"path": "/no/such/tileset.json"}), "grow1": ("Grow", {"size": [4, 4]})},
                [("ts1", "tileset", "grow1", "tileset")])
    with pytest.raises(GraphRunFailed) as exc:
        evaluate(bad, quiet=True, flag_of={"TileSet": {"path": "--tileset"}})
    assert str(exc.value).startswith("--tileset: ") and exc.value.node_id == "ts1" and exc.value.where == "path"
    with pytest.raises(GraphRunFailed) as exc:
        evaluate(bad, quiet=True)
    assert str(exc.value).endswith(" [path]")
