"""Property studies of several given hint groups in one database (Figs. 3B, 4A).

``study_hint_groups`` is :func:`engine.batch.study.sweep_hints` with the hint
vectors given instead of drawn from the simplex: group ``j`` is grown
``samples_per_group`` times, sample ``i`` of it with seed
``sample_seed(seed, j, i)`` and ``set = j`` in its row. So one file holds
every group, a run resumes group by group, and appending a group to the list
keeps the rows of the groups before it.
"""

from __future__ import annotations

from .sample import Sample, sample_seed
from .study import _check_hints, _check_int, _execute, make_config, summarise_rows
from .study_file import study_params

__all__ = ["study_hint_groups"]


def study_hint_groups(tileset, hint_groups, *, samples_per_group: int, seed: int = 0,
                      shape=(20, 20), periodic: bool = True, E: float = 1.0, nu: float = 0.46,
                      out_path=None, scheduler=None, n_workers: int = 2, progress=None,
                      resume: bool = True, availability=None, resolution: int | None = None,
                      line_width: float | None = None, radius: float = 0.2,
                      void: str = "removed", tol: float = 1e-6) -> dict:
    """Grow and homogenize ``samples_per_group`` tilings for each hint group.

    Parameters
    ----------
    tileset : TileSet, tile set name or path
    hint_groups : sequence of (dict name -> weight or None), at least one
        Block (``"T"``) or tile (``"T@1"``) weights of each group; None =
        uniform over blocks.
    samples_per_group : int >= 1
    seed : int >= 0, study seed; sample ``i`` of group ``j`` uses ``sample_seed(seed, j, i)``
    Other parameters as in :func:`engine.batch.study.run_study`.

    Returns
    -------
    dict
        ``n_groups, samples_per_group, n_samples``, the status counts
        ``n_done, n_ok, n_singular, n_error``, ``cancelled, n_new,
        n_resumed, seconds, out_path`` and ``sets``: per group ``{"set",
        "hints", "n_done", "n_ok", "E_avg", "nu_avg", "E_avg/E_s",
        "realised_probabilities"}``; ``rows`` when ``out_path`` is None.
    """
    config = make_config(tileset, shape=shape, periodic=periodic, availability=availability,
                         E=E, nu=nu, resolution=resolution, line_width=line_width,
                         radius=radius, void=void, tol=tol)
    per_group = _check_int("samples_per_group", samples_per_group, 1)
    seed = _check_int("seed", seed, 0)
    groups = list(hint_groups) if isinstance(hint_groups, (list, tuple)) else None
    if not groups:
        raise ValueError(f"hint_groups must be a non-empty list of hint dicts (or None for "
                         f"uniform); got {hint_groups!r}")
    ts = config.tileset
    hint_sets = []
    for j, h in enumerate(groups):
        try:
            hint_sets.append(_check_hints(ts, h, config.shape))
        except ValueError as exc:
            raise ValueError(f"hint group {j}: {exc}") from None
    samples = [Sample(j, i, sample_seed(seed, j, i), hint_sets[j])
               for j in range(len(hint_sets)) for i in range(per_group)]
    params = study_params(config, mode="groups", seed=seed, hints=hint_sets)
    run = _execute(config, samples, params=params, out_path=out_path, scheduler=scheduler,
                   n_workers=n_workers, progress=progress, resume=resume)
    by_set: dict = {j: [] for j in range(len(hint_sets))}
    for r in run["rows"]:
        by_set[r["set"]].append(r)
    sets = []
    for j, h in enumerate(hint_sets):
        s = summarise_rows(by_set[j], ts.block_names)
        sets.append({"set": j, "hints": h, "n_done": s["n_done"], "n_ok": s["n_ok"],
                     **{k: s[k] for k in ("E_avg", "nu_avg", "E_avg/E_s",
                                          "realised_probabilities")}})
    total = summarise_rows(run["rows"], ts.block_names)
    out = {"tileset": ts.name, "n_groups": len(hint_sets), "samples_per_group": per_group,
           "n_samples": len(samples),
           **{k: total[k] for k in ("n_done", "n_ok", "n_singular", "n_error")},
           **{k: run[k] for k in ("cancelled", "n_new", "n_resumed", "seconds", "out_path")},
           "sets": sets}
    if out_path is None:
        out["rows"] = run["rows"]
    return out
