"""The memory budget, and refusing work that would not fit in it.

Node types estimate the peak memory of an evaluation from their parameters
(and input shapes) in ``NodeType.memory_estimate``; the evaluator, the
command line and the window compare that estimate with one budget, here,
before anything is allocated.  Kernels may import this module; it imports
nothing of the graph.

The budget is the memory available to a new process (``MemAvailable``), or
``MESOFORGE_MEMORY_LIMIT`` when set: a byte count with an optional K, M, G
or T suffix (powers of 1024), e.g. ``512M``; tests set it low so that a
refusal is quick to provoke.
"""

from __future__ import annotations

import math
import os

__all__ = ["ENV_LIMIT", "MemoryLimitError", "available_memory_bytes", "memory_budget", "check_budget",
           "format_bytes", "parse_bytes", "tiled_mesh_bytes"]

ENV_LIMIT = "MESOFORGE_MEMORY_LIMIT"
_SUFFIXES = {"": 1, "B": 1, "K": 2**10, "KB": 2**10, "M": 2**20, "MB": 2**20, "G": 2**30, "GB": 2**30,
             "T": 2**40, "TB": 2**40}

# Tiled meshes (``engine.geometry.marching.periodic_mesh`` over ``tiles`` copies
# of a cell's field): the float32 tiled grid with its masks and marching-cubes
# temporaries, measured at ~30 B per tiled grid point for a beam cell, plus the
# vertices and faces (~128 B per output face with the welding temporaries).
# Before the cell is meshed the face count is bounded by FACES_PER_POINT per
# grid point (an octet cell at resolution 96 has ~0.14).
TILED_BYTES_PER_POINT = 32
BYTES_PER_FACE = 128
FACES_PER_POINT = 0.2


class MemoryLimitError(ValueError):
    """A request whose memory estimate exceeds the budget; refused before allocating.

    Attributes: ``need`` and ``budget`` (bytes), ``lower`` (what to lower, in
    words) and ``where`` (the parameter that sets the size, for the evaluator).
    """

    def __init__(self, message: str, *, need: int, budget: int, lower: str = "", where: str = ""):
        super().__init__(message)
        self.need = int(need)
        self.budget = int(budget)
        self.lower = lower
        self.where = where


def parse_bytes(text) -> int:
    """``"512M"`` -> 536870912; a plain number is bytes.  ValueError otherwise."""
    s = str(text).strip().upper().replace(" ", "")
    unit = s.lstrip("0123456789.E+-")
    number = s[:len(s) - len(unit)] if unit else s
    try:
        value = float(number) * _SUFFIXES[unit]
    except (KeyError, ValueError):
        value = math.nan
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{ENV_LIMIT}={text!r}: expected a byte count > 0 such as 2000000000, 512M or 4G")
    return int(value)


def available_memory_bytes() -> int | None:
    """Memory available to a new process (``MemAvailable``), or None if unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def memory_budget() -> int | None:
    """Bytes a request may use: ``MESOFORGE_MEMORY_LIMIT`` if set, else the
    available memory; None when neither is known (nothing is refused)."""
    text = os.environ.get(ENV_LIMIT, "").strip()
    if text:
        return parse_bytes(text)
    return available_memory_bytes()


def format_bytes(n: float) -> str:
    """``26.5 GB``, ``200 MB``, ``512 kB`` (powers of 1000)."""
    n = float(n)
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def _budget_text(budget: int) -> str:
    if os.environ.get(ENV_LIMIT, "").strip():
        return f"the {format_bytes(budget)} allowed by {ENV_LIMIT}"
    return f"the {format_bytes(budget)} available"


def check_budget(need: int, *, what: str, lower: str = "", where: str = "", budget: int | None = None) -> int:
    """Refuse ``need`` bytes when they exceed the budget.

    Parameters
    ----------
    need : int, the estimate (bytes)
    what : str, what needs it, e.g. ``"resolution = 512"``
    lower : str, what to lower to fit, e.g. ``"resolution"``
    where : str, the parameter name carried by the error
    budget : int, optional; default :func:`memory_budget`

    Returns
    -------
    int, ``need``

    Raises
    ------
    MemoryLimitError
        ``"resolution = 512 needs about 26.5 GB of memory, more than the 8 GB
        available; lower resolution"``.
    """
    limit = memory_budget() if budget is None else int(budget)
    if limit is not None and need > limit:
        tail = f"; lower {lower}" if lower else ""
        raise MemoryLimitError(f"{what} needs about {format_bytes(need)} of memory, more than "
                               f"{_budget_text(limit)}{tail}", need=need, budget=limit, lower=lower,
                               where=where)
    return int(need)


def tiled_mesh_bytes(grid_shape, tiles, faces: int | None = None) -> int:
    """Peak memory of meshing ``tiles`` copies of a periodic cell in one pass.

    Parameters
    ----------
    grid_shape : (3,) int, the cell's grid nodes per axis
    tiles : (3,) int >= 1, cells per axis; (1, 1, 1) reuses the cell's mesh (0 bytes)
    faces : int, optional; the cell mesh's face count (default: the bound
        ``FACES_PER_POINT`` per grid point)

    Returns
    -------
    int, bytes
    """
    t = [int(v) for v in tiles]
    if all(v == 1 for v in t):
        return 0
    n = [int(v) for v in grid_shape]
    points = math.prod(a * b + 3 for a, b in zip(n, t))
    cell_faces = FACES_PER_POINT * math.prod(n) if faces is None else int(faces)
    return int(points * TILED_BYTES_PER_POINT + cell_faces * math.prod(t) * BYTES_PER_FACE)
