"""What the study plots show, computed from a study file's rows (no Qt).

A study or database file (``engine.batch.study``) holds one row per sample.
``group_study`` splits the rows into hint groups -- rows with the same
``set`` and the same requested block-hint vector (``hint_<block>``) -- and
gives each group the points of the Fig. 3B / 4A scatter (``E_avg/E_s``,
``nu_avg`` of its status-ok rows), their means, and the requested next to the
realised block probabilities (fig. S3A). ``directional_modulus`` is the
in-plane Young's modulus ``E(theta) / E_s`` of one row, from its stored ``C``;
``group_directional_modulus`` the mean of those curves over a group.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine.growth.properties import directional_young_in_plane

from .sample import STATUS_OK, STATUS_SINGULAR
from .rows import read_rows

__all__ = ["StudyGroup", "study_blocks", "group_study", "stiffness_of", "directional_modulus",
           "group_directional_modulus", "load_study"]


@dataclass(frozen=True)
class StudyGroup:
    """The rows of one hint group.

    Attributes
    ----------
    set : int, the rows' ``set`` cell
    hints_text : str, the ``hints`` cell of the group's first row (as requested)
    blocks : tuple of str, block names, the order of ``requested`` and ``realised``
    requested : (n_blocks,) float64, normalised requested block hints
    realised : (n_blocks,) float64
        Mean realised block probabilities over the rows that grew (status ok or
        singular); NaN when none did.
    E : (n_ok,) float64, ``E_avg / E_s`` of the status-ok rows, in row order
    nu : (n_ok,) float64, ``nu_avg`` of the same rows
    rows : tuple of dict, every row of the group, sorted by ``index``
    """

    set: int
    hints_text: str
    blocks: tuple
    requested: np.ndarray
    realised: np.ndarray
    E: np.ndarray
    nu: np.ndarray
    rows: tuple

    @property
    def n_samples(self) -> int:
        return len(self.rows)

    @property
    def n_ok(self) -> int:
        return int(self.E.size)

    @property
    def E_mean(self) -> float:
        return float(np.mean(self.E)) if self.E.size else math.nan

    @property
    def nu_mean(self) -> float:
        return float(np.mean(self.nu)) if self.nu.size else math.nan

    def count(self, status: str) -> int:
        return sum(r.get("status") == status for r in self.rows)


def study_blocks(rows) -> tuple:
    """Block names of a study file, in column order, from its ``p_<block>`` cells."""
    if not rows:
        return ()
    return tuple(k[2:] for k in rows[0] if k.startswith("p_"))


def _ok(row) -> bool:
    e, nu = row.get("E_avg/E_s"), row.get("nu_avg")
    return (row.get("status") == STATUS_OK and isinstance(e, (int, float))
            and isinstance(nu, (int, float)) and math.isfinite(e) and math.isfinite(nu))


def group_study(rows) -> list:
    """Split study rows into hint groups.

    Parameters
    ----------
    rows : list of dict, as ``read_study`` returns them

    Returns
    -------
    list of StudyGroup, ordered by ``set`` and then by first appearance.
    """
    if not rows:
        return []
    blocks = study_blocks(rows)
    need = ["set", "index", "status", "E_avg/E_s", "nu_avg"] + [f"hint_{b}" for b in blocks]
    missing = [c for c in need if c not in rows[0]]
    if not blocks or missing:
        raise ValueError(f"the rows lack the columns {missing or ['p_<block>']}: they are not "
                         f"from a study file")
    order: dict = {}
    for r in rows:
        key = (int(r["set"]), tuple(float(r[f"hint_{b}"]) for b in blocks))
        order.setdefault(key, []).append(r)
    groups = []
    for (s, req), members in sorted(order.items(), key=lambda kv: kv[0][0]):
        members = sorted(members, key=lambda r: r["index"])
        grown = [r for r in members if r["status"] in (STATUS_OK, STATUS_SINGULAR)]
        p = np.array([[float(r[f"p_{b}"]) for b in blocks] for r in grown], dtype=np.float64)
        realised = p.mean(axis=0) if grown else np.full(len(blocks), np.nan)
        ok = [r for r in members if _ok(r)]
        hints = members[0].get("hints")
        groups.append(StudyGroup(
            set=s, hints_text="" if hints is None else str(hints), blocks=blocks,
            requested=np.array(req, dtype=np.float64), realised=realised,
            E=np.array([float(r["E_avg/E_s"]) for r in ok], dtype=np.float64),
            nu=np.array([float(r["nu_avg"]) for r in ok], dtype=np.float64),
            rows=tuple(members)))
    return groups


def stiffness_of(row) -> np.ndarray:
    """The row's homogenized stiffness: (3, 3) in 2D or (6, 6) in 3D, float64, Voigt
    order with engineering shear (NaN entries for a row that failed)."""
    n = 6 if "C66" in row else 3
    C = np.empty((n, n), dtype=np.float64)
    for i in range(n):
        for j in range(i, n):
            v = row.get(f"C{i + 1}{j + 1}")
            C[i, j] = C[j, i] = math.nan if v is None else float(v)
    return C


def directional_modulus(row, *, n: int = 180):
    """In-plane Young's modulus of one row along ``(cos t, sin t[, 0])``, over ``E_s``.

    Parameters
    ----------
    row : dict, a study row
    n : int >= 3, number of angles ``t_k = 2 pi k / n``

    Returns
    -------
    theta : (n,) float64, radians
    E : (n,) float64, ``E(theta) / E_s``; NaN for a mechanism or a failed sample
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3:
        raise ValueError(f"n must be an integer >= 3; got {n!r}")
    theta = 2 * np.pi * np.arange(n) / n
    C = stiffness_of(row)
    if row.get("status") != STATUS_OK or not np.all(np.isfinite(C)):
        return theta, np.full(n, np.nan)
    e_s = float(row.get("E_s") or 1.0)
    return theta, directional_young_in_plane(C, theta) / e_s


def group_directional_modulus(group: StudyGroup, *, n: int = 180):
    """Mean over the group's status-ok rows of :func:`directional_modulus`
    (the mean curve, not the curve of the mean ``C``); NaN if no row is ok."""
    curves = [directional_modulus(r, n=n) for r in group.rows if _ok(r)]
    theta = 2 * np.pi * np.arange(n) / n
    if not curves:
        return theta, np.full(n, np.nan)
    return theta, np.nanmean(np.stack([e for _, e in curves]), axis=0)


def load_study(path) -> list:
    """Rows of a study file made by ``mesoforge study``: ``*.csv``, or ``*.parquet``
    (its row journal ``*.parquet.rows.csv``, or the Parquet file itself with pyarrow)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise ValueError(f"{str(p)!r}: a study file ends in .csv or .parquet")
    journal = p.with_name(p.name + ".rows.csv") if suffix == ".parquet" else p
    if journal.exists():
        rows = read_rows(journal)
    elif suffix == ".parquet" and p.exists():
        try:
            import pyarrow.parquet as pq
        except ImportError:
            raise ValueError(f"{str(p)!r}: reading Parquet needs pyarrow (not installed) "
                             f"or its journal {journal.name!r}") from None
        rows = pq.read_table(p).to_pylist()
    else:
        raise ValueError(f"{str(p)!r}: no such file")
    missing = [c for c in ("set", "index", "status", "hints") if rows and c not in rows[0]]
    if missing:
        raise ValueError(f"{str(p)!r} has no {', '.join(map(repr, missing))} column: it is not "
                         f"a study file")
    return sorted(rows, key=lambda r: (r["set"], r["index"]))
