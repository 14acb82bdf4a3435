"""Filters (eqs. 15-17), Boolean combination (eq. 18), bounds, contours, meshes and writers."""

import numpy as np
import pytest

from engine.geometry.mesh_io import load_mesh, mesh_summary
from engine.rd.compile import (combine_structures, compile_structure, infill_signed_distance,
                               minimum_relative_thickness, pattern_wavelength, rescale_pattern,
                               save_structure_png, save_structure_stl, structure_contours, structure_mesh)

PERIOD = 40


def _stripes(n_periods=6, rows=4, period=PERIOD, axis=1):
    """Triangle-wave stripes: 1 on the stripe centre lines, 0 half a period away."""
    x = np.arange(n_periods * period) + 0.5
    dist = np.abs((x % period) - period / 2)
    s = 1.0 - dist / (period / 2)
    s = np.tile(s, (rows, 1))
    return s if axis == 1 else s.T


def _stripe_width(solid):
    """Mean width in cells of the runs of True along the last axis (first row)."""
    row = solid[0].astype(int)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], row, [0]])))
    runs = edges[1::2] - edges[::2]
    return runs.mean()


def test_equation_15_clamp_and_its_normalisation():
    s = np.linspace(0.0, 1.0, 101)
    mu, delta = 0.3, 0.05
    paper = np.maximum(np.minimum(s, 1 - mu + delta), 1 - mu - delta)
    ours = rescale_pattern(s, mu=mu, delta=delta)
    np.testing.assert_allclose((1 - mu - delta) + 2 * delta * ours, paper, atol=1e-15)


@pytest.mark.parametrize("mu", [0.12, 0.3, 0.4])
def test_stripe_width_follows_mu(mu):
    s = _stripes()
    before = _stripe_width(s > 0.5)
    after = _stripe_width(rescale_pattern(s, mu=mu, delta=0.01) > 0.5)
    assert before == pytest.approx(0.5 * PERIOD, abs=1)       # the raw 0.5 iso: half the period
    assert after == pytest.approx(mu * PERIOD, abs=1)         # eq. 16: h = mu l


def test_variable_thickness_heaviside():
    s = _stripes(rows=2)
    mu = np.where(np.arange(s.shape[1]) < s.shape[1] // 2, 0.1, 0.45) * np.ones_like(s)
    out = rescale_pattern(s, mu=mu, delta=0.0)
    assert set(np.unique(out)) <= {0.0, 0.5, 1.0}
    half = s.shape[1] // 2
    assert _stripe_width(out[:, :half] > 0.5) == pytest.approx(0.1 * PERIOD, abs=1)
    assert _stripe_width(out[:, half:] > 0.5) == pytest.approx(0.45 * PERIOD, abs=1)


def test_minimum_member_size_and_wavelength():
    assert minimum_relative_thickness(3, 20) == pytest.approx(0.15)
    n = 128
    y, x = np.mgrid[0:n, 0:n]
    t = np.radians(30)
    s = 0.5 + 0.5 * np.cos(2 * np.pi * (x * np.cos(t) + y * np.sin(t)) / 16.0)
    assert pattern_wavelength(s) == pytest.approx(16.0, rel=0.05)
    out = compile_structure([s, s.T], mu=(0.1, 0.3), h_min=4, wavelength=16)
    assert out.mu == (0.25, 0.3) and out.mu_min == pytest.approx(0.25)
    measured = compile_structure([s, s.T], mu=(0.1, 0.3), h_min=4)
    assert measured.wavelength == pytest.approx(16.0, rel=0.05)


def _random_smooth(rng, shape):
    from scipy.ndimage import gaussian_filter

    f = gaussian_filter(rng.normal(size=shape), 2.0)
    return (f - f.min()) / (f.max() - f.min())


def test_boolean_union_2d_matches_set_operations():
    rng = np.random.default_rng(0)
    a, b = _random_smooth(rng, (40, 50)), _random_smooth(rng, (40, 50))
    out = combine_structures([a, b])
    np.testing.assert_array_equal(out > 0.5, (a > 0.5) | (b > 0.5))


def test_boolean_lattice_and_membranes_3d_match_set_operations():
    rng = np.random.default_rng(1)
    s = [_random_smooth(rng, (12, 14, 16)) for _ in range(3)]
    m = [f > 0.5 for f in s]
    lattice = (m[0] & m[1]) | (m[0] & m[2]) | (m[1] & m[2])
    np.testing.assert_array_equal(combine_structures(s) > 0.5, lattice)
    np.testing.assert_array_equal(combine_structures(s, combination="membrane") > 0.5, m[0] | m[1])
    np.testing.assert_array_equal(combine_structures(s, combination="membrane", membranes=(2,)) > 0.5,
                                  m[2] | (m[0] & m[1]))
    with pytest.raises(ValueError, match="membrane"):
        combine_structures([s[0][0], s[1][0]], combination="membrane")     # 2D slices


def test_compile_2d_grid_lattice_bounded_by_rho_with_solid_gamma():
    s1 = _stripes(n_periods=4, rows=160, axis=1)          # stripes along y
    s2 = s1.T                                            # stripes along x
    n = s1.shape[0]
    y, x = np.mgrid[0:n, 0:n] + 0.5
    r = np.hypot(x - n / 2, y - n / 2)
    rho = np.clip(0.5 + (60.0 - r) / 8.0, 0.0, 1.0)       # disc of radius 60, smooth edge
    gamma = np.zeros_like(rho)
    gamma[70:90, 70:90] = 1.0
    out = compile_structure([s1, s2], mu=(0.2, 0.2), rho=rho, gamma=gamma)
    solid = out.density > 0.5
    union = (rescale_pattern(s1, mu=0.2) > 0.5) | (rescale_pattern(s2, mu=0.2) > 0.5) | (gamma > 0.5)
    inner = r < 58
    outer = r > 62
    np.testing.assert_array_equal(solid[inner], union[inner])
    assert not solid[outer].any()
    assert solid[70:90, 70:90].all()


def test_shell_on_the_infill_boundary():
    n = 120
    y, x = np.mgrid[0:n, 0:n] + 0.5
    r = np.hypot(x - 60.2, y - 59.7)
    rho = np.clip(0.5 + (40.0 - r) / 6.0, 0.0, 1.0)
    empty = np.zeros((n, n))
    sd = infill_signed_distance(rho)
    near, band = np.abs(r - 40) < 0.9, np.abs(r - 40) < 5
    np.testing.assert_allclose(sd[near], (40 - r)[near], atol=0.05)      # sub-cell from rho
    np.testing.assert_allclose(sd[band], (40 - r)[band], atol=0.75)      # distance transform
    out = compile_structure([empty, empty], mu=0.2, rho=rho, shell_thickness=3.0)
    area = (out.density > 0.5).sum()
    assert area == pytest.approx(np.pi * (40**2 - 37**2), rel=0.03)


def test_disc_contour_length():
    n, radius = 96, 30.0
    y, x = np.mgrid[0:n, 0:n] + 0.5
    r = np.hypot(x - 47.3, y - 49.1)
    dens = np.clip(0.5 + (radius - r) / 2.0, 0.0, 1.0)
    (c,) = structure_contours(dens)
    np.testing.assert_array_equal(c[0], c[-1])
    length = np.linalg.norm(np.diff(c, axis=0), axis=1).sum()
    assert length == pytest.approx(2 * np.pi * radius, rel=0.02)
    cross = c[:-1, 0] * c[1:, 1] - c[1:, 0] * c[:-1, 1]
    area = 0.5 * cross.sum()
    assert area > 0                                       # counter-clockwise outer boundary
    centroid = ((c[:-1] + c[1:]) * cross[:, None]).sum(axis=0) / (6 * area)
    np.testing.assert_allclose(centroid, [47.3, 49.1], atol=0.02)


def test_contour_is_closed_along_the_box():
    (c,) = structure_contours(np.ones((5, 7)), spacing=2.0)
    np.testing.assert_allclose(c.min(axis=0), [0.0, 0.0])
    np.testing.assert_allclose(c.max(axis=0), [14.0, 10.0])


def test_sphere_mesh_is_watertight_with_the_right_volume():
    n, radius = 40, 13.0
    z, y, x = np.mgrid[0:n, 0:n, 0:n] + 0.5
    r = np.sqrt((x - 20.3) ** 2 + (y - 19.6) ** 2 + (z - 20.1) ** 2)
    dens = np.clip(0.5 + (radius - r) / 2.0, 0.0, 1.0)
    v, f = structure_mesh(dens)
    info = mesh_summary(v, f)
    assert info["watertight"]
    assert info["volume"] == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.03)
    centre = np.array(info["bounds"]).mean(axis=0)
    np.testing.assert_allclose(centre, [20.3, 19.6, 20.1], atol=0.1)


