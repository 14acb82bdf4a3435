"""Analysis by synthesis: a gyroid cell recovered from a render of it, the image loss
scanned by brute force, cancel, image files and bad input.

References: the known cell the target was rendered with, a brute-force scan of eq. 39
over independent renders, the raw `render` pixels (not `render_image`), and arrays
written to files here.  Budgets are evaluation counts (no wall-time asserts)."""

import math

import numpy as np
import pytest
import tifffile
from PIL import Image

from engine.gpu.camera import Camera
from engine.gpu.image_fit import as_image, fit_image, load_image_exemplar
from engine.gpu.sphere_trace import render
from engine.implicit.combine import Intersection
from engine.implicit.fourier_loss import image_loss
from engine.implicit.periodic import Periodic
from engine.implicit.reconstruct import ParamSpace
from engine.implicit.shapes import Primitive
from engine.progress import Cancelled

TRUE_CELL = 0.85
SIZE = 48
CAMERA = Camera((4.0, -5.0, 3.5), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 35.0)
BOX = Primitive("box", (1.5, 1.5, 1.5))
FLOOR = math.log(1e-8)


def _scene(v):
    """Gyroid [1D] cut to a 3 mm cube: the solid gyroid network of cell v[0] inside a box."""
    return Intersection((Periodic(kind="gyroid", cell=float(v[0])), BOX))


SPACE = ParamSpace(("cell",), (0.6,), (1.6,), _scene)


def _frame(cell):
    """The raw uint8 RGBA of a lambert render (the renderer, not fit_image's conversion)."""
    return render(_scene([cell]), CAMERA, SIZE, SIZE, shading="lambert").rgba


@pytest.fixture(scope="module")
def target(gpu):
    rgba = _frame(TRUE_CELL)
    # lambert shading is grey: R = G = B, so the red channel is the grey image
    assert np.array_equal(rgba[..., 0], rgba[..., 1]) and np.array_equal(rgba[..., 0], rgba[..., 2])
    assert 0.3 < np.mean(rgba[..., 3] > 0) < 0.9          # the cube fills a good part of the frame
    return rgba


def test_cmaes_recovers_the_cell_from_an_rgb_image(target):
    r = fit_image(SPACE, target[..., :3], CAMERA, "cmaes", math.inf, max_evaluations=120, seed=0)
    assert r.evaluations <= 120 and r.names == ("cell",)
    assert abs(r.params[0] - TRUE_CELL) / TRUE_CELL < 0.02, r.params
    assert r.stopped_by in ("converged", "budget")


def test_powell_recovers_the_cell_from_a_grey_image(target):
    grey = target[..., 0]                                  # (h, w) uint8
    r = fit_image(SPACE, grey, CAMERA, "powell", math.inf, max_evaluations=80)
    assert r.evaluations <= 80
    assert abs(r.params[0] - TRUE_CELL) / TRUE_CELL < 0.02, r.params


def test_loss_scan_is_minimal_at_the_truth(target):
    grey = target[..., 0] / 255.0
    cells = np.linspace(0.6, 1.6, 41)                      # includes 0.85 (step 0.025)
    assert np.any(np.isclose(cells, TRUE_CELL))
    losses = [image_loss(_frame(c)[..., 0] / 255.0, grey) for c in cells]
    best = int(np.argmin(losses))
    assert cells[best] == pytest.approx(TRUE_CELL)
    assert losses[best] == pytest.approx(FLOOR)            # the same render: equal spectra
    assert np.sort(losses)[1] > FLOOR + 5                  # nothing else comes close
    # a fit started at the truth converges on its first render
    r = fit_image(SPACE, target[..., 0], CAMERA, "powell", math.inf, x0=[TRUE_CELL], max_evaluations=5)
    assert r.stopped_by == "converged" and r.evaluations == 1 and r.loss == pytest.approx(FLOOR)


def test_rgba_target_with_ssim_at_truth(target):
    r = fit_image(SPACE, target, CAMERA, "powell", math.inf, x0=[TRUE_CELL], ssim_weight=0.5,
                  max_evaluations=5)                       # powell renders x0 first
    assert r.stopped_by == "converged" and r.evaluations == 1
    # off the truth the SSIM term adds to eq. 39 (recomputed here)
    calls = []
    fit_image(SPACE, target, CAMERA, "powell", math.inf, x0=[1.2], ssim_weight=0.5, max_evaluations=1,
              progress=lambda f, loss, x: calls.append(loss))
    img = _frame(1.2) / 255.0
    base = image_loss(img, target / 255.0)
    assert calls[0] == pytest.approx(image_loss(img, target / 255.0, ssim_weight=0.5, data_range=1.0))
    assert calls[0] > base


def test_cancel_returns_the_best_so_far(target):
    count = {"n": 0}

    def check():
        count["n"] += 1
        if count["n"] > 9:
            raise Cancelled("stop")

    seen = []
    r = fit_image(SPACE, target[..., :3], CAMERA, "cmaes", math.inf, check=check,
                  progress=lambda f, loss, x: seen.append(loss))
    assert r.stopped_by == "cancel" and 1 <= r.evaluations < 9
    assert len(seen) == r.evaluations + 1 and r.loss == min(seen)
    # the returned cell really has the returned loss (rendered again here)
    again = image_loss(_frame(r.params[0])[..., :3] / 255.0, target[..., :3] / 255.0)
    assert again == pytest.approx(r.loss, abs=1e-9)


