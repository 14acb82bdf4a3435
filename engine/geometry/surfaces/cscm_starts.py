"""Where the edge-length search of :mod:`.cscm` starts, and which of its
results becomes the patch.

A free-boundary problem can have more than one solution for the same loop
combinatorics, and CONTOURENERGY vanishes (up to discretisation) at each of
them, so no energy-based rule can tell them apart. The Schwarz P hexagon
in the cube [0, 1/2]^3 is the case in point: besides Schwarz P (dual edge
lengths all equal) a tetragonal member of Schwarz's tP family also meets
all six faces at right angles with a cubic cell. Its dual is a box with
one side shorter (c/a = 0.630, 0.633, 0.634 at 36, 72 and 128 boundary
pieces, so it is not a discretisation artefact), there are three of them
(one per axis) and its area is 0.23% larger than Schwarz P. Nelder-Mead
falls into whichever basin the three-case heuristic's lengths lie in; the
heuristic depends on where the user placed the loop vertices on their
edges, and near a basin boundary a 1e-9 change of one vertex (or a
different BLAS kernel) moves the result from one patch to the other.

So the result must not depend on the start alone:

* The search runs from the heuristic lengths of the user's loop and from
  those of the *canonical* loop: the same loop with every vertex moved to
  the midpoint of its FBV edge (vertices sharing an edge spread evenly
  along it, in their order). The canonical start depends only on the FBV
  and the loop's combinatorics, which is all a free boundary fixes.
* Of the runs whose energy is at most ``SOLVED_ENERGY`` (a solution up to
  discretisation), the one with the least area wins -- the patch is a
  minimal surface, so among solutions the minimal one is taken. Runs
  within ``AREA_TIE`` of the least area count as the same solution (or
  symmetric copies) and the earliest start among them wins, so a user
  start that already finds the least-area patch keeps its exact result. If no run is a solution,
  the lowest energy wins (ties: the earlier start).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dual_contour import initial_lengths
from .fbv import conjugate_violations

__all__ = ["SearchStart", "canonical_loop_points", "search_starts", "choose_run",
           "SOLVED_ENERGY", "AREA_TIE"]

# Contour energy (dimensionless) below which a run counts as a solution:
# converged runs reach 1e-9 to 3e-6 at the default search resolution, and
# the node warns above 1e-3.
SOLVED_ENERGY = 1e-5
# Relative area difference below which two runs count as one solution.
# Measured at the default search resolution: the same patch reached from
# two starts differs by up to 1.3e-4 (the lengths stop within the search's
# xatol), Schwarz P and the tetragonal tP member by 2.4e-3 to 2.6e-3.
AREA_TIE = 5e-4
# Two starts whose closed lengths agree to this (relative, after scaling
# out the size) run the same search; the later one is skipped.
SAME_START = 1e-9


@dataclass(frozen=True)
class SearchStart:
    """One start of the edge-length search.

    Attributes
    ----------
    name : str
        ``'user'`` (heuristic lengths at the user's vertex positions, or the
        ``initial`` lengths passed in) or ``'canonical'``.
    lengths : (k,) float64
        Initial dual edge lengths (model units of the dual).
    """

    name: str
    lengths: np.ndarray


def canonical_loop_points(fbv, loop):
    """The loop with every vertex at a fixed place on its FBV edge.

    Each vertex moves along its edge to the midpoint; ``m`` vertices on one
    edge go to the fractions ``1/(m+1) ... m/(m+1)`` in the order they had
    along it. The combinatorics (which edge, which faces) stay the same.

    Parameters
    ----------
    fbv : BoundingVolume
    loop : LoopOnFBV
        A checked conjugate loop.

    Returns
    -------
    (k, 3) float64 or None
        None when a vertex's edge is not a segment between two corners.
    """
    p = np.asarray(loop.points, dtype=np.float64)
    edges = {}
    for i, planes in enumerate(loop.vertex_planes):
        edges.setdefault(tuple(sorted(int(k) for k in planes)), []).append(i)
    out = p.copy()
    for (a, b), members in sorted(edges.items()):
        ends = fbv.edge_corners(a, b)
        if len(ends) != 2:
            return None
        c0, c1 = fbv.corners[ends[0]], fbv.corners[ends[1]]
        axis = c1 - c0
        t = (p[members] - c0) @ axis / float(axis @ axis)
        order = np.asarray(members)[np.argsort(t, kind="stable")]
        m = order.size
        out[order] = c0 + (np.arange(1, m + 1) / (m + 1))[:, None] * axis
    return out


def _same_direction(a, b):
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    return bool(np.max(np.abs(a - b)) <= SAME_START)


def search_starts(fbv, loop, user_lengths, *, canonical=True):
    """The starts of the search: the user's, then the canonical one.

    Parameters
    ----------
    fbv : BoundingVolume
    loop : LoopOnFBV
    user_lengths : (k,) float
        Initial lengths of the user's loop (model units).
    canonical : bool
        Add the canonical start (skipped when its loop breaks an FBV rule,
        changes the arcs' planes, or gives the user's lengths up to scale).

    Returns
    -------
    list of SearchStart
    """
    starts = [SearchStart("user", np.asarray(user_lengths, dtype=np.float64))]
    if not canonical:
        return starts
    points = canonical_loop_points(fbv, loop)
    if points is None:
        return starts
    found, other = conjugate_violations(fbv, points)
    if found or not np.array_equal(other.arc_planes, loop.arc_planes):
        return starts
    lengths = initial_lengths(fbv, other)
    if np.all(lengths > 0.0) and not _same_direction(lengths, starts[0].lengths):
        starts.append(SearchStart("canonical", lengths))
    return starts


def choose_run(energies, areas, *, solved_energy=SOLVED_ENERGY, area_tie=AREA_TIE):
    """Index of the run whose patch is kept (rule in the module docstring).

    Parameters
    ----------
    energies : (r,) float
        Final contour energy of each run, in start order.
    areas : (r,) float
        Area of each run's patch (scaled to the FBV, model units squared);
        only compared between runs that are solutions.

    Returns
    -------
    int
    """
    e = np.asarray(energies, dtype=np.float64)
    a = np.asarray(areas, dtype=np.float64)
    solved = np.flatnonzero(e <= solved_energy)
    if solved.size == 0:
        return int(np.argmin(e))                    # first of equal minima
    if solved.size == 1:
        return int(solved[0])
    least = float(a[solved].min())
    return int(solved[np.flatnonzero(a[solved] <= least * (1.0 + area_tie))[0]])