def test_solid_touching_the_box_is_capped():
    dens = np.zeros((6, 8, 10))
    dens[:, 2:6, :] = 1.0                                 # slab through the box in x and z
    v, f = structure_mesh(dens, spacing=0.5)
    info = mesh_summary(v, f)
    assert info["watertight"] and info["volume"] > 0
    np.testing.assert_allclose(info["bounds"][0], [0.0, 1.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(info["bounds"][1], [5.0, 3.0, 3.0], atol=1e-9)


def test_png_and_stl_writers(tmp_path):
    from PIL import Image

    dens = np.zeros((6, 8))
    dens[0, :3] = 1.0                                    # bottom row (y = 0), left
    save_structure_png(tmp_path / "s.png", dens, level=0.5)
    img = np.asarray(Image.open(tmp_path / "s.png"))
    assert img.shape == (6, 8) and img.dtype == np.uint8
    assert (img[-1, :3] == 0).all() and (img[-1, 3:] == 255).all() and (img[:-1] == 255).all()
    save_structure_png(tmp_path / "g.png", dens * 0.5)
    assert np.asarray(Image.open(tmp_path / "g.png"))[-1, 0] == 128
    cube = np.zeros((6, 6, 6))
    cube[1:5, 1:5, 1:5] = 1.0
    save_structure_stl(tmp_path / "s.stl", cube)
    v, f = load_mesh(tmp_path / "s.stl")
    assert mesh_summary(v, f)["watertight"]
    with pytest.raises(ValueError, match="no solid"):
        save_structure_stl(tmp_path / "e.stl", np.zeros((4, 4, 4)))


def test_bad_inputs_are_refused_by_name():
    s = _stripes(rows=4)
    with pytest.raises(ValueError, match="structures must hold one field per grid dimension"):
        compile_structure([s], mu=0.2)
    with pytest.raises(ValueError, match=r"mu must be one number, or 2"):
        compile_structure([s, s], mu=(0.1, 0.2, 0.3))
    with pytest.raises(ValueError, match=r"structures\[1\] must lie in \[0, 1\]"):
        compile_structure([s, s * 2], mu=0.2)
    with pytest.raises(ValueError, match="rho must have the grid shape"):
        compile_structure([s, s], mu=0.2, rho=np.ones((2, 2)))
    with pytest.raises(ValueError, match="delta"):
        rescale_pattern(s, mu=0.2, delta=0.7)
