"""What the RDGrow node runs, as an object the node, the dock and the CLI share.

An `RDGrowthSession` is built from an RDGrow node's validated parameters,
its input (an ``RDFieldsValue``) and the node's seed.  It holds one
``engine.rd.growth`` run per principal direction and advances them:

    session = RDGrowthSession(fields, params, seed)
    while not session.advance(100, progress):     # 100 more steps per direction
        show(session.frame())                      # a picture of the growth so far
    value = session.apply()                        # == RDGrowNode.evaluate's structures

* ``advance(steps, progress)`` grows every unfinished direction by up to
  ``steps`` more steps (None: to the end).  The kernel resumes from its own
  state bit for bit, so growing in pieces equals one uninterrupted run.
* Pausing is cancelling: when ``progress`` returns False the kernel stops
  after its last complete step, the session keeps that state and raises
  ``Cancelled``; the next ``advance`` continues exactly.
* ``apply()`` is the node's value once every direction has finished: the
  states made canonical and the node's brush edits applied by local
  regrowth (`regrow`).  ``grow()`` is the whole node run in one call.
* ``regrow(edits)`` applies brush edits to the session's value and regrows
  only around them (what the node does when only edits were appended).

Qt-free; the node's message and parameter name come with every refusal
(``NodeInputError``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from engine.graph.errors import NodeInputError
from engine.rd.values import RDFieldsValue, RDStructuresValue
from engine.progress import Cancelled, stage

from . import rd_state
from .rd import growth_fields, growth_shape, selected_directions


@dataclass
class RDGrowthFrame:
    """One picture of a growth in progress.

    s : (n,) + grid float32, ``1 - u`` per direction (a copy; zeros before a direction's first step)
    directions : tuple of int, the principal direction of each structure
    steps : tuple of int, steps taken per direction
    g_history : tuple of (m, 2) float64, (step, G^t) per direction
    stop_reasons : tuple of str, "" while a direction still grows, else "converged" / "max_steps"
    states : tuple of RDState (None before a direction's first step), not canonical
    status : str, what the caller says the growth is doing ("running", "paused", "cancelled", "done")
    """

    s: np.ndarray
    directions: tuple
    steps: tuple
    g_history: tuple
    stop_reasons: tuple
    states: tuple = field(repr=False, default=())
    status: str = "running"

    @property
    def last_g(self) -> tuple:
        """G^t at the last check of each direction (nan before the first)."""
        return tuple(float(h[-1, 1]) if len(h) else float("nan") for h in self.g_history)


def _refused(exc: rd_state.GrowthInputError) -> NodeInputError:
    return NodeInputError(str(exc), where=exc.where)


class RDGrowthSession:
    """The growth an RDGrow node runs, one direction after the other, resumable.

    Parameters
    ----------
    source : RDFieldsValue, the node's input (on the fields' grid; upsampled here to the growth grid)
    params : dict, the node's full, validated parameters (``resolution``, ``iso``, ... ``edits``)
    seed : int, the node's seed (``ctx.seed``; ``node_seed(doc.seed, node_id)`` from outside)

    Raises
    ------
    NodeInputError
        The node's refusal of these parameters on these fields (``where`` names the parameter).
    """

    def __init__(self, source: RDFieldsValue, params: dict, seed: int):
        self.params = dict(params)
        self.seed = int(seed)
        shape = growth_shape(self.params["resolution"], source)
        self.directions = tuple(selected_directions(self.params["directions"], source.ndim))
        self.fields = growth_fields(source, shape)
        try:
            self.options = rd_state.growth_options(self.fields, self.params, self.seed)
        except rd_state.GrowthInputError as exc:
            raise _refused(exc) from None
        self.value: RDStructuresValue | None = None
        self.start()

    @classmethod
    def of_value(cls, value: RDStructuresValue, params: dict) -> "RDGrowthSession":
        """A finished session holding ``value`` (a previous result of the node with ``params``),
        ready to `regrow` after new brush edits."""
        self = cls.__new__(cls)
        self.params = dict(params)
        self.seed = 0
        self.directions = tuple(value.directions)
        self.fields = value.fields
        self.options = {"eps": self.params["eps"], "max_steps": self.params["max_steps"]}
        self._results, self._seconds = [], []
        self.value = value
        return self

    # -- state --------------------------------------------------------------------------------
    @property
    def shape(self) -> tuple:
        """The growth grid, [y, x] / [z, y, x]."""
        return tuple(self.fields.grid_shape)

    @property
    def max_steps(self) -> int:
        """Step limit per direction."""
        return int(self.options["max_steps"])

    @property
    def eps(self) -> float:
        """Threshold of the stopping criterion G^t (eq. 14)."""
        return float(self.options["eps"])

    @property
    def steps(self) -> tuple:
        """Steps taken so far, per direction."""
        return tuple(0 if r is None else int(r.steps) for r in self._results)

    def finished(self, k: int) -> bool:
        """Direction number ``k`` (in `directions` order) converged or reached ``max_steps``."""
        r = self._results[k]
        return r is not None and (r.stop_reason == "converged" or r.steps >= self.max_steps)

    @property
    def done(self) -> bool:
        """Every direction has finished (a session made by `of_value` is done)."""
        return all(self.finished(k) for k in range(len(self._results)))

    def _reason(self, k: int) -> str:
        """Why direction ``k`` finished, as the node reports it ("" while it grows)."""
        if not self.finished(k):
            return ""
        return "converged" if self._results[k].stop_reason == "converged" else "max_steps"

    # -- growth -------------------------------------------------------------------------------
    def start(self) -> None:
        """Forget any growth: the next `advance` starts every direction from its seeds."""
        self._results = [None] * len(self.directions)
        self._seconds = [0.0] * len(self.directions)
        self.value = None

    def advance(self, steps: int | None = None, progress=None) -> bool:
        """Grow every unfinished direction, in order, by up to ``steps`` more steps
        (None: until it converges or reaches ``max_steps``).  True once all have finished.

        progress : callable(done, total) -> bool or None, on a bar over the whole growth
            (direction k of n owns [k/n, (k+1)/n]); False stops after the last complete step
            (a direction stopped at its last step counts as finished all the same).

        Raises
        ------
        Cancelled
            ``progress`` returned False; the state of the last complete step is kept and the
            next call continues from it exactly.
        NodeInputError
            The kernel refused the inputs.
        """
        from engine.rd.growth import grow

        n = len(self.directions)
        for k in range(n):
            if self.finished(k):
                continue
            previous = self._results[k]
            begun = 0 if previous is None else int(previous.steps)
            cap = self.max_steps if steps is None else min(self.max_steps, begun + max(1, int(steps)))
            opts = dict(self.options, max_steps=cap)
            if previous is not None:   # a resumed growth keeps its seeds and resolved parameters
                for key in ("seeds", "seed_radius", "params"):
                    opts.pop(key, None)
            share = stage(progress, k / n, 1 / n)
            # the kernel reports (step, this call's cap); the bar runs to max_steps
            kernel = None if share is None else (lambda done, _cap, share=share: share(done, self.max_steps))
            try:
                res = grow(self.fields.rho, self.fields.rotation, direction=self.directions[k],
                           gamma_map=self.fields.gamma, progress=kernel,
                           state=None if previous is None else previous.state, **opts)
            except ValueError as exc:
                raise _refused(rd_state.GrowthInputError(str(exc), rd_state.where_of(str(exc)))) from None
            self._results[k] = res
            self._seconds[k] += res.wall_time
            if res.stop_reason == "cancelled":
                raise Cancelled(f"growth of direction {self.directions[k]} stopped at step {res.steps}")
        return self.done

    def frame(self, status: str = "running") -> RDGrowthFrame:
        """A picture of the growth now (copies: safe to hand to another thread)."""
        s = np.zeros((len(self.directions),) + self.shape, np.float32)
        hist, states = [], []
        for k, r in enumerate(self._results):
            if r is None:
                hist.append(np.zeros((0, 2)))
                states.append(None)
                continue
            s[k] = 1.0 - r.u
            hist.append(np.array(r.history, np.float64).reshape(-1, 2))
            states.append(r.state)
        reasons = tuple(self._reason(k) for k in range(len(self._results)))
        return RDGrowthFrame(s, self.directions, self.steps, tuple(hist), reasons, tuple(states), status)

    # -- the node's value ---------------------------------------------------------------------
    def grown(self) -> RDStructuresValue:
        """The finished growth as the node's value before brush edits (states canonical).

        Raises RuntimeError while a direction still grows."""
        if not self.done:
            raise RuntimeError(f"the growth has not finished (steps {list(self.steps)} of {self.max_steps})")
        n_cells = math.prod(self.shape)
        runs = [rd_state.GrowthRun(rd_state.canonical_state(r.state), self._reason(k), r.steps, self._seconds[k],
                                   r.steps * n_cells, r.history) for k, r in enumerate(self._results)]
        return rd_state.structures_value(self.fields, self.directions, self.params["iso"], runs, edits=(),
                                         regrown=False, changed=None)

    def apply(self, progress=None) -> RDStructuresValue:
        """The node's result: the finished growth with the node's brush edits (``params["edits"]``)
        applied one after the other by local regrowth; kept as `value` (a second call returns it).

        progress : on a bar over the edits alone.  Raises RuntimeError while a direction still
        grows, NodeInputError for an edit the node refuses, Cancelled."""
        if self.value is None:
            edits = self.params["edits"]
            self.value = self._with_edits(progress, 0, len(self.directions) * len(edits))
        return self.value

    def grow(self, progress=None) -> RDStructuresValue:
        """Everything the node does on fresh inputs: grow every direction to the end, then
        apply the brush edits (`apply`).  ``progress`` on one bar where each growth and each
        regrowth takes one equal share, as the node reports it."""
        n = len(self.directions)
        total = n * (1 + len(self.params["edits"]))
        self.advance(None, stage(progress, 0.0, n / total))
        if self.value is None:
            self.value = self._with_edits(progress, n, total)
        return self.value

    def _with_edits(self, progress, done, total) -> RDStructuresValue:
        value = self.grown()
        edits = self.params["edits"]
        return self._regrow(value, edits, progress, done, total) if edits else value

    def regrow(self, edits, progress=None) -> RDStructuresValue:
        """Apply canonical brush ``edits`` (appended after the value's own) to the session's
        value and regrow each locally; returns the new value and keeps it.

        Raises RuntimeError before the growth has finished, NodeInputError (where="edits")
        for an edit that covers nothing or lies outside the infill space, Cancelled."""
        base = self.apply() if self.value is None else self.value
        self.value = self._regrow(base, list(edits), progress, 0, len(self.directions) * len(edits))
        return self.value

    def _regrow(self, value, edits, progress, done, total):
        try:
            return rd_state.regrow_all(value, edits, self.params, progress=progress, done=done,
                                       total=total or None)
        except rd_state.GrowthInputError as exc:
            raise _refused(exc) from None
