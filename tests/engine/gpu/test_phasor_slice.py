"""The phasor-slice shader against float64 references: a brute-force sum over
every kernel written here from the formulas in engine/phasor/kernels.py, and
engine.phasor.noise (the project's reference evaluator)."""

import math
import threading

import numpy as np
import pytest

import engine.phasor.gpu_slice as ps
from engine.progress import Cancelled
from engine.gpu import SlicePlane
from engine.phasor.gpu_slice import diamond_mask, phasor_slice_gpu, sawtooth
from engine.phasor.attenuation import attenuation_grid
from engine.phasor.fields import PhasorFields, constant_fields, trilinear
from engine.phasor.kernels import PhasorKernels
from engine.phasor.noise import phasor_complex
from engine.phasor.sampling import sample_kernels

PHASE_TOL = 1e-4      # rad, wrapped, where |G| > SIGNIFICANT * max|G|
SIGNIFICANT = 1e-2
ABS_TOL = 1e-5        # |G - G_ref| / max|G| everywhere
ORIGIN = np.array([-2.0, -1.0, 0.5])


# ------------------------------------------------------- brute-force reference

def frame(d):
    """Unit v = z x D, w = v x D; where D is vertical v = x - (x.D) D, normalised."""
    v = np.stack([-d[:, 1], d[:, 0], np.zeros(len(d))], axis=1)
    vertical = np.linalg.norm(v, axis=1) < 1e-6
    v[vertical] = np.array([1.0, 0.0, 0.0]) - d[vertical, :1] * d[vertical]
    v /= np.linalg.norm(v, axis=1)[:, None]
    w = np.cross(v, d)
    return v, w / np.linalg.norm(w, axis=1)[:, None]


def brute(kernels, points, *, fields=None, filtered=False, filter_scale=2.0, attenuation=None):
    """(G_v, G_w, ambiguous): every kernel against every point, float64.

    ``ambiguous`` marks points with a kernel within 1e-5 (relative) of the
    truncation sphere, where float32 and float64 may disagree on inclusion.
    """
    shape = points.shape[:-1]
    x = points.reshape(-1, 3)
    R = kernels.radius
    b = math.pi / R ** 2
    r = x[:, None, :] - kernels.positions[None]
    r2 = np.einsum("pnk,pnk->pn", r, r)
    if filtered:
        a = b / filter_scale ** 2
        reach2 = (a + b) / (a * b) * b * R ** 2
        f = fields.sample_frequency(x)
        e = frame(fields.sample_direction(x))
        A = np.ones(len(x)) if attenuation is None else trilinear(attenuation, fields.lo, fields.hi, x)
    else:
        reach2 = R ** 2
    out = []
    for k, (d, phi) in enumerate(((kernels.direction_v, kernels.phase_v), (kernels.direction_w, kernels.phase_w))):
        fd = kernels.frequency[:, None] * d
        if filtered:
            delta = A[:, None, None] * (fd[None] - (f[:, None] * e[k])[:, None, :])
            env = np.exp(-(a * b / (a + b)) * r2 - math.pi ** 2 * np.einsum("pnk,pnk->pn", delta, delta) / (a + b))
            g = fd[None] - (b / (a + b)) * delta
            phase = 2 * math.pi * np.einsum("pnk,pnk->pn", g, r) + phi
        else:
            env = np.exp(-b * r2)
            phase = 2 * math.pi * np.einsum("pnk,nk->pn", r, fd) + phi
        out.append(np.sum(np.where(r2 < reach2, env * np.exp(1j * phase), 0), axis=1).reshape(shape))
    ambiguous = (np.abs(r2 / reach2 - 1).min(axis=1) < 1e-5).reshape(shape)
    return out[0], out[1], ambiguous


