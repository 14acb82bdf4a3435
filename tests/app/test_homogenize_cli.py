import json

import numpy as np
import pytest

from app import cli


def _run(capsys, *args):
    code = cli.main(["homogenize", *map(str, args)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_npy_laminate_matches_closed_form(tmp_path, capsys):
    # Layers normal to x of stiffness E and 0.5 E (same nu), equal thickness.
    # Closed form: strains parallel to the layers are shared (Voigt), stresses
    # normal to them are shared (Reuss) -- for equal nu the in-plane shear and
    # normal stiffness are Voigt means and the normal ones harmonic means.
    n = 8
    grid = np.ones((n, n, n))
    grid[n // 2:] = 0.5
    p = tmp_path / "lam.npy"
    np.save(p, grid)
    code, out, err = _run(capsys, p, "--E", 1.0, "--nu", 0.0, "--json")
    assert code == 0, err
    res = json.loads(out)
    C = np.array(res["C"])
    # nu = 0: C = diag(E, E, E, E/2, E/2, E/2) per layer; stacked along x
    harmonic = 1 / (0.5 / 1.0 + 0.5 / 0.5)
    mean = 0.75
    expect = np.diag([harmonic, mean, mean, mean / 2, harmonic / 2, harmonic / 2])
    np.testing.assert_allclose(C, expect, rtol=1e-6, atol=1e-9)
    assert res["kind"] == "voxels" and res["density"] == pytest.approx(0.75)


def test_png_solid_gives_plane_stress_isotropic(tmp_path, capsys):
    from PIL import Image
    p = tmp_path / "solid.png"
    Image.fromarray(np.zeros((10, 10), np.uint8)).save(p)  # black = solid
    code, out, err = _run(capsys, p, "--E", 2.0, "--nu", 0.25, "--json")
    assert code == 0, err
    C = np.array(json.loads(out)["C"])
    f = 2.0 / (1 - 0.25**2)
    np.testing.assert_allclose(C, [[f, 0.25 * f, 0], [0.25 * f, f, 0], [0, 0, f * 0.75 / 2]], rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("grid, message", [
    (np.full((4, 4, 4), np.nan), "NaN"),
    (np.full((4, 4, 4), 2.0), "[0, 1]"),
    (np.zeros((4, 4, 4)), "empty"),
    (np.ones((4, 4, 5)), "cubic"),
])
def test_bad_grids_are_refused_with_a_message(tmp_path, capsys, grid, message):
    p = tmp_path / "bad.npy"
    np.save(p, grid)
    code, out, err = _run(capsys, p)
    assert code == 2 and str(p) in err and message in err


def test_bad_material_is_refused(tmp_path, capsys):
    p = tmp_path / "ok.npy"
    np.save(p, np.ones((4, 4, 4)))
    code, _, err = _run(capsys, p, "--nu", 0.5)
    assert code == 2 and "nu" in err
    code, _, err = _run(capsys, p, "--E", -1)
    assert code == 2 and "E" in err


def test_huge_grid_is_refused_up_front_with_an_estimate(tmp_path, capsys):
    p = tmp_path / "huge.npy"
    np.save(p, np.ones((300, 300, 300), np.uint8))
    code, _, err = _run(capsys, p)
    assert code == 2 and "GB" in err and "300" in err


def test_png_reports_the_polar_young_modulus(tmp_path, capsys):
    from PIL import Image
    img = np.full((20, 20), 255, np.uint8)
    img[:, 8:12] = 0          # a vertical bar: stiff along y only...
    img[8:12, :] = 0          # ...and a horizontal one: a square grid
    p = tmp_path / "grid.png"
    Image.fromarray(img).save(p)
    code, out, err = _run(capsys, p, "--json")
    assert code == 0, err
    res = json.loads(out)
    E = np.array(res["polar"]["E"])
    theta = np.radians(res["polar"]["theta_deg"])
    # a square grid is stiffest along its bars (0 and 90 degrees), softest at 45
    assert E[np.argmin(abs(theta - 0))] == pytest.approx(E[np.argmin(abs(theta - np.pi / 2))], rel=1e-6)
    assert E[np.argmin(abs(theta - np.pi / 4))] < 0.5 * E[0]
    assert E[0] == pytest.approx(res["constants"]["E_x"], rel=1e-9)