def test_cancel_before_any_render_returns_x0(target):
    def check():
        raise Cancelled("now")
    r = fit_image(SPACE, target, CAMERA, "powell", 5.0, x0=[1.3], check=check)
    assert r.stopped_by == "cancel" and r.evaluations == 0 and r.loss == math.inf
    np.testing.assert_array_equal(r.params, [1.3])


def test_bad_input_refused(target):
    grey = target[..., 0]
    for bad in (np.zeros((SIZE, SIZE, 2), np.uint8), np.zeros(SIZE, np.uint8),
                np.zeros((2, SIZE, SIZE, 3), np.uint8), np.zeros((1, SIZE), np.uint8)):
        with pytest.raises(ValueError, match="target"):
            fit_image(SPACE, bad, CAMERA, "cmaes", 1.0)
    with pytest.raises(ValueError, match="NaN"):
        fit_image(SPACE, np.full((SIZE, SIZE), np.nan), CAMERA, "cmaes", 1.0)
    for budget in (0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="budget_s"):
            fit_image(SPACE, grey, CAMERA, "cmaes", budget)
    with pytest.raises(ValueError, match="camera"):
        fit_image(SPACE, grey, "4,-5,3.5,0,0,0,35", "cmaes", 1.0)
    with pytest.raises(ValueError, match="step"):
        fit_image(SPACE, grey, CAMERA, "cmaes", 1.0, step="huge")
    with pytest.raises(ValueError, match="shading"):
        fit_image(SPACE, grey, CAMERA, "cmaes", 1.0, shading="phong")
    with pytest.raises(ValueError, match="ssim_weight"):
        fit_image(SPACE, grey, CAMERA, "cmaes", 1.0, ssim_weight=-1)
    with pytest.raises(ValueError, match="7 x 7"):
        fit_image(SPACE, grey[:5, :5], CAMERA, "cmaes", 1.0, ssim_weight=1)
    with pytest.raises(ValueError, match="algorithm"):
        fit_image(SPACE, grey, CAMERA, "nelder-mead", 1.0)
    with pytest.raises(ValueError, match="'cell'"):
        fit_image(SPACE, grey, CAMERA, "powell", 1.0, x0=[3.0])
    with pytest.raises(ValueError, match="make"):
        fit_image(ParamSpace(("cell",), (0.6,), (1.6,)), grey, CAMERA, "powell", 1.0)


def test_as_image_scales_by_dtype():
    a = np.array([[0, 51], [255, 102]], np.uint8)
    np.testing.assert_array_equal(as_image(a), a / 255.0)
    b = np.array([[0, 65535], [1000, 7]], np.uint16)
    np.testing.assert_array_equal(as_image(b), b / 65535.0)
    np.testing.assert_array_equal(as_image(np.eye(3, dtype=bool)), np.eye(3))
    f = np.full((3, 4, 1), 0.25, np.float32)
    assert as_image(f).shape == (3, 4) and np.all(as_image(f) == 0.25)
    with pytest.raises(ValueError, match="0..65535"):
        as_image(np.array([[-1, 2], [3, 4]]))


def test_load_image_exemplar_png_and_tiff(tmp_path):
    rng = np.random.default_rng(5)
    grey = rng.integers(0, 256, (9, 11), dtype=np.uint8)
    rgb = rng.integers(0, 256, (9, 11, 3), dtype=np.uint8)
    rgba = rng.integers(0, 256, (9, 11, 4), dtype=np.uint8)
    deep = rng.integers(0, 65536, (9, 11), dtype=np.uint16)
    for name, arr in (("g.png", grey), ("c.png", rgb), ("a.png", rgba)):
        Image.fromarray(arr).save(tmp_path / name)
        got = load_image_exemplar(tmp_path / name)
        assert got.dtype == np.float64 and got.shape == arr.shape
        np.testing.assert_array_equal(got, arr / 255.0)
    tifffile.imwrite(tmp_path / "d.tif", deep)
    np.testing.assert_array_equal(load_image_exemplar(tmp_path / "d.tif"), deep / 65535.0)
    tifffile.imwrite(tmp_path / "c.tiff", rgb)
    np.testing.assert_array_equal(load_image_exemplar(tmp_path / "c.tiff"), rgb / 255.0)
    pal = Image.fromarray(grey).convert("P")
    pal.save(tmp_path / "p.png")
    expect = np.asarray(pal.convert("RGB")) / 255.0
    np.testing.assert_array_equal(load_image_exemplar(tmp_path / "p.png"), expect)


def test_load_image_exemplar_refuses_naming_the_file(tmp_path):
    stack = tmp_path / "stack.tif"
    tifffile.imwrite(stack, np.zeros((5, 9, 11), np.uint8))            # five pages
    with pytest.raises(ValueError, match="stack.tif.*shape"):
        load_image_exemplar(stack)
    la = tmp_path / "la.png"
    Image.fromarray(np.zeros((9, 11, 2), np.uint8)).save(la)          # grey + alpha
    with pytest.raises(ValueError, match="la.png.*shape"):
        load_image_exemplar(la)
    bad = tmp_path / "broken.png"
    bad.write_bytes(b"not a png")
    with pytest.raises(ValueError, match="broken.png.*cannot read"):
        load_image_exemplar(bad)
    with pytest.raises(ValueError, match="missing.png.*no such file"):
        load_image_exemplar(tmp_path / "missing.png")
    with pytest.raises(ValueError, match="x.npy.*unknown image format"):
        load_image_exemplar(tmp_path / "x.npy")