def random_kernels(seed, *, fields=None, grid=(4, 4, 3), radius=4.5, jitter=0.15):
    """Kernels on a small grid, 0-12 per cell; oscillators near the local
    frame of ``fields`` (so filtered terms matter) or fully random."""
    rng = np.random.default_rng(seed)
    grid = np.asarray(grid)
    counts = rng.integers(0, 13, int(np.prod(grid)))
    cell = np.repeat(np.arange(len(counts)), counts)
    ijk = np.stack([cell % grid[0], (cell // grid[0]) % grid[1], cell // (grid[0] * grid[1])], axis=1)
    n = len(cell)
    pos = ORIGIN + (ijk + rng.random((n, 3))) * radius
    if fields is None:
        freq, dv, dw = rng.uniform(0.7, 1.6, n), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    else:
        freq = fields.sample_frequency(pos) * (1 + 0.05 * rng.normal(size=n))
        dv, dw = frame(fields.sample_direction(pos))
        dv, dw = dv + jitter * rng.normal(size=(n, 3)), dw + jitter * rng.normal(size=(n, 3))
    dv /= np.linalg.norm(dv, axis=1)[:, None]
    dw /= np.linalg.norm(dw, axis=1)[:, None]
    return PhasorKernels(ORIGIN, radius, grid, np.concatenate([[0], np.cumsum(counts)]), pos, freq, dv, dw,
                         rng.uniform(0, 2 * math.pi, n), rng.uniform(-20, 20, n), rng.uniform(-1, 1, n))


def turning_fields(shape=(4, 5, 6), *, vertical=False):
    """D turns about z and tilts across the box, F varies by +-30 %."""
    nz, ny, nx = shape
    Z, Y, X = np.meshgrid(*[(np.arange(n) + 0.5) / n for n in shape], indexing="ij")
    ang, tilt = 0.6 * (X + 0.5 * Y), 0.4 * (Z - 0.5)
    D = np.stack([np.cos(ang) * np.cos(tilt), np.sin(ang) * np.cos(tilt), np.sin(tilt)], axis=-1)
    if vertical:  # D exactly along +-z in half the cells
        D[:, :, : nx // 2] = [0.0, 0.0, 1.0]
        D[0, :, : nx // 2] = [0.0, 0.0, -1.0]
    return PhasorFields(D, 1.0 + 0.3 * (X - 0.5 * Z), np.zeros(shape), ORIGIN, ORIGIN + [18.0, 18.0, 13.5])


PLANES = {
    "z": SlicePlane.axis_aligned("z", 6.3, 0.25, ((-3.0, 13.0), (-2.0, 14.0))),
    "x": SlicePlane.axis_aligned("x", 7.1, 0.2, ((0.0, 12.8), (1.0, 13.8))),
    "oblique": SlicePlane([-1.0, 2.0, 1.0], [0.8, 0.6, 0.0], [-0.36, 0.48, 0.8], (15.0, 14.0), (64, 60)),
}


def assert_close(g, ref, skip=None):
    """Wrapped phase within PHASE_TOL where |G| is significant; |G - ref| small everywhere."""
    ref = np.asarray(ref, np.complex128)
    scale = np.abs(ref).max()
    assert scale > 0.5
    ok = np.ones(ref.shape, bool) if skip is None else ~skip
    assert np.abs(g - ref)[ok].max() <= ABS_TOL * scale
    significant = ok & (np.abs(ref) > SIGNIFICANT * scale)
    assert significant.mean() > 0.8
    dphi = np.abs(np.angle(g.astype(np.complex128) * np.conj(ref)))[significant]
    assert dphi.max() <= PHASE_TOL, f"max phase error {dphi.max():.3g} rad"


# ------------------------------------------------------------------ accuracy

@pytest.mark.parametrize("plane", PLANES.values(), ids=PLANES.keys())
def test_unfiltered_matches_brute_force(gpu, plane):
    k = random_kernels(1)
    g_v, g_w = phasor_slice_gpu(k, plane)
    assert g_v.shape == plane.shape and g_v.dtype == np.complex64
    b_v, b_w, amb = brute(k, plane.points())
    assert_close(g_v, b_v, amb)
    assert_close(g_w, b_w, amb)


@pytest.mark.parametrize("attenuated", [False, True])
@pytest.mark.parametrize("plane", PLANES.values(), ids=PLANES.keys())
def test_filtered_matches_brute_force(gpu, plane, attenuated):
    fields = turning_fields()
    k = random_kernels(2, fields=fields)
    att = np.random.default_rng(3).random(fields.shape) if attenuated else None
    g_v, g_w = phasor_slice_gpu(k, plane, fields=fields, filtered=True, attenuation=att)
    b_v, b_w, amb = brute(k, plane.points(), fields=fields, filtered=True, attenuation=att)
    assert_close(g_v, b_v, amb)
    assert_close(g_w, b_w, amb)


def test_filtered_vertical_direction_and_other_scale(gpu):
    fields = turning_fields(vertical=True)
    k = random_kernels(4, fields=fields)
    plane = PLANES["oblique"]
    g_v, g_w = phasor_slice_gpu(k, plane, fields=fields, filtered=True, filter_scale=1.3)
    b_v, b_w, amb = brute(k, plane.points(), fields=fields, filtered=True, filter_scale=1.3)
    assert_close(g_v, b_v, amb)
    assert_close(g_w, b_w, amb)


@pytest.mark.parametrize("filtered", [False, True])
@pytest.mark.parametrize("plane", PLANES.values(), ids=PLANES.keys())
def test_matches_engine_reference(gpu, plane, filtered):
    """Sampled kernels, the attenuation grid of engine.phasor.attenuation."""
    fields = turning_fields()
    k = sample_kernels(fields, rng=5)
    rng = np.random.default_rng(5)
    k = k.with_phases(rng.uniform(-np.pi, np.pi, k.n), rng.uniform(-np.pi, np.pi, k.n))
    options = dict(fields=fields, filtered=filtered)
    if filtered:
        options["attenuation"] = attenuation_grid(fields, radius=k.radius)
    g_v, g_w = phasor_slice_gpu(k, plane, **options)
    r_v, r_w = phasor_complex(k, plane.points(), **options)
    amb = brute(k, plane.points()[::4, ::4], **options)[2]
    skip = np.zeros(plane.shape, bool)
    skip[::4, ::4] = amb  # a cheap spot check that truncation ties are rare
    assert_close(g_v, r_v, skip)
    assert_close(g_w, r_w, skip)


# ------------------------------------------------------------ invariants

def test_same_inputs_same_bytes(gpu):
    fields = turning_fields()
    k = random_kernels(6, fields=fields)
    first = phasor_slice_gpu(k, PLANES["oblique"], fields=fields, filtered=True)
    second = phasor_slice_gpu(k, PLANES["oblique"], fields=fields, filtered=True)
    for a, b in zip(first, second):
        assert a.tobytes() == b.tobytes()


def test_tiling_does_not_change_the_sums(gpu):
    """Tiles only regroup the per-pixel sums (same kernels, same order)."""
    k = random_kernels(7)
    plane = PLANES["z"]
    whole = phasor_slice_gpu(k, plane, tile=256)
    tiled = phasor_slice_gpu(k, plane, tile=24)
    for a, b in zip(whole, tiled):
        assert a.tobytes() == b.tobytes()


def test_kernel_chunks_accumulate(gpu, monkeypatch):
    """More kernels than one uniform block holds: several passes per tile."""
    k = random_kernels(8)
    plane = PLANES["x"]
    whole = phasor_slice_gpu(k, plane)
    monkeypatch.setattr(ps, "_capacity", lambda ctx: 64)
    chunked = phasor_slice_gpu(k, plane)
    assert k.n > 3 * 64
    for a, b in zip(whole, chunked):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.abs(a).max())


def test_no_kernel_in_reach_gives_zero(gpu):
    k = random_kernels(9)
    far = SlicePlane.axis_aligned("z", 100.0, 0.5, ((0.0, 8.0), (0.0, 8.0)))
    g_v, g_w = phasor_slice_gpu(k, far)
    assert not g_v.any() and not g_w.any()


def test_outputs_sawtooth_and_mask(gpu):
    k = random_kernels(10)
    plane = PLANES["z"]
    g_v, g_w = phasor_slice_gpu(k, plane)
    p_v, p_w = phasor_slice_gpu(k, plane, out="sawtooth")
    assert p_v.dtype == np.float32 and 0 <= p_v.min() and p_v.max() < 1
    np.testing.assert_array_equal(p_v, sawtooth(g_v))
    np.testing.assert_array_equal(p_w, sawtooth(g_w))
    mask = phasor_slice_gpu(k, plane, out="mask")
    np.testing.assert_array_equal(mask, diamond_mask(p_v, p_w))
    assert 0.2 < mask.mean() < 0.8


def test_sawtooth_and_mask_values():
    g = np.array([1, 1j, -1, -1j, 0, np.exp(-1e-9j)], np.complex64)
    np.testing.assert_allclose(sawtooth(g), [0, 0.25, 0.5, 0.75, 0, 0], atol=1e-6)
    assert diamond_mask(np.array([0.5, 0.5, 0.0]), np.array([0.5, 0.9, 0.5])).tolist() == [True, True, False]


# ------------------------------------------------------ progress and threads

def test_progress_reports_every_tile(gpu):
    calls = []
    phasor_slice_gpu(random_kernels(11), PLANES["z"], tile=32, progress=lambda d, t: calls.append((d, t)) or True)
    assert calls == [(i, 4) for i in range(5)]


def test_cancel_between_tiles_raises(gpu):
    calls = []

    def progress(done, total):
        calls.append(done)
        return done < 2

    with pytest.raises(Cancelled):
        phasor_slice_gpu(random_kernels(12), PLANES["z"], tile=16, progress=progress)
    assert calls == [0, 1, 2]
    phasor_slice_gpu(random_kernels(12), PLANES["z"])  # the context is still usable


def test_worker_threads_share_the_context(gpu):
    k = random_kernels(13)
    expected = phasor_slice_gpu(k, PLANES["z"])
    results = [None] * 3

    def work(i):
        results[i] = phasor_slice_gpu(k, PLANES["z"])

    threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert r[0].tobytes() == expected[0].tobytes()


# ---------------------------------------------------------------- refusals

def test_bad_arguments_are_refused():
    k = random_kernels(14)
    plane = PLANES["z"]
    fields = constant_fields(ORIGIN, ORIGIN + 10, (2, 2, 2))
    with pytest.raises(ValueError, match="out"):
        phasor_slice_gpu(k, plane, out="phase")
    with pytest.raises(ValueError, match="fields"):
        phasor_slice_gpu(k, plane, filtered=True)
    with pytest.raises(ValueError, match="attenuation"):
        phasor_slice_gpu(k, plane, fields=fields, filtered=True, attenuation=np.ones((3, 3, 3)))
    with pytest.raises(ValueError, match="attenuation"):
        phasor_slice_gpu(k, plane, fields=fields, filtered=True, attenuation=np.full((2, 2, 2), 1.5))
    with pytest.raises(ValueError, match="filter_scale"):
        phasor_slice_gpu(k, plane, fields=fields, filtered=True, filter_scale=0)
    with pytest.raises(TypeError, match="plane"):
        phasor_slice_gpu(k, (0, 0, 1))
    with pytest.raises(TypeError, match="kernels"):
        phasor_slice_gpu("kernels", plane)
