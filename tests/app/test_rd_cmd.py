"""`mesoforge rd`: optimise, grow, compile and write a PNG / STL."""

import json

import numpy as np
import pytest

from app import cli, rd_cmd


def _run(capsys, *args):
    code = cli.main(["rd", *map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_tiny_cantilever_writes_a_png_and_json(tmp_path, capsys):
    from PIL import Image

    out = tmp_path / "cantilever.png"
    code, text, err = _run(capsys, "--preset", "cantilever", "--res", "32x16", "--grow-res", "96x48",
                           "--gamma", 4, "--max-steps", 1500, "--max-iter", 15, "--out", out, "--json")
    assert code == 0, err
    info = json.loads(text)
    assert set(info) >= {"out", "optimisation", "growth", "compile_seconds", "total_seconds"}
    assert info["optimisation"]["seconds"] > 0 and info["optimisation"]["iterations"] == 15
    g = info["growth"]
    assert g["grid"] == [96, 48] and g["cell_updates_per_second"] > 0 and len(g["directions"]) == 2
    for d in g["directions"]:
        assert d["stop_reason"] in ("converged", "max_steps") and 0 < d["stop_step"] <= 1500
        assert d["stop_time"] == pytest.approx(d["stop_step"] * d["dt"])
        assert d["steps"] >= d["stop_step"] and d["seconds"] >= 0
        if d["stop_reason"] == "converged":
            assert d["stop_g"] < 1e-7
    img = np.asarray(Image.open(out))
    assert img.shape == (48, 96) and set(np.unique(img)) <= {0, 255}
    assert 0.02 < (img == 0).mean() < 0.6
    assert "grow:" in err                                                   # progress on stderr


def test_tiny_mbb3d_writes_a_closed_stl(tmp_path, capsys):
    import trimesh

    out = tmp_path / "mbb.stl"
    code, text, err = _run(capsys, "--preset", "mbb3d", "--res", "16x8x4", "--grow-res", "48x24x12",
                           "--gamma", 4, "--max-steps", 1000, "--max-iter", 10, "--iso", 0.5, "--out", out)
    assert code == 0, err
    assert "wrote" in text
    mesh = trimesh.load(out)
    assert mesh.is_watertight and len(mesh.faces) > 100
    assert np.all(mesh.bounds[0] >= -1e-9) and np.all(mesh.bounds[1] <= np.array([16, 8, 4]) + 1e-6)  # elements


@pytest.mark.parametrize("args, needle", [
    (["--res", "32x16x4", "--out", "x.png"], "--res"),
    (["--res", "32by16", "--out", "x.png"], "--res"),
    (["--out", "x.obj"], "--out"),
    (["--preset", "mbb3d", "--out", "x.png"], "--out"),
    (["--fields", "missing.npz", "--out", "x.png"], "--fields"),
    (["--max-steps", "0", "--out", "x.png"], "--max-steps"),
    (["--preset", "lbeam", "--res", "40x20", "--max-iter", "1", "--out", "x.png"], "--res"),
])
def test_bad_arguments_exit_2_naming_them(tmp_path, capsys, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(capsys, *args)
    assert code == 2
    line = err.strip().splitlines()[-1]
    assert line.startswith("mesoforge rd:") and needle in line
    assert not list(tmp_path.iterdir())                                      # nothing written


def test_ctrl_c_exits_130_and_writes_nothing(tmp_path, capsys, monkeypatch):
    out = tmp_path / "c.png"

    def interrupted(*_a, **_k):
        raise KeyboardInterrupt
    monkeypatch.setattr(rd_cmd, "_evaluate", interrupted)
    code, _, err = _run(capsys, "--res", "32x16", "--out", out)
    assert code == 130 and "not written" in err and not out.exists()


def test_fields_file_grows_without_optimising(tmp_path, capsys):
    ny, nx = 24, 48
    rho = np.zeros((ny, nx))
    rho[4:20, 4:44] = 1.0
    angle = 0.4
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    np.savez(tmp_path / "f.npz", rho=rho, R=np.broadcast_to(R, (ny, nx, 2, 2)))
    out = tmp_path / "f.png"
    code, text, err = _run(capsys, "--fields", tmp_path / "f.npz", "--grow-res", "96x48", "--gamma", 4,
                           "--max-steps", 800, "--out", out, "--json")
    assert code == 0, err
    info = json.loads(text)
    assert info["optimisation"] is None and info["growth"]["grid"] == [96, 48] and out.exists()
