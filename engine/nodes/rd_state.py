"""What the RDGrow node keeps and the pieces its growth session
(`engine.nodes.rd_session`) is made of: the kernel options, the canonical
state, local regrowth after brush edits, and the compact form of the grown
state stored in the project file.

The kept state is *canonical*: after every growth or regrowth ``u`` and
``v`` are clipped to [0, 1] and quantised to 1/255 (held as float64), so
that the state held in memory and the state read back from a project file
are the same numbers, and a regrowth after reopening equals one without.
At the member boundaries ``s = 1 - u`` changes by ~0.1 per cell, so the
quantisation moves a contour by a few hundredths of a cell; the
compilation's smoothing band (delta = 0.01 each side) spans ~5 levels.

Blob (``encode_structures``): per direction ``u`` and ``v`` as uint8
levels, differenced along the flattened grid (mod 256), zlib-compressed,
base64 text; plus steps, stop reasons, G histories, timings, the resolved
kernel parameters and the edits applied.  A 640 x 320 cantilever (two
directions) takes about 0.2 MB of text.
"""

from __future__ import annotations

import base64
import math
import re
import zlib

import numpy as np

from engine.progress import Cancelled, stage
from engine.rd.values import RDFieldsValue, RDStructuresValue

BLOB_FORMAT = "mesoforge-rd-structures/1"
MIN_MARGIN = 4             # cells around an edit's box that regrow with it (at least; else its radius)


class GrowthInputError(ValueError):
    """Growth inputs the kernel refused; ``where`` names the node parameter."""

    def __init__(self, message: str, where: str):
        super().__init__(message)
        self.where = where


_WHERE = ((r"infill space|\biso\b", "iso"), (r"\bdt\b", "dt"), (r"\bseeds?\b", "seeds"),
          (r"\bxi\b", "xi"), (r"\balpha\b", "alpha"), (r"\bgamma\b", "gamma"), (r"\bmax_steps\b", "max_steps"),
          (r"\beps\b", "eps"))


def where_of(message: str) -> str:
    """The node parameter a kernel's message is about ("rdfields": the input)."""
    for pattern, where in _WHERE:
        if re.search(pattern, message):
            return where
    return "rdfields"


def kernel_params(params: dict):
    """``engine.rd.gray_scott.RDParams`` from the node's parameters."""
    from engine.rd.gray_scott import RDParams

    return RDParams(d=params["d"], gamma=params["gamma"], F=params["F"], k=params["k"], alpha=params["alpha"],
                    xi=params["xi"], dt=params["dt"] or None)


def seed_radius(shape) -> float:
    """Seed disc / ball radius in cells (paper 6.1: 5 % of the longest side)."""
    return 0.05 * max(shape)


def growth_options(fields: RDFieldsValue, params: dict, seed: int) -> dict:
    """The ``engine.rd.growth.grow`` keywords the node uses, shared by every
    direction (the same seeds for all): iso, params, seeds, seed_radius, eps,
    max_steps.  `engine.nodes.rd_session.RDGrowthSession` grows with these."""
    from engine.rd.growth import place_seeds

    shape = fields.grid_shape
    radius = seed_radius(shape)
    seeds = None
    if params["seeds"] == "several":
        inside = fields.rho >= params["iso"]
        if not inside.any():
            raise GrowthInputError(f"the infill space {{rho >= iso}} is empty (max rho = {fields.rho.max():.4g}, "
                                   f"iso = {params['iso']:g}); lower iso", "iso")
        seeds = place_seeds(inside, seeds=params["n_seeds"], radius=radius, rng=seed)
    return {"iso": params["iso"], "params": kernel_params(params), "seeds": seeds, "seed_radius": radius,
            "eps": params["eps"], "max_steps": params["max_steps"]}


LEVELS = 255


def quantised(a) -> np.ndarray:
    """``a`` clipped to [0, 1] and rounded to the nearest 1/255 (float64)."""
    return np.rint(np.clip(a, 0.0, 1.0) * LEVELS) / LEVELS


def canonical_state(state):
    """``state`` with u and v quantised (see the module notes); its last
    check's Omega sum no longer fits the quantised u and is dropped."""
    from dataclasses import replace

    return replace(state, u=quantised(state.u), v=quantised(state.v), last_check=None)


def _structure(state) -> np.ndarray:
    return (1.0 - state.u).astype(np.float32)


class GrowthRun:
    """One direction's last run (what `structures_value` is made of): state, why and where it stopped, seconds,
    cell updates (cells x steps) and its G history."""

    def __init__(self, state, reason, stop_step, seconds, updates, history):
        self.state, self.reason, self.stop_step = state, reason, int(stop_step)
        self.seconds, self.updates = float(seconds), float(updates)
        self.history = np.asarray(history, dtype=np.float64).reshape(-1, 2)


