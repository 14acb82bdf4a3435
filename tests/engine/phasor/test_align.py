import numpy as np
import pytest

from engine.progress import Cancelled
from engine.phasor.align import align_phases, alignment_step_reference
from engine.phasor.fields import PhasorFields, constant_fields
from engine.phasor.sampling import sample_kernels


def _wrapped(a, b):
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def _random_kernels(seed=0):
    rng = np.random.default_rng(seed)
    shape = (2, 3, 3)
    d = rng.normal(size=shape + (3,))
    d /= np.linalg.norm(d, axis=-1)[..., None]
    fields = PhasorFields(d, rng.uniform(1.0, 1.5, shape), rng.uniform(0, 0.8, shape),
                          (0, 0, 0), (10.0, 9.0, 5.0))
    k = sample_kernels(fields, rng=seed)
    return k.with_phases(rng.uniform(-np.pi, np.pi, k.n), rng.uniform(-np.pi, np.pi, k.n)), rng


@pytest.mark.parametrize("include_self", [True, False])
def test_one_iteration_equals_the_plain_all_pairs_reference(include_self):
    k, rng = _random_kernels(1)
    active = rng.random(k.n) < 0.6
    for mask in (None, active):
        fast = align_phases(k, iterations=1, include_self=include_self, active=mask)
        ref_v, ref_w = alignment_step_reference(k, include_self=include_self, active=mask)
        assert _wrapped(fast.phase_v, ref_v).max() < 1e-12
        assert _wrapped(fast.phase_w, ref_w).max() < 1e-12


def test_iterations_are_jacobi_sweeps_from_the_previous_phases():
    k, _ = _random_kernels(2)
    fast = align_phases(k, iterations=3)
    ref = k
    for _ in range(3):
        ref = ref.with_phases(*alignment_step_reference(ref))
    assert _wrapped(fast.phase_v, ref.phase_v).max() < 1e-10
    assert _wrapped(fast.phase_w, ref.phase_w).max() < 1e-10
    assert align_phases(k, iterations=0).phase_v.tobytes() == k.phase_v.tobytes()


def _coherence(k):
    """|mean of e^{i(phi_j - phi_i - 2 pi f d . (x_j - x_i))}| over close pairs (1 = one global wave)."""
    p = k.positions
    r = p[:, None, :] - p[None, :, :]
    close = (np.sum(r * r, axis=-1) < k.radius ** 2) & ~np.eye(k.n, dtype=bool)
    j, i = np.nonzero(close)
    lag = 2 * np.pi * k.frequency[i] * np.sum(k.direction_v[i] * (p[j] - p[i]), axis=1)
    return abs(np.mean(np.exp(1j * (k.phase_v[j] - k.phase_v[i] - lag))))


def test_alignment_makes_a_constant_field_one_coherent_wave_with_or_without_the_self_term():
    fields = constant_fields((0, 0, 0), (18, 18, 6), (1, 1, 1), direction=(1, 0, 0), frequency=1.0)
    k = sample_kernels(fields, rng=3)
    with_self = align_phases(k)
    without = align_phases(k, include_self=False)
    c0, c1, c2 = _coherence(k), _coherence(with_self), _coherence(without)
    print(f"\nneighbour coherence: raw {c0:.3f}, aligned {c1:.3f} (self in), {c2:.3f} (self out)")
    assert c0 < 0.1 and c1 > 0.85 and c2 > 0.85
    assert abs(c1 - c2) < 0.05  # the self term is a small inertia among ~33 neighbours


def test_inactive_sites_keep_their_phases_bit_for_bit():
    k, rng = _random_kernels(4)
    active = np.zeros(k.n, dtype=bool)
    active[rng.choice(k.n, 20, replace=False)] = True
    out = align_phases(k, iterations=5, active=active)
    assert out.phase_v[~active].tobytes() == k.phase_v[~active].tobytes()
    assert out.phase_w[~active].tobytes() == k.phase_w[~active].tobytes()
    assert np.all(_wrapped(out.phase_v[active], k.phase_v[active]) > 0)


def test_progress_reaches_the_end_and_false_cancels():
    k, _ = _random_kernels(5)
    seen = []
    align_phases(k, iterations=2, progress=lambda d, t: seen.append((d, t)) or True)
    assert seen[0] == (0, 2 * k.n) and seen[-1] == (2 * k.n, 2 * k.n)
    assert all(b[0] >= a[0] for a, b in zip(seen, seen[1:]))
    with pytest.raises(Cancelled):
        align_phases(k, iterations=3, progress=lambda d, t: d < k.n)


def test_bad_options_are_refused_by_name():
    k, _ = _random_kernels(6)
    with pytest.raises(ValueError, match="iterations"):
        align_phases(k, iterations=-1)
    with pytest.raises(ValueError, match="active"):
        align_phases(k, active=np.ones(3, dtype=bool))
