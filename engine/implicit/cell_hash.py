"""Hashes of grid cells and a per-cell stream of uniforms, bit-identical in numpy and GLSL.

Paper 004 (section 3.1.1, eqs. 1-3) seeds a PRNG per grid cell from a
multilinear spatial hash of the cell index with prime coefficients.  Here:

* ``key = P1 i + P2 j + P3 k + w(seed)``  (mod 2^32, the multilinear hash;
  i, j, k are taken as 32-bit two's complement, so negative cells work);
* ``stream = pcg(key)``: the cell's PRNG state (the paper multiplies the
  hash by the number of uniforms per cell instead; mixing first keeps all
  32 bits of the key and lets every consumer draw as many uniforms as it
  needs without shifting the others);
* the r-th uniform of the cell is ``(pcg(stream + r) >> 8) / 2^24``, in
  [0, 1) with 24 bits, exactly representable in float32, so the GLSL and
  numpy uniforms are the same numbers, not just the same bits of the hash.

``pcg`` is the one-round permuted congruential hash (an LCG step followed
by a random-rotation xorshift and a multiply, as in PCG's RXS-M-XS output
function); it is a bijection of uint32.  Two cells share a key only if their
index difference lies in the kernel lattice of the linear map, whose
shortest vectors are hundreds of cells long (a test checks a 40^3 block).

`xorshift_key` is the alternative of section 3.2: the cell index folded
into the seed with Marsaglia's xorshift32 bit scrambling (agglomeration).

The GLSL twins (`GLSL_HASH`, added by `add_glsl`) use ``uint`` arithmetic,
which wraps modulo 2^32 exactly like numpy's uint32.
"""

from __future__ import annotations

import numpy as np

from .values import GlslModule

__all__ = ["P1", "P2", "P3", "check_seed", "seed_word", "pcg_hash", "cell_key", "cell_stream", "cell_uniform",
           "xorshift32", "xorshift_key", "GLSL_HASH", "add_glsl"]

P1, P2, P3 = 73856093, 19349663, 83492791      # primes of the multilinear hash
_GOLDEN = 0x9E3779B9                           # 2^32 / golden ratio, an odd constant
_MASK = 0xFFFFFFFF
_U = np.uint32


def _u32(values) -> np.ndarray:
    """Integers (any sign) as uint32 arrays modulo 2^32 (two's complement bits)."""
    return (np.asarray(values, dtype=np.int64) & _MASK).astype(np.uint32)


def pcg_hash(v) -> np.ndarray:
    """The PCG hash of uint32 values `v` (array_like of uint32): uint32 array, same shape."""
    v = np.asarray(v, dtype=np.uint32)
    with np.errstate(over="ignore"):
        state = v * _U(747796405) + _U(2891336453)
        word = ((state >> ((state >> _U(28)) + _U(4))) ^ state) * _U(277803737)
        return (word >> _U(22)) ^ word


def check_seed(seed) -> int:
    """`seed` as a Python int; ValueError if it is not an integer (bools refused)."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ValueError(f"seed must be an int, got {seed!r}")
    return int(seed)


def seed_word(seed: int) -> int:
    """An integer seed (any size and sign) folded into a uint32 word (Python int).

    Raises
    ------
    ValueError
        If `seed` is not an integer.
    """
    s = check_seed(seed) % (1 << 64)
    hi = pcg_hash(_U((s >> 32) ^ _GOLDEN))
    return int(pcg_hash(_U(s & _MASK) ^ hi))


def cell_key(i, j, k, word: int) -> np.ndarray:
    """Multilinear hash of cell indices (int arrays, any sign) and a `seed_word`: uint32."""
    with np.errstate(over="ignore"):
        return _u32(i) * _U(P1) + _u32(j) * _U(P2) + _u32(k) * _U(P3) + _U(word & _MASK)


def cell_stream(i, j, k, word: int) -> np.ndarray:
    """The PRNG state of cells (i, j, k) under `word` (`seed_word`): uint32."""
    return pcg_hash(cell_key(i, j, k, word))


def cell_uniform(stream, r: int) -> np.ndarray:
    """The r-th uniform (r >= 0) of cells with `stream` (uint32): float64 in [0, 1), each a
    multiple of 2^-24 (exact in float32)."""
    with np.errstate(over="ignore"):
        bits = pcg_hash(np.asarray(stream, dtype=np.uint32) + _U(r))
    return (bits >> _U(8)).astype(np.float64) * (1.0 / 16777216.0)


def xorshift32(x) -> np.ndarray:
    """Marsaglia's xorshift32 scrambling (shifts 13, 17, 5) of uint32 values: uint32.
    A bijection of the nonzero words (0 maps to 0)."""
    x = np.asarray(x, dtype=np.uint32)
    x = x ^ (x << _U(13))
    x = x ^ (x >> _U(17))
    return x ^ (x << _U(5))


def xorshift_key(i, j, k, word: int) -> np.ndarray:
    """Cell indices folded into `word` by xorshift32 scrambling (paper 004, section 3.2): uint32.

    ``x = xs(word ^ golden); x = xs(x ^ i); x = xs(x ^ j); x = xs(x ^ k)``; feed the
    result to `pcg_hash` (or use it as a `cell_uniform` stream) for uniforms."""
    x = xorshift32(_U(word & _MASK) ^ _U(_GOLDEN))
    for c in (i, j, k):
        x = xorshift32(x ^ _u32(c))
    return x


GLSL_HASH = f"""uint mf_pcg(uint v) {{
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}}

uint mf_cell_key(ivec3 c, uint word) {{
    uvec3 u = uvec3(c);
    return u.x * {P1}u + u.y * {P2}u + u.z * {P3}u + word;
}}

uint mf_cell_stream(ivec3 c, uint word) {{ return mf_pcg(mf_cell_key(c, word)); }}

float mf_cell_uniform(uint stream, uint r) {{
    return float(mf_pcg(stream + r) >> 8u) * (1.0 / 16777216.0);
}}

uint mf_xorshift32(uint x) {{
    x ^= x << 13u;
    x ^= x >> 17u;
    return x ^ (x << 5u);
}}

uint mf_xorshift_key(ivec3 c, uint word) {{
    uvec3 u = uvec3(c);
    uint x = mf_xorshift32(word ^ {_GOLDEN}u);
    x = mf_xorshift32(x ^ u.x);
    x = mf_xorshift32(x ^ u.y);
    return mf_xorshift32(x ^ u.z);
}}"""


def add_glsl(module: GlslModule) -> None:
    """Add the hash helpers (``mf_pcg``, ``mf_cell_key``, ``mf_cell_stream``,
    ``mf_cell_uniform``, ``mf_xorshift32``, ``mf_xorshift_key``) to `module` once."""
    module.helper("mf_cell_hash", GLSL_HASH)
