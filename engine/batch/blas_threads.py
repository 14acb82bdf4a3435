"""Limit the threads of the OpenBLAS copies loaded by numpy / scipy.

Dask workers start with ``OPENBLAS_NUM_THREADS=1``; a sample computed in the
main process would otherwise use every core in BLAS, and a threaded
reduction sums in a different order, so rows would differ in the last bits
depending on the scheduler. ``blas_threads(1)`` makes both the same.

Finds the loaded libraries through ``/proc/self/maps`` (Linux); elsewhere,
or when no OpenBLAS is found, it does nothing.
"""

from __future__ import annotations

import ctypes
import os
from contextlib import contextmanager

__all__ = ["blas_threads"]

# (getter, setter) symbol names used by the OpenBLAS builds numpy / scipy ship
_SYMBOLS = (
    ("openblas_get_num_threads", "openblas_set_num_threads"),
    ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
    ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
    ("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
)
_FOUND: dict = {}


def _openblas_controls() -> list:
    """(get, set) function pairs, one per loaded OpenBLAS library."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as f:
            paths = {line.split()[-1] for line in f if "openblas" in line.lower()}
    except OSError:
        return []
    out = []
    for path in sorted(paths):
        if path in _FOUND:
            if _FOUND[path] is not None:
                out.append(_FOUND[path])
            continue
        pair = None
        if os.path.isfile(path):
            try:
                lib = ctypes.CDLL(path)
            except OSError:
                lib = None
            for get_name, set_name in _SYMBOLS if lib is not None else ():
                getter, setter = getattr(lib, get_name, None), getattr(lib, set_name, None)
                if getter is not None and setter is not None:
                    getter.restype = ctypes.c_int
                    setter.argtypes = [ctypes.c_int]
                    pair = (getter, setter)
                    break
        _FOUND[path] = pair
        if pair is not None:
            out.append(pair)
    return out


@contextmanager
def blas_threads(n: int):
    """Run the block with OpenBLAS limited to ``n`` threads, then restore."""
    controls = _openblas_controls()
    old = [get() for get, _ in controls]
    for _, set_ in controls:
        set_(int(n))
    try:
        yield
    finally:
        for (_, set_), k in zip(controls, old):
            set_(int(k))
