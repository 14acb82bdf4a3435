"""Cell hashes: numpy against a plain-Python-integer reference and against the GLSL, bit for bit."""

import numpy as np
import pytest

from engine.implicit import cell_hash as ch

M = 0xFFFFFFFF


def ref_pcg(v: int) -> int:
    """PCG hash on Python ints, masking every step by hand."""
    state = (v * 747796405 + 2891336453) & M
    word = (((state >> ((state >> 28) + 4)) ^ state) * 277803737) & M
    return (word >> 22) ^ word


def ref_key(i, j, k, word):
    return (i * ch.P1 + j * ch.P2 + k * ch.P3 + word) & M      # Python % works for negatives


def ref_xorshift(x):
    x ^= (x << 13) & M
    x ^= x >> 17
    return x ^ ((x << 5) & M)


def ref_xorshift_key(i, j, k, word):
    x = ref_xorshift(word ^ 0x9E3779B9)
    for c in (i, j, k):
        x = ref_xorshift(x ^ (c & M))
    return x


def _cells(n, seed=0):
    rng = np.random.default_rng(seed)
    small = rng.integers(-50, 50, (n, 3))
    big = rng.integers(-2 ** 31, 2 ** 31, (n, 3))
    edge = np.array([[0, 0, 0], [-1, -1, -1], [2 ** 31 - 1, -2 ** 31, 0], [-2 ** 31, 2 ** 31 - 1, -1]])
    return np.concatenate([small, big, edge]).astype(np.int64)


def test_numpy_matches_python_integers():
    cells = _cells(300)
    word = ch.seed_word(12345)
    key = ch.cell_key(cells[:, 0], cells[:, 1], cells[:, 2], word)
    stream = ch.cell_stream(cells[:, 0], cells[:, 1], cells[:, 2], word)
    xk = ch.xorshift_key(cells[:, 0], cells[:, 1], cells[:, 2], word)
    u5 = ch.cell_uniform(stream, 5)
    for n, (i, j, k) in enumerate(cells.tolist()):
        kk = ref_key(i, j, k, word)
        assert key[n] == kk
        assert stream[n] == ref_pcg(kk)
        assert u5[n] == (ref_pcg((ref_pcg(kk) + 5) & M) >> 8) / 2 ** 24
        assert xk[n] == ref_xorshift_key(i, j, k, word)
    assert key.dtype == stream.dtype == xk.dtype == np.uint32


def test_seed_word():
    assert ch.seed_word(7) == ch.seed_word(np.int64(7))
    words = {ch.seed_word(s) for s in [0, 1, 2, -1, 2 ** 40, 2 ** 40 + 1, 99]}
    assert len(words) == 7 and all(0 <= w <= M for w in words)
    for bad in (1.5, "3", True, None):
        with pytest.raises(ValueError, match="seed must be an int"):
            ch.seed_word(bad)


def test_no_key_collisions_in_a_block():
    a = np.arange(-20, 20)
    i, j, k = (v.ravel() for v in np.meshgrid(a, a, a, indexing="ij"))
    for word in (0, ch.seed_word(3)):
        assert len(np.unique(ch.cell_key(i, j, k, word))) == i.size
        assert len(np.unique(ch.xorshift_key(i, j, k, word))) == i.size


def test_uniforms_are_uniform_and_independent():
    a = np.arange(-16, 16)
    i, j, k = (v.ravel() for v in np.meshgrid(a, a, a, indexing="ij"))
    stream = ch.cell_stream(i, j, k, ch.seed_word(1))
    u = np.stack([ch.cell_uniform(stream, r) for r in range(4)])
    n = i.size
    assert u.min() >= 0.0 and u.max() < 1.0
    # chi-square over 16 bins, each draw: 15 dof, 99.99% quantile ~ 44
    for row in u:
        counts = np.bincount((row * 16).astype(int), minlength=16)
        assert np.sum((counts - n / 16) ** 2 / (n / 16)) < 44
    # draws of one cell, and neighbouring cells, are uncorrelated (|r| < 4 / sqrt(n))
    assert np.abs(np.corrcoef(u)[np.triu_indices(4, 1)]).max() < 4 / np.sqrt(n)
    grid = u[0].reshape(32, 32, 32)
    for ax in range(3):
        r = np.corrcoef(grid.take(range(31), ax).ravel(), grid.take(range(1, 32), ax).ravel())[0, 1]
        assert abs(r) < 4 / np.sqrt(grid.size)
    # another seed gives other numbers
    other = ch.cell_uniform(ch.cell_stream(i, j, k, ch.seed_word(2)), 0)
    assert np.mean(other == u[0]) < 0.01


def test_xorshift_is_a_bijection_on_a_sample():
    x = np.random.default_rng(0).choice(2 ** 32 - 1, 200000, replace=False).astype(np.uint32) + 1
    y = ch.xorshift32(x)
    assert len(np.unique(y)) == len(x) and np.all(y != 0)
    assert ch.xorshift32(np.uint32(0)) == 0


_SHADER = """#version 430
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Cells { int cells[]; };
layout(std430, binding = 1) writeonly buffer Out { uint outs[]; };
uniform uint u_count;
uniform uint u_word;

%s

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    ivec3 c = ivec3(cells[3u * i], cells[3u * i + 1u], cells[3u * i + 2u]);
    uint st = mf_cell_stream(c, u_word);
    outs[5u * i] = mf_cell_key(c, u_word);
    outs[5u * i + 1u] = st;
    outs[5u * i + 2u] = floatBitsToUint(mf_cell_uniform(st, 0u));
    outs[5u * i + 3u] = floatBitsToUint(mf_cell_uniform(st, 8u));
    outs[5u * i + 4u] = mf_xorshift_key(c, u_word);
}
"""


@pytest.mark.parametrize("seed", [0, 987654321, -5])
def test_glsl_gives_identical_bits(gpu, seed):
    from engine.gpu.context import gpu_session
    cells = _cells(20000, seed=abs(seed) % 7)
    word = ch.seed_word(seed)
    n = len(cells)
    with gpu_session() as ctx:
        prog = ctx.compute_shader(_SHADER % ch.GLSL_HASH)
        inp = ctx.buffer(cells.astype(np.int32).tobytes())
        out = ctx.buffer(reserve=4 * 5 * n)
        try:
            inp.bind_to_storage_buffer(0)
            out.bind_to_storage_buffer(1)
            prog["u_count"].value = n
            prog["u_word"].value = word
            prog.run(-(-n // 64))
            ctx.memory_barrier()
            got = np.frombuffer(out.read(), dtype=np.uint32).reshape(n, 5)
        finally:
            out.release()
            inp.release()
            prog.release()
    i, j, k = cells.T
    stream = ch.cell_stream(i, j, k, word)
    np.testing.assert_array_equal(got[:, 0], ch.cell_key(i, j, k, word))
    np.testing.assert_array_equal(got[:, 1], stream)
    np.testing.assert_array_equal(got[:, 2], ch.cell_uniform(stream, 0).astype(np.float32).view(np.uint32))
    np.testing.assert_array_equal(got[:, 3], ch.cell_uniform(stream, 8).astype(np.float32).view(np.uint32))
    np.testing.assert_array_equal(got[:, 4], ch.xorshift_key(i, j, k, word))
