"""Slices, singularity energies and prints of a phasor infill (engine.phasor.infill)."""

import logging

import numpy as np
import pytest
import trimesh

from engine.fab import PrintSettings, read_gcode_paths
from engine.progress import Cancelled
from engine.phasor.domain import box_of, slice_domain
from engine.phasor.field_init import fields_from_spec
from engine.phasor.fields import constant_fields
from engine.phasor.infill import (check_pixel, infill_slice, layer_positions, sample_infill,
                                  slice_plane, write_print)
from engine.phasor.noise import diamond_mask, phasor_complex, sawtooth, slice_points
from engine.phasor.singularity import singularity_energy, singularity_slice_fd

SPEC = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 45}, "F": 1.0}


@pytest.fixture(scope="module")
def part():
    mesh = trimesh.creation.box(extents=(6.0, 4.0, 1.0))
    lo, hi = box_of(mesh, 0.5)
    fields = fields_from_spec(SPEC, lo=lo, hi=hi, shape=(4, 10, 14), mesh=mesh)
    return mesh, sample_infill(fields, domain=mesh, rng=2, iterations=8)


@pytest.fixture(scope="module")
def boxed():
    fields = fields_from_spec(SPEC, lo=[0, 0, 0], hi=[6, 6, 1], shape=(2, 12, 12))
    return sample_infill(fields, rng=4, iterations=8)


def test_check_pixel_names_the_frequency_and_the_pixel():
    fields = constant_fields([0, 0, 0], [4, 4, 4], (2, 2, 2), frequency=2.0)
    check_pixel(fields, 0.125)                  # exactly 4 pixels per period
    with pytest.raises(ValueError) as err:
        check_pixel(fields, 0.2)
    text = str(err.value)
    assert "pixel 0.2 mm" in text and "F up to 2 cells/mm" in text and "F <= 1.25 cells/mm" in text
    with pytest.raises(ValueError, match="positive length"):
        check_pixel(fields, 0.0)


def test_slice_plane_covers_the_box_in_whole_pixels(boxed):
    plane = slice_plane(boxed.fields, "y", 3.0, 0.1)
    assert plane.shape == (10, 60)                  # rows along z (1 mm), columns along x (6 mm)
    assert np.allclose(plane.origin, [0, 3, 0]) and np.allclose(plane.size, [6, 1])
    with pytest.raises(ValueError, match=r"position: z = 1.5 mm lies outside .* \[0, 1\]"):
        slice_plane(boxed.fields, "z", 1.5, 0.1)
    with pytest.raises(ValueError, match="axis"):
        slice_plane(boxed.fields, "w", 0.5, 0.1)


def test_raw_state_is_the_same_kernels_with_zero_phases(boxed):
    kernels, filtered = boxed.noise("raw")
    assert not filtered and not kernels.phase_v.any() and not kernels.phase_w.any()
    assert np.array_equal(kernels.direction_v, boxed.kernels.direction_v)
    assert boxed.noise("aligned") == (boxed.kernels, False)
    assert boxed.noise() == (boxed.kernels, True) and boxed.state == "aligned+filtered"
    with pytest.raises(ValueError, match="state"):
        boxed.noise("smoothed")


def test_numpy_slice_is_the_sawtooth_of_the_reference_noise(boxed):
    r = infill_slice(boxed, "z", 0.5, 0.1, state="aligned", engine="numpy")
    plane = slice_plane(boxed.fields, "z", 0.5, 0.1)
    g_v, g_w = phasor_complex(boxed.kernels, slice_points(plane))
    assert np.array_equal(r.p_v, sawtooth(g_v).reshape(plane.shape))
    assert np.array_equal(r.diamonds, diamond_mask(sawtooth(g_v), sawtooth(g_w)).reshape(plane.shape))
    assert r.engine == "numpy" and r.inside.all()


def test_energy_matches_the_singularity_module(boxed):
    r = infill_slice(boxed, "z", 0.5, 0.1, state="aligned", engine="numpy")
    e = r.energy()
    plane = slice_plane(boxed.fields, "z", 0.5, 0.1)
    s_v, s_w = singularity_slice_fd(boxed.kernels, plane, fields=boxed.fields)
    assert e["v"] == pytest.approx(singularity_energy(s_v), abs=1e-12)
    assert e["w"] == pytest.approx(singularity_energy(s_w), abs=1e-12)
    assert e["pixels"] == (plane.shape[0] - 2) * (plane.shape[1] - 2)
    raw = infill_slice(boxed, "z", 0.5, 0.1, state="raw", engine="numpy").energy()
    assert e["either"] < raw["either"]


def test_gpu_falls_back_to_numpy_when_egl_is_missing(boxed, monkeypatch, caplog):
    import engine.phasor.gpu_slice
    from engine.gpu import GpuUnavailable

    def no_gpu(*args, **kwargs):
        raise GpuUnavailable("no EGL here")

    monkeypatch.setattr(engine.phasor.gpu_slice, "phasor_slice_gpu", no_gpu)
    with caplog.at_level(logging.WARNING, logger="engine.phasor.infill"):
        r = infill_slice(boxed, "z", 0.5, 0.1, engine="gpu")
    assert r.engine == "numpy" and "no EGL here" in caplog.text
    ref = infill_slice(boxed, "z", 0.5, 0.1, engine="numpy")
    assert np.array_equal(r.g_v, ref.g_v)


def test_slices_of_a_part_keep_to_its_section(part):
    mesh, infill = part
    r = infill_slice(infill, "z", 0.1, 0.1, engine="numpy")
    ref = slice_domain(mesh, "z", 0.1, lo=r.lo, hi=r.hi, shape=r.plane.shape)
    assert np.array_equal(r.inside, ref) and 0 < ref.mean() < 1
    assert not r.diamonds[~r.inside].any() and r.diamonds[r.inside].any()
    e = r.energy()
    border = np.zeros(ref.shape, bool)
    border[1:-1, 1:-1] = True
    assert e["pixels"] == np.count_nonzero(ref & border)


def test_print_has_one_layer_per_height_inside_the_part(part, tmp_path):
    mesh, infill = part
    assert np.allclose(layer_positions(infill, 0.25), [-0.375, -0.125, 0.125, 0.375])
    settings = PrintSettings(layer_height=0.25, nozzle_diameter=0.4)
    out = tmp_path / "part.gcode"
    summary = write_print(infill, out, settings=settings, pixel=0.1, engine="numpy")
    layers = read_gcode_paths(out, offset=settings.offset)
    assert summary.layers == 4 and [round(layer.z, 3) for layer in layers] == [0.25, 0.5, 0.75, 1.0]
    for layer in layers:
        pts = np.concatenate(layer.paths)
        assert np.all(np.abs(pts) <= [3.0 + 1e-6, 2.0 + 1e-6])
        assert "INFILL" in {k.upper() for k in layer.kinds}


def test_a_cancelled_print_leaves_the_old_file(boxed, tmp_path):
    out = tmp_path / "p.gcode"
    out.write_text("old\n")
    with pytest.raises(Cancelled):
        write_print(boxed, out, pixel=0.1, engine="numpy", progress=lambda done, total: done < 2)
    assert out.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.gcode"]
