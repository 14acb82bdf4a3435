import subprocess
import sys

import numpy as np
import pytest

from engine.fab import (PrintSettings, layer_preview_lines, layer_stack_toolpaths,
                        layers_to_gcode, read_gcode_paths, vtk_line_cells)
from engine.fab.preview import KIND_CODES
from engine.geometry import Cancelled

PX = 0.1


def stack(diamonds, n_layers=4, n=80):
    c = (n - 1) / 2
    yy, xx = np.mgrid[0:n, 0:n]
    disc = np.hypot(xx - c, yy - c) * PX <= 3.5
    for k in range(n_layers):
        z = 0.2 * (k + 1)
        yield z, diamonds(n, PX, z), disc, (-4.0, -4.0), PX


def test_layers_to_gcode_round_trip(tmp_path, diamonds):
    s = PrintSettings(perimeters=2)
    calls = []
    out = tmp_path / "part.gcode"
    summary = layers_to_gcode(stack(diamonds), out, settings=s, n_layers=4,
                              progress=lambda d, t: calls.append((d, t)) or True)
    assert summary.layers == 4 and calls[-1] == (4, 4)
    back = read_gcode_paths(out, offset=s.offset)
    assert [round(b.z, 3) for b in back] == [0.2, 0.4, 0.6, 0.8]
    for b in back:
        assert b.kinds.count("perimeter") == 2 and "infill" in b.kinds
        pts = np.concatenate(b.paths)
        assert np.hypot(pts[:, 0] + 4 - 3.95, pts[:, 1] + 4 - 3.95).max() <= 3.5 - 0.2 + PX
    assert sum(b.filament.sum() for b in back) == pytest.approx(summary.filament_length, rel=1e-5)


def test_layers_to_gcode_cancel_and_bad_items(tmp_path, diamonds):
    with pytest.raises(Cancelled):
        layers_to_gcode(stack(diamonds), tmp_path / "c.gcode", progress=lambda d, t: d < 1)
    assert not (tmp_path / "c.gcode").exists()
    with pytest.raises(ValueError, match="layer 0"):
        layers_to_gcode([(0.2, np.zeros((4, 4), bool))], tmp_path / "b.gcode")


def test_preview_lines(diamonds):
    layers = list(layer_stack_toolpaths(stack(diamonds, n_layers=3)))
    pv = layer_preview_lines(layers)
    n_seg = sum(len(p) - 1 for l in layers for p in l.paths)
    assert pv.segments.shape == (n_seg, 2) and pv.kinds.shape == (n_seg,)
    assert pv.points.shape == (sum(len(p) for l in layers for p in l.paths), 3)
    assert set(np.unique(pv.points[:, 2]).round(3)) == {0.2, 0.4, 0.6}
    assert np.all(pv.points[pv.segments[:, 0], 2] == pv.points[pv.segments[:, 1], 2])
    with_travel = layer_preview_lines(layers, travel=True)
    n_travel = sum(len(l.paths) - 1 for l in layers)
    assert np.count_nonzero(with_travel.kinds == KIND_CODES["travel"]) == n_travel
    assert layer_preview_lines(layers, every=2).layer.max() == 2
    assert vtk_line_cells([[0, 1], [1, 2]]).tolist() == [2, 0, 1, 2, 1, 2]


def test_fab_import_leaves_qt_out():
    code = ("import sys, engine.fab; bad = [m for m in sys.modules if m.split('.')[0] in "
            "('PySide6', 'pyvista', 'pyvistaqt', 'ui', 'app')]; sys.exit(1 if bad else 0)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_same_inputs_same_bytes(tmp_path, diamonds):
    a, b = tmp_path / "a.gcode", tmp_path / "b.gcode"
    layers_to_gcode(stack(diamonds, n_layers=2), a)
    layers_to_gcode(stack(diamonds, n_layers=2), b)
    assert a.read_bytes() == b.read_bytes()
