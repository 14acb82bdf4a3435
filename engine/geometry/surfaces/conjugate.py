"""The discrete conjugate of a discrete minimal surface (Pinkall & Polthier
1993; Polthier's non-conforming, edge-midpoint conjugation).

A piecewise-linear map is harmonic when its cotan Laplacian vanishes at the
interior vertices. Inside one triangle ``T`` with unit normal ``N_T`` the
conjugate differential is the quarter turn ``J_T v = N_T x v`` of the
differential of the surface. The conjugate values live on *edge midpoints*:
two midpoints of ``T`` differ by half of an edge vector of ``T``, so their
conjugates must differ by the quarter turn of that half edge. Walking
around an interior vertex through the ring of its incident triangles, these
differences sum to the rotated cotan Laplacian at that vertex, which is zero
for a discrete minimal surface: the conjugate is single-valued on the
midpoints (up to one global translation) without any further condition.

Consequences used by the tests and by :mod:`.cscm`:

* each conjugate midpoint triangle is the original midpoint triangle turned
  by 90 degrees about ``N_T`` -- normals are preserved exactly (Prop. 4.1a of
  Makatura et al. 2023) and the midpoint mesh is an exact isometry;
* a straight boundary segment along ``d`` becomes a curve in a plane
  orthogonal to ``d`` (Prop. 4.1c), up to the tangential boundary force the
  fixed-boundary Plateau solver leaves on the segment.

Outputs, both provided:

* the *midpoint* conjugate (one position per undirected edge), with the
  edge-midpoint triangles as connectivity (non-conforming: the midpoint
  triangles of neighbouring faces share corners but leave the vertex stars
  uncovered);
* a conforming mesh on the *original* connectivity ("mapped back to
  vertices"): each face predicts its corners from its three midpoints
  (``a = m_ab + m_ca - m_bc``), and a vertex takes the angle-weighted mean of
  its faces' predictions. This is what :mod:`.cscm` tiles and snaps.
"""

from __future__ import annotations

import hashlib
import threading
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .curvature import validate_mesh

__all__ = ["ConjugateSurface", "conjugate_surface", "midpoint_mesh", "mesh_edges", "corner_angles"]


@dataclass(frozen=True)
class ConjugateSurface:
    """Result of :func:`conjugate_surface`.

    Attributes
    ----------
    vertices : (n, 3) float64, read-only
        Conjugate mapped back to the input vertices (conforming mesh with the
        input ``faces``), model units.
    faces : (m, 3) int64, read-only
        The input faces.
    midpoints : (e, 3) float64, read-only
        Conjugate value at every edge midpoint.
    edges : (e, 2) int64, read-only
        Undirected edges, ``edges[k]`` carries ``midpoints[k]``.
    face_edges : (m, 3) int64, read-only
        ``face_edges[t, k]`` is the edge opposite corner ``k`` of face ``t``;
        ``midpoints[face_edges]`` are the midpoint triangles.
    closure_error : float
        Largest mismatch of the per-face midpoint differences after the
        least-squares integration (model units); near zero iff the input
        is discrete minimal (harmonic) at its interior vertices.
    """

    vertices: np.ndarray
    faces: np.ndarray
    midpoints: np.ndarray
    edges: np.ndarray
    face_edges: np.ndarray
    closure_error: float


def mesh_edges(faces, n_vertices):
    """Undirected edges of a triangle mesh and the edge opposite each corner.

    Returns
    -------
    (edges (e, 2) int64 with edges[:, 0] < edges[:, 1], face_edges (m, 3) int64)
    """
    f = np.asarray(faces, dtype=np.int64)
    opp = np.concatenate([f[:, [1, 2]], f[:, [2, 0]], f[:, [0, 1]]])   # opposite corner 0, 1, 2
    key = np.sort(opp, axis=1)
    code = key[:, 0] * n_vertices + key[:, 1]
    uniq, inverse = np.unique(code, return_inverse=True)
    edges = np.column_stack([uniq // n_vertices, uniq % n_vertices]).astype(np.int64)
    return edges, inverse.reshape(3, -1).T.astype(np.int64)


def corner_angles(vertices, faces):
    """Interior angle (radians) at every corner, shape (m, 3)."""
    p = vertices[faces]
    out = np.empty(faces.shape)
    for k in range(3):
        a = p[:, (k + 1) % 3] - p[:, k]
        b = p[:, (k + 2) % 3] - p[:, k]
        out[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1),
                               np.einsum("ij,ij->i", a, b))
    return out


def _face_normals(v, f):
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0.0)


