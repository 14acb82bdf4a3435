"""What a Grow node runs, as a Qt-free object: `GrowthPlan`.

A plan is made from the Grow node's validated parameters, its tile set and
the tiling seed (`GrowthPlan.from_params`); every entry point of virtual
growth calls it instead of assembling `grow_tiling` arguments itself:

- `GrowNode.evaluate` calls `GrowthPlan.evaluate` (a fresh growth, or a local
  regrowth of the repainted cells when only the painted regions changed);
- the command line (``mesoforge grow`` / ``study``) evaluates a graph holding
  the node, so it reaches the same call;
- the Virtual Growth dock asks `GrowthPlan.replay` for the collapse steps it
  animates, and `GrowthPlan.requested_blocks` for the block shares the node
  asks for; `ReplayCursor` steps through a replay.

Seeds: the node's ``seed`` parameter, when >= 0, is the tiling seed used as
is; -1 (the default) means the seed the evaluator derives from the document
seed and the node id (`tiling_seed`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from engine.batch.hints_text import parse_hints
from engine.graph.errors import NodeInputError
from engine.growth.values import TilingValue
from engine.growth import UNASSIGNED, grow_tiling
from engine.growth.regions import parse_region_hints, parse_region_map, region_hint_field
from engine.growth.regrow import regrow_region, regrowth_start

from .grid_size import grid_shape_of

__all__ = ["GrowthPlan", "GrowthReplay", "ReplayCursor", "MAX_CELLS", "REGROW_MARGIN",
           "grid_shape", "tiling_seed", "requested_block_hints", "recorded_history"]

MAX_CELLS = 1_000_000       # most grid cells a Grow node grows
REGROW_MARGIN = 1           # cells cleared around a repainted region (square neighbourhood)
DERIVED_SEED = -1           # the ``seed`` parameter's "derived from the document seed" value
# parameters whose change means a fresh growth (not a local regrowth)
_REGROW_KEYS = ("size", "periodic", "hints", "availability")


def tiling_seed(params: dict, derived: int) -> int:
    """The tiling seed of a Grow node: its ``seed`` parameter when >= 0, else
    ``derived`` (the evaluator's ``node_seed(document seed, node id)``)."""
    seed = int(params.get("seed", DERIVED_SEED))
    return int(derived) if seed < 0 else seed


def grid_shape(size, tileset) -> tuple:
    """``[nx, ny(, nz)]`` -> grid shape ``(ny, nx)`` / ``(nz, ny, nx)``.

    Raises NodeInputError (``where="size"``) when the count of entries does
    not match the set's dimension or the grid has more than MAX_CELLS cells."""
    return grid_shape_of(size, tileset.ndim, MAX_CELLS, where="size", owner=f"tile set {tileset.name!r} is")


def requested_block_hints(hints, tileset) -> np.ndarray | None:
    """(n_blocks,) requested block probabilities (normalised) from parsed hints
    (block or tile names -> weight), or from the set's weights when ``hints``
    is None; None when a name is unknown or every weight is 0."""
    n_blocks = tileset.n_blocks
    tile_block = np.asarray(tileset.tile_block)
    if hints is None:
        w = np.bincount(tile_block, weights=np.asarray(tileset.weights, float), minlength=n_blocks)
    else:
        w = np.zeros(n_blocks)
        names, tiles = list(tileset.block_names), list(tileset.tile_names)
        for key, value in dict(hints).items():
            if key in names:
                w[names.index(key)] += float(value)
            elif key in tiles:
                w[tile_block[tiles.index(key)]] += float(value)
            else:
                return None
    total = float(w.sum())
    return w / total if total > 0 else None


@dataclass(frozen=True)
class GrowthReplay:
    """The collapse steps of a growth, for animating it.

    start : int32 grid before the first step (UNASSIGNED = not yet decided)
    steps : (n, 2) int64 ``[flat cell index, tile]`` in decision order (-1 = defect)
    final : int32 grid the steps end in (the shown tiling)
    note : what the replay shows ("recorded growth", "recorded local regrowth of N cells", ...)
    """

    start: np.ndarray
    steps: np.ndarray
    final: np.ndarray
    note: str = ""

    @property
    def n_steps(self) -> int:
        return len(self.steps)


def recorded_history(tv: TilingValue) -> GrowthReplay | None:
    """The replay recorded with a tiling, or None when it carries none.

    ``tv.steps`` / ``tv.start_tiles`` (set by the Grow node) first, then the
    tiling's own ``steps``; without a start grid the cells named in the steps
    are cleared from the final grid (growth decides each cell once).
    """
    final = np.asarray(tv.tiling.tiles)
    steps = getattr(tv, "steps", None)
    if steps is None:
        steps = getattr(tv.tiling, "steps", None)
    if steps is None:
        return None
    steps = np.asarray(steps)
    if steps.ndim != 2 or steps.shape[1] != 2 or not np.issubdtype(steps.dtype, np.integer) \
            or (steps.size and (steps[:, 0].min() < 0 or steps[:, 0].max() >= final.size)):
        return None
    start = getattr(tv, "start_tiles", None)
    if start is None or np.shape(start) != final.shape:
        start = final.copy()
        start.reshape(-1)[steps[:, 0]] = UNASSIGNED
    start = np.array(start, dtype=np.int32)
    cleared = int(np.count_nonzero(start == UNASSIGNED))
    note = "recorded growth" if cleared == final.size else f"recorded local regrowth of {cleared} cells"
    return GrowthReplay(start, steps.astype(np.int64), np.array(final), note)


@dataclass(frozen=True)
class GrowthPlan:
    """One growth of a Grow node, ready to run.

    tileset : engine.growth.TileSet
    shape : grid shape ``(ny, nx)`` / ``(nz, ny, nx)``
    periodic : opposite boundaries are neighbours
    hints : parsed base hints (name -> weight) or None (the set's weights)
    labels : int label per cell of the painted regions (2D), or None
    per_label : parsed hints of each painted label (``region_hints``), {} without regions
    availability : blocks per cell (paper's N), None = unlimited
    seed : the tiling seed (`tiling_seed`)
    params : the node's validated parameters the plan was made from
    """

    tileset: object
    shape: tuple
    periodic: bool
    hints: dict | None
    labels: np.ndarray | None
    per_label: dict
    availability: float | None
    seed: int
    params: dict = field(repr=False)

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def from_params(cls, params: dict, tileset, seed: int) -> "GrowthPlan":
        """A plan from the Grow node's validated ``params`` (see GrowNode), its
        tile set and the tiling seed; NodeInputError naming the parameter
        (``where``) when the size, hints or regions do not fit the set."""
        shape = grid_shape(params["size"], tileset)
        try:
            hints = parse_hints(params["hints"], tileset)
        except ValueError as exc:
            raise NodeInputError(str(exc), where="hints") from None
        try:
            labels = parse_region_map(params["regions"], shape)
        except ValueError as exc:
            raise NodeInputError(str(exc), where="regions") from None
        per_label = {}
        if labels is not None:
            try:
                per_label = parse_region_hints(params["region_hints"],
                                               lambda text: parse_hints(text, tileset))
            except ValueError as exc:
                raise NodeInputError(str(exc), where="region_hints") from None
        return cls(tileset, shape, bool(params["periodic"]), hints, labels, per_label,
                   params["availability"] or None, int(seed), dict(params))

    @cached_property
    def field(self) -> np.ndarray | None:
        """Per-cell hint field of the painted regions (None without regions);
        made when growth first needs it."""
        if self.labels is None:
            return None
        return region_hint_field(self.tileset, self.shape, self.labels, self.hints, self.per_label)

    @property
    def growth_hints(self):
        """What growth is given as hints: the painted field, else the base hints."""
        return self.field if self.field is not None else self.hints

    # -- running ------------------------------------------------------------------------------
    def run(self, *, record_steps: bool = True, max_steps: int | None = None,
            progress=None) -> TilingValue:
        """Grow the whole grid afresh. ``max_steps`` stops after that many
        observations (cells not reached stay UNASSIGNED; see `resume`).
        Raises engine.progress.Cancelled when ``progress`` answers False."""
        tiling = grow_tiling(self.tileset, self.shape, hints=self.growth_hints, periodic=self.periodic,
                             availability=self.availability, rng=self.seed, max_steps=max_steps,
                             record_steps=record_steps, progress=progress)
        start = np.full(self.shape, UNASSIGNED, np.int32)
        return TilingValue(tiling, self.tileset, tiling.steps if record_steps else None,
                           start if record_steps else None)

    def resume(self, value: TilingValue, *, record_steps: bool = True, progress=None) -> TilingValue:
        """Grow the cells a stopped growth (``max_steps``, or a partial tiling)
        never reached, keeping every decided tile and defect; the others are
        grown by the plan's hints and seed. A complete tiling comes back as it is."""
        tiling = value.tiling
        self._check_fits(tiling)
        open_cells = np.asarray(tiling.tiles) == UNASSIGNED
        if not open_cells.any():
            return TilingValue(tiling, self.tileset, np.zeros((0, 2), np.int32), tiling.tiles)
        return self.regrow(value, np.zeros(self.shape, bool), margin=0, record_steps=record_steps,
                           progress=progress)

    def regrow(self, value: TilingValue, changed, *, margin: int = REGROW_MARGIN,
               record_steps: bool = True, progress=None) -> TilingValue:
        """Local regrowth (paper's repainting): the ``changed`` cells (bool mask
        of the grid) plus ``margin`` grow again under the plan's hints (the
        painted field); every other tile stays byte-identical. The result
        records the regrowth's steps and the grid it started from."""
        self._check_fits(value.tiling)
        changed = np.asarray(changed, dtype=bool)
        start = regrowth_start(value.tiling, changed, margin=margin)
        tiling = regrow_region(value.tiling, self.tileset, changed, margin=margin,
                               hints=self.growth_hints, rng=self.seed, record_steps=record_steps,
                               progress=progress)
        return TilingValue(tiling, self.tileset, tiling.steps if record_steps else None,
                           start if record_steps else None)

    def evaluate(self, previous: TilingValue | None = None, previous_params: dict | None = None,
                 previous_seed: int | None = None, *, progress=None) -> TilingValue:
        """What the Grow node outputs: the tiling kept as it is when nothing
        painted changed since ``previous`` (the node's last result, made with
        ``previous_params`` and tiling seed ``previous_seed``), a local
        regrowth when only the painted regions did, else a fresh growth."""
        changed = self.changed_cells(previous, previous_params, previous_seed)
        if changed is None:
            return self.run(progress=progress)
        if not changed.any():
            tiling = previous.tiling
            return TilingValue(tiling, self.tileset, np.zeros((0, 2), np.int32), tiling.tiles)
        return self.regrow(previous, changed, progress=progress)

    def changed_cells(self, previous: TilingValue | None, previous_params: dict | None,
                      previous_seed: int | None) -> np.ndarray | None:
        """Bool mask of the cells to regrow when at most the painted regions
        changed since ``previous`` (same set, size, seed, periodicity; all
        False when nothing did); None when the grid must grow afresh."""
        prev = previous_params or {}
        params = self.params
        same = (previous is not None and previous.tileset is self.tileset
                and previous.tiling.tiles.shape == tuple(self.shape) and not params["availability"]
                and all(prev.get(k) == params[k] for k in _REGROW_KEYS)
                and previous_seed == self.seed)
        if not same:
            return None
        try:
            old = parse_region_map(prev.get("regions", ""), self.shape)
        except ValueError:
            return None
        old = np.zeros(self.shape, np.int64) if old is None else old
        new = np.zeros(self.shape, np.int64) if self.labels is None else self.labels
        if prev.get("region_hints") != params["region_hints"]:
            return (old != new) | (new != 0) | (old != 0)
        return old != new

    def _check_fits(self, tiling) -> None:
        if tuple(tiling.tiles.shape) != tuple(self.shape):
            raise ValueError(f"the tiling's grid {tiling.tiles.shape} is not the plan's {self.shape}")

    # -- what the dock shows -------------------------------------------------------------------
    def replay(self, value: TilingValue) -> GrowthReplay:
        """The collapse steps that made ``value``: those recorded with it, else
        a growth of the plan with its steps recorded (the same tiling when it
        was grown in one pass from these parameters; the note says otherwise).
        Raises ValueError when it cannot be replayed."""
        recorded = recorded_history(value)
        if recorded is not None:
            return recorded
        t = value.tiling
        if tuple(t.shape) != tuple(self.shape):
            raise ValueError("the grid size changed since the tiling was grown")
        grown = self.run(record_steps=True).tiling
        note = ""
        if not np.array_equal(grown.tiles, t.tiles):
            note = ("the shown tiling was not grown in one pass from the node's current "
                    "parameters (local regrowth or an edit) and carries no record: "
                    "the replay shows a fresh growth")
        return GrowthReplay(np.full(t.shape, UNASSIGNED, np.int32), np.asarray(grown.steps, np.int64),
                            np.asarray(grown.tiles), note)

    def requested_blocks(self) -> np.ndarray | None:
        """(n_blocks,) block probabilities the node asks for: the base hints'
        shares, or (painted regions) each label's shares weighted by its cells;
        None when they cannot be told."""
        ts = self.tileset
        if self.labels is None:
            return requested_block_hints(self.hints, ts)
        per_label = self.per_label
        counts = np.bincount(np.asarray(self.labels).ravel())
        total = np.zeros(ts.n_blocks)
        for label in np.flatnonzero(counts):
            share = requested_block_hints(per_label.get(int(label), self.hints), ts)
            if share is None:
                return None
            total += counts[label] * share
        return total / total.sum()


class ReplayCursor:
    """A position in a `GrowthReplay`: the grid after the first ``pos`` steps.

    ``grid`` is the cursor's own array (changed in place by `step`)."""

    def __init__(self, replay: GrowthReplay):
        self.replay = replay
        self.grid = replay.start.copy()
        self.pos = 0

    @property
    def n_steps(self) -> int:
        return self.replay.n_steps

    @property
    def done(self) -> bool:
        return self.pos >= self.n_steps

    def restart(self) -> np.ndarray:
        """Back to the grid before the first step."""
        self.grid[...] = self.replay.start
        self.pos = 0
        return self.grid

    def step(self, n: int = 1) -> bool:
        """Apply the next ``n`` steps (later events win, as in the growth);
        True when the grid changed. The last step leaves exactly ``final``."""
        steps = self.replay.steps
        end = min(len(steps), self.pos + max(0, int(n)))
        if end <= self.pos:
            return False
        chunk = steps[self.pos:end]
        self.grid.reshape(-1)[chunk[:, 0]] = chunk[:, 1]
        self.pos = end
        if self.pos == len(steps):
            self.grid[...] = self.replay.final
        return True
