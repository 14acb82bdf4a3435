import math
import os
import re

import numpy as np
import pytest

from engine.fab import Layer, PrintSettings, read_gcode_paths, write_gcode
from engine.geometry import Cancelled


def square(side, x0=0.0, y0=0.0):
    return np.array([[x0, y0], [x0 + side, y0], [x0 + side, y0 + side],
                     [x0, y0 + side], [x0, y0]])


@pytest.mark.parametrize("relative", [False, True])
def test_square_extrusion_matches_closed_form(tmp_path, relative):
    s = PrintSettings(relative_extrusion=relative, extrusion_multiplier=0.95)
    side = 20.0
    layers = [Layer(z=0.2 * (k + 1), paths=(square(side), square(side / 2, 30, 30)),
                    kinds=("perimeter", "infill")) for k in range(3)]
    out = tmp_path / "sq.gcode"
    summary = write_gcode(layers, out, settings=s)
    r_f = s.filament_diameter / 2
    per_square = 4 * side * s.nozzle_diameter * s.layer_height * 0.95 / (math.pi * r_f ** 2)
    back = read_gcode_paths(out, offset=s.offset)
    assert len(back) == 3
    for layer in back:
        assert layer.filament[0] == pytest.approx(per_square, abs=1e-4)
        assert layer.filament[1] == pytest.approx(per_square / 2, abs=1e-4)
    assert summary.filament_length == pytest.approx(3 * 1.5 * per_square)
    assert summary.extrusion_length == pytest.approx(3 * 1.5 * 4 * side)
    text = out.read_text()
    assert ("M83" in text) == relative and ("M82" in text) != relative


def test_parser_recovers_written_paths(tmp_path):
    rng = np.random.default_rng(3)
    layers = []
    for k in range(4):
        paths = tuple(np.cumsum(rng.uniform(-2, 2, (rng.integers(2, 30), 2)), axis=0) + 25
                      for _ in range(5))
        layers.append(Layer(z=0.2 * (k + 1), paths=paths, kinds=("infill",) * 5))
    s = PrintSettings(offset=(110.5, 90.25))
    write_gcode(iter(layers), tmp_path / "r.gcode", settings=s, n_layers=4)
    back = read_gcode_paths(tmp_path / "r.gcode", offset=s.offset)
    assert [b.z for b in back] == pytest.approx([l.z for l in layers])
    for b, l in zip(back, layers):
        assert b.kinds == l.kinds
        assert len(b.paths) == len(l.paths)
        for p, q in zip(b.paths, l.paths):
            np.testing.assert_allclose(p, q, atol=0.6e-3)     # 3 decimals


def test_header_order_first_layer_and_footer(tmp_path):
    s = PrintSettings(nozzle_temperature=215, bed_temperature=65, first_layer_speed=15,
                      print_speed=50)
    layers = [Layer(z=0.2 * (k + 1), paths=(square(10),), kinds=("perimeter",))
              for k in range(2)]
    out = tmp_path / "h.gcode"
    write_gcode(layers, out, settings=s)
    lines = [l.split(";")[0].strip() or l.strip() for l in out.read_text().splitlines()]
    want = ["M140 S65", "M104 S215", "M190 S65", "M109 S215", "G28", "G90", "M82", "G92 E0",
            ";LAYER:0", "G0 Z0.200", "G1 F900", ";LAYER:1", "G0 Z0.400", "G1 F3000",
            "M104 S0", "M140 S0", "M84"]
    pos = [next(i for i, l in enumerate(lines) if l.startswith(w)) for w in want]
    assert pos == sorted(pos)
    first_extrusion = next(i for i, l in enumerate(lines) if re.match(r"G1 X.* E", l))
    assert pos[want.index(";LAYER:0")] < first_extrusion < pos[want.index(";LAYER:1")]
    assert ";LAYER_COUNT:" in out.read_text()
    assert re.search(r";LAYER_COUNT:\s*2\n", out.read_text())


def test_travel_retracts_and_restores(tmp_path):
    s = PrintSettings(retraction_length=2.0, retraction_min_travel=1.0, offset=(0, 0))
    layer = Layer(z=0.2, paths=(np.array([[0.0, 0], [10, 0]]), np.array([[10.0, 0.5], [0, 0.5]]),
                                np.array([[0.0, 20], [10, 20]])), kinds=("infill",) * 3)
    out = tmp_path / "t.gcode"
    write_gcode([layer], out, settings=s)
    lines = out.read_text().splitlines()
    travels = [i for i, l in enumerate(lines) if l.startswith("G0 X")]
    # the short hop (0.5 mm) needs no retraction, the 20 mm one does
    es = [float(m.group(1)) for l in lines for m in [re.match(r"G1 E(-?[\d.]+)", l)] if m]
    assert len(es) >= 4            # retract/restore around the first travel and the long one
    long_hop = travels[-1]
    assert lines[long_hop - 1].startswith("G1 E") and lines[long_hop + 1].startswith("G1 E")
    assert not lines[travels[-2] - 1].startswith("G1 E")
    back = read_gcode_paths(out)
    assert back[0].filament.sum() == pytest.approx(30 * s.filament_per_mm, abs=1e-4)


def test_cancel_leaves_existing_file_untouched(tmp_path):
    out = tmp_path / "keep.gcode"
    out.write_text("old")
    layers = [Layer(z=0.2 * (k + 1), paths=(square(5),), kinds=("infill",)) for k in range(5)]
    calls = []

    def progress(done, total):
        calls.append((done, total))
        return done < 2

    with pytest.raises(Cancelled):
        write_gcode(layers, out, progress=progress)
    assert out.read_text() == "old"
    assert os.listdir(tmp_path) == ["keep.gcode"]
    assert calls[:3] == [(0, 5), (1, 5), (2, 5)]