def structures_value(fields, directions, iso, runs, *, edits, regrown, changed, rate=None) -> RDStructuresValue:
    """The node's value of one `GrowthRun` per direction on the growth-grid ``fields``;
    ``rate`` (cell updates per second) defaults to the runs' updates over their seconds."""
    seconds = sum(r.seconds for r in runs)
    if rate is None:
        rate = sum(r.updates for r in runs) / seconds if seconds > 0 else 0.0
    return RDStructuresValue(
        s=np.stack([_structure(r.state) for r in runs]), directions=tuple(int(i) for i in directions),
        fields=fields, iso=float(iso), steps=tuple(int(r.state.step) for r in runs),
        stop_reasons=tuple(r.reason for r in runs), stop_steps=tuple(r.stop_step for r in runs),
        g_history=tuple(r.history for r in runs), seconds=tuple(r.seconds for r in runs),
        cell_updates_per_second=float(rate), states=tuple(r.state for r in runs), edits=tuple(edits),
        regrown=regrown, changed=changed)


def edit_region(shape, edit, index) -> np.ndarray:
    """Cells one canonical brush edit covers (a disc / ball per centre)."""
    from engine.rd.regrow import brush_region

    centres = [edit["centre"]] if "centre" in edit else edit["centres"]
    region = np.zeros(shape, dtype=bool)
    for c in centres:
        if len(c) != len(shape):
            raise GrowthInputError(f"edit {index}: a centre has {len(c)} coordinates; the growth grid is "
                                   f"{len(shape)}D", "edits")
        region |= brush_region(shape, c, edit["radius"])
    if not region.any():
        raise GrowthInputError(f"edit {index} ({edit['mode']}) covers no cell of the {list(shape[::-1])} growth "
                               f"grid (centres in growth-grid cells, x first)", "edits")
    return region


def _union(a, b):
    if a is None:
        return b
    return tuple((min(p[0], q[0]), max(p[1], q[1])) for p, q in zip(a, b))


def regrow_all(previous: RDStructuresValue, new_edits, params: dict, *, progress=None, done=0,
               total=None) -> RDStructuresValue:
    """Apply ``new_edits`` one after the other to every direction of
    ``previous`` and regrow each locally (engine.rd.regrow): only a window
    around the edit changes, everything else keeps its bytes.  ``progress`` is
    reported on a bar of ``total`` equal shares of which ``done`` are behind
    (one share per direction and edit).  Raises GrowthInputError, Cancelled."""
    from engine.rd.regrow import regrow

    fields = previous.fields
    shape = fields.grid_shape
    inside = fields.rho >= previous.iso
    n_dir = len(previous.directions)
    total = total or n_dir * len(new_edits)
    states = list(previous.states)
    last = [None] * n_dir
    seconds, updates, box = 0.0, 0.0, None
    k = done
    first = len(previous.edits)
    for e, edit in enumerate(new_edits):
        index = first + e
        region = edit_region(shape, edit, index)
        if not (region & inside).any():
            raise GrowthInputError(f"edit {index} ({edit['mode']}) lies outside the infill space "
                                   f"(rho >= iso): nothing there can grow", "edits")
        margin = max(MIN_MARGIN, int(math.ceil(edit["radius"])))
        for j in range(n_dir):
            try:
                res = regrow(states[j], fields.rho, fields.rotation, region=region, mode=edit["mode"],
                             gamma_map=fields.gamma, iso=previous.iso, margin=margin, eps=params["eps"],
                             max_steps=params["max_steps"], progress=stage(progress, k / total, 1 / total))
            except ValueError as exc:
                raise GrowthInputError(f"edit {index}: {exc}", "edits") from None
            if res.stop_reason == "cancelled":
                raise Cancelled(f"regrowth of edit {index} cancelled")
            states[j] = canonical_state(res.state)
            window = tuple((s.start, s.stop) for s in res.box)
            cells = math.prod(b - a for a, b in window)
            last[j] = GrowthRun(states[j], res.stop_reason, res.steps, res.wall_time, cells * res.steps, res.history)
            seconds += res.wall_time
            updates += cells * res.steps
            box = _union(box, window)
            k += 1
    if not new_edits:
        return previous
    rate = updates / seconds if seconds > 0 else 0.0
    return structures_value(fields, previous.directions, previous.iso, last,
                            edits=tuple(previous.edits) + tuple(new_edits), regrown=True, changed=box, rate=rate)


# ------------------------------------------------------------------ project-file blob

def _pack8(a) -> str:
    """uint8 levels of ``a`` (already quantised), differenced (mod 256), zlib, base64."""
    q = np.rint(np.asarray(a, dtype=np.float64) * LEVELS).astype(np.uint8).ravel()
    diff = np.diff(q, prepend=np.uint8(0)).astype(np.uint8)
    return base64.b64encode(zlib.compress(diff.tobytes(), 9)).decode("ascii")


def _unpack8(text: str, shape) -> np.ndarray:
    n = math.prod(shape)
    raw = zlib.decompress(base64.b64decode(text.encode("ascii"), validate=True))
    if len(raw) != n:
        raise ValueError(f"a stored field has {len(raw)} values, expected {n} for the grid {list(shape)}")
    q = np.cumsum(np.frombuffer(raw, np.uint8), dtype=np.uint8)
    return (q.astype(np.float64) / LEVELS).reshape(shape)


