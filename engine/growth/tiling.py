"""The result of a growth: a grid of tile indices, defects and the record."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Tiling", "DEFECT", "UNASSIGNED", "resolve_rng"]

DEFECT = -1       # no admissible tile was left for the cell
UNASSIGNED = -2   # growth stopped (max_steps) before reaching the cell


def resolve_rng(rng):
    """Turn ``rng`` (None, int or Generator) into ``(Generator, seed)``.

    ``seed`` is the int that reproduces the run, or None when a Generator
    was passed (its state is the caller's business). With ``rng=None`` a
    fresh seed is drawn from OS entropy and recorded.
    """
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is None:
        rng = int(np.random.SeedSequence().generate_state(1, dtype=np.uint64)[0] >> 1)
    if isinstance(rng, bool) or not isinstance(rng, (int, np.integer)) or rng < 0:
        raise ValueError(f"rng must be None, a non-negative int seed or a numpy Generator; "
                         f"got {rng!r}")
    return np.random.default_rng(int(rng)), int(rng)


@dataclass(frozen=True, eq=False)
class Tiling:
    """A grown tiling.

    Attributes
    ----------
    tiles : int32 array of the grid shape, read-only
        Tile index per cell (row-major, ``[i, j]`` = ``[y, x]`` or
        ``[k, i, j]`` = ``[z, y, x]``); ``DEFECT`` (-1) where no tile fit,
        ``UNASSIGNED`` (-2) where growth was stopped by ``max_steps``.
    tileset_name : str
    periodic : bool
        Whether opposite grid boundaries were treated as neighbours (torus).
    seed : int or None
        Seed that reproduces the run, None if a Generator was passed.
    steps : (n_events, 2) int32 or None
        With ``record_steps``: ``[flat cell index, tile]`` in the order
        cells were decided; tile -1 marks a defect forming.
    stats : dict
        ``n_cells, n_defects, n_observations, complete`` and, with finite
        availability, ``remaining`` per block.
    """

    tiles: np.ndarray
    tileset_name: str
    periodic: bool
    seed: int | None = None
    steps: np.ndarray | None = None
    stats: dict = field(default_factory=dict)

    def __post_init__(self):
        self.tiles.setflags(write=False)
        if self.steps is not None:
            self.steps.setflags(write=False)

    @property
    def shape(self) -> tuple:
        return self.tiles.shape

    @property
    def defects(self) -> np.ndarray:
        """Bool mask of the grid shape: cells where a defect formed."""
        return self.tiles == DEFECT

    @property
    def n_defects(self) -> int:
        return int(np.count_nonzero(self.tiles == DEFECT))

    def tile_names(self, tileset) -> np.ndarray:
        """Object array of the grid shape: ``"T@2"`` per cell, None if not a tile."""
        names = np.array(list(tileset.tile_names) + [None, None], dtype=object)
        return names[np.where(self.tiles >= 0, self.tiles, len(tileset.tile_names))]