class _MidpointGraph:
    """Connectivity-only pieces of the conjugation, cached per face array.

    The midpoint differences of all faces form an overdetermined system
    ``D x = d`` (three rows per face); its normal equations are the graph
    Laplacian of the midpoint graph with edge 0 pinned, factorised once.
    """

    def __init__(self, faces, n_vertices):
        self.edges, self.face_edges = mesh_edges(faces, n_vertices)
        fe = self.face_edges
        m, ne = fe.shape[0], self.edges.shape[0]
        # Row 3t+k asks m(opp k+1) - m(opp k) = d.
        i = np.concatenate([fe[:, k] for k in range(3)])
        j = np.concatenate([fe[:, (k + 1) % 3] for k in range(3)])
        rows = np.arange(3 * m)
        self.diff = sp.csr_matrix((np.concatenate([-np.ones(3 * m), np.ones(3 * m)]),
                                   (np.concatenate([rows, rows]), np.concatenate([i, j]))),
                                  shape=(3 * m, ne))
        normal = (self.diff.T @ self.diff).tolil()
        normal[0, :] = 0.0
        normal[0, 0] = 1.0
        self.lu = splu(normal.tocsc())

    def integrate(self, d):
        rhs = self.diff.T @ d
        rhs[0] = 0.0
        x = self.lu.solve(np.ascontiguousarray(rhs))
        err = np.linalg.norm(self.diff @ x - d, axis=1)
        return x, float(err.max()) if err.size else 0.0


_GRAPHS: dict = {}
_GRAPH_CACHE_SIZE = 8
_GRAPH_LOCK = threading.Lock()


def _midpoint_graph(faces, n_vertices):
    """Cached :class:`_MidpointGraph`, keyed on the face array's content."""
    key = (n_vertices, faces.shape, hashlib.sha1(np.ascontiguousarray(faces).tobytes()).hexdigest())
    with _GRAPH_LOCK:
        graph = _GRAPHS.get(key)
    if graph is None:
        graph = _MidpointGraph(faces, n_vertices)
        with _GRAPH_LOCK:
            if len(_GRAPHS) >= _GRAPH_CACHE_SIZE:
                _GRAPHS.pop(next(iter(_GRAPHS)))
            _GRAPHS[key] = graph
    return graph


def conjugate_surface(vertices, faces, *, sign=1):
    """Discrete conjugate of a discrete minimal (harmonic) disc mesh.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
        Discrete minimal surface (e.g. a Plateau solution), model units.
    faces : array_like, shape (m, 3), int
        Consistently oriented triangles; the face normals' orientation fixes
        the direction of the quarter turn.
    sign : {1, -1}
        ``1`` rotates by +90 degrees about the normal (``J v = N x v``),
        ``-1`` by -90 degrees; the two results are point reflections of one
        another (the associate family at +-90 degrees).

    Returns
    -------
    ConjugateSurface
        Positions are defined up to one translation; the conjugate is
        returned with its vertex centroid at the origin.

    Raises
    ------
    ValueError
        Bad mesh or ``sign``.
    """
    if sign not in (1, -1):
        raise ValueError(f"sign must be 1 or -1; got {sign!r}")
    v, f = validate_mesh(vertices, faces)
    graph = _midpoint_graph(f, v.shape[0])
    edges, fe = graph.edges.copy(), graph.face_edges.copy()
    normal = _face_normals(v, f) * float(sign)
    # Midpoint opposite corner k+1 minus midpoint opposite corner k equals
    # half the edge from corner k+1 to corner k; its conjugate is that half
    # edge turned by 90 degrees about the face normal.
    d = np.concatenate([np.cross(normal, 0.5 * (v[f[:, k]] - v[f[:, (k + 1) % 3]]))
                        for k in range(3)])
    mid, closure = graph.integrate(d)
    verts = _vertices_from_midpoints(mid, f, fe, corner_angles(v, f), v.shape[0])
    shift = verts.mean(axis=0)
    verts -= shift
    mid -= shift
    for arr in (verts, f, mid, edges, fe):
        arr.setflags(write=False)
    return ConjugateSurface(vertices=verts, faces=f, midpoints=mid, edges=edges,
                            face_edges=fe, closure_error=closure)


def _vertices_from_midpoints(mid, f, fe, angles, n):
    """Angle-weighted mean of the corner positions each face predicts."""
    total = np.zeros((n, 3))
    weight = np.zeros(n)
    for k in range(3):
        k1, k2 = (k + 1) % 3, (k + 2) % 3
        # Corner k sits at m(opp k1) + m(opp k2) - m(opp k).
        guess = mid[fe[:, k1]] + mid[fe[:, k2]] - mid[fe[:, k]]
        np.add.at(total, f[:, k], guess * angles[:, k, None])
        np.add.at(weight, f[:, k], angles[:, k])
    return total / np.maximum(weight, 1e-300)[:, None]


def midpoint_mesh(conj):
    """The midpoint triangles of a :class:`ConjugateSurface` as a mesh.

    Returns
    -------
    (vertices (e, 3) float64, faces (m, 3) int64)
        One vertex per edge; a face per input face, joining its three edge
        midpoints. Covers a quarter of the surface (non-conforming).
    """
    return np.array(conj.midpoints), np.array(conj.face_edges[:, [0, 1, 2]])