def _pack64(a) -> str:
    return base64.b64encode(zlib.compress(np.ascontiguousarray(a, "<f8").tobytes(), 6)).decode("ascii")


def _unpack64(text: str) -> np.ndarray:
    return np.frombuffer(zlib.decompress(base64.b64decode(text.encode("ascii"), validate=True)), "<f8").copy()


def encode_structures(value: RDStructuresValue) -> dict | None:
    """The grown state as JSON-able data, or None when it has no resumable states."""
    if value.states is None:
        return None
    return {
        "format": BLOB_FORMAT, "grid": list(value.fields.grid_shape), "directions": list(value.directions),
        "iso": value.iso, "steps": list(value.steps), "stop_reasons": list(value.stop_reasons),
        "stop_steps": list(value.stop_steps), "seconds": list(value.seconds),
        "cell_updates_per_second": value.cell_updates_per_second, "edits": list(value.edits),
        "regrown": value.regrown,
        "changed": None if value.changed is None else [list(p) for p in value.changed],
        "g_history": [_pack64(g) for g in value.g_history],
        "states": [{"u": _pack8(st.u), "v": _pack8(st.v), "step": int(st.step), "time": float(st.time),
                    "params": st.params.to_dict(), "direction": int(st.direction), "inputs": st.inputs,
                    "history": _pack64(st.history)} for st in value.states],
    }


def decode_structures(blob: dict, source: RDFieldsValue) -> RDStructuresValue:
    """Rebuild ``encode_structures``'s value against the node's input ``source``."""
    from engine.nodes.rd import growth_fields
    from engine.rd.gray_scott import RDParams
    from engine.rd.growth import RDState

    if not isinstance(blob, dict) or blob.get("format") != BLOB_FORMAT:
        raise ValueError(f"expected a stored growth of format {BLOB_FORMAT!r}")
    try:
        shape = tuple(int(n) for n in blob["grid"])
        if len(shape) != source.ndim:
            raise ValueError(f"the stored growth is {len(shape)}D, the connected fields {source.ndim}D")
        fields = growth_fields(source, shape)
        states = []
        for st in blob["states"]:
            history = _unpack64(st["history"]).reshape(-1, 2)
            states.append(RDState(_unpack8(st["u"], shape), _unpack8(st["v"], shape), int(st["step"]),
                                  float(st["time"]), RDParams.from_dict(st["params"]), int(st["direction"]),
                                  str(st["inputs"]), history))
        _check_digests(states, fields, float(blob["iso"]))
        histories = [_unpack64(g).reshape(-1, 2) for g in blob["g_history"]]
        runs = [GrowthRun(*args, 0.0, g) for args, g in zip(
            zip(states, blob["stop_reasons"], blob["stop_steps"], blob["seconds"]), histories)]
        if not runs or not len(runs) == len(blob["directions"]) == len(blob["stop_reasons"]) == len(histories):
            raise ValueError("the stored growth has a state per direction missing")
        changed = blob.get("changed")
        return structures_value(fields, blob["directions"], float(blob["iso"]), runs, edits=tuple(blob["edits"]),
                      regrown=bool(blob["regrown"]),
                      changed=None if changed is None else tuple((int(a), int(b)) for a, b in changed),
                      rate=float(blob["cell_updates_per_second"]))
    except (KeyError, TypeError, IndexError, zlib.error, base64.binascii.Error) as exc:
        raise ValueError(f"malformed stored growth ({type(exc).__name__}: {exc})") from None


def _check_digests(states, fields, iso) -> None:
    """ValueError unless every state was grown on these fields (the kernel's input digest)."""
    from engine.rd.growth import prepare_inputs

    for st in states:
        try:
            inputs = prepare_inputs(fields.rho, fields.rotation, direction=st.direction, gamma_map=fields.gamma,
                                    iso=iso, params=st.params)
        except ValueError as exc:
            raise ValueError(f"the stored growth does not fit the connected fields ({exc})") from None
        if inputs.digest != st.inputs:
            raise ValueError("the RD fields changed since this growth was stored")


# ------------------------------------------------------------------ variable thickness

def graded_thickness(magnitude, mu: float, inside) -> np.ndarray:
    """Relative thickness field for eq. 17: ``mu (1 + t) / 2`` with ``t`` the
    principal stress magnitude over its 95th percentile in the infill space,
    clipped to [0, 1]; unstressed members get half of ``mu``, the most
    stressed 5 % all of it."""
    m = np.abs(np.asarray(magnitude, dtype=np.float64))
    ref = float(np.percentile(m[inside], 95)) if np.any(inside) else 0.0
    t = np.clip(m / ref, 0.0, 1.0) if ref > 0 else np.ones_like(m)
    return np.clip(0.5 * mu * (1.0 + t), 0.0, 1.0)
