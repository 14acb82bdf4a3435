"""Discrete differential quantities on triangle meshes: the cotan Laplacian,
mixed Voronoi areas, area and mean curvature.

Conventions, used by every solver in this package:

* ``L`` is the cotan Laplacian with off-diagonal entries
  ``L_ij = (cot a_ij + cot b_ij) / 2`` (the angles opposite edge ij; one term
  on a boundary edge) and rows summing to zero, so it is negative
  semi-definite and ``(L X)_i`` is minus the gradient of the area at vertex
  ``i`` (Pinkall & Polthier 1993).
* The mean-curvature normal is ``L X / A_mixed`` (Meyer et al. 2003), hence
  ``|H| = |L X|_i / (2 A_mixed,i)`` with ``H`` the mean of the principal
  curvatures: a sphere of radius r has ``|H| = 1 / r``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["validate_mesh", "corner_cotangents", "cotan_laplacian", "mixed_areas",
           "face_areas", "surface_area", "mean_curvature", "surface_report"]


def validate_mesh(vertices, faces):
    """Check and convert a triangle mesh.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
    faces : array_like, shape (m, 3), int
        Indices into ``vertices``.

    Returns
    -------
    (numpy.ndarray (n, 3) float64, numpy.ndarray (m, 3) int64)

    Raises
    ------
    ValueError
        Wrong shapes, non-finite coordinates, or face indices out of range.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (n, 3); got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or f.shape[0] == 0:
        raise ValueError(f"faces must have shape (m, 3) with m >= 1; got shape {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must hold integer indices; got dtype {f.dtype}")
    bad = np.flatnonzero(~np.all(np.isfinite(v), axis=1))
    if bad.size:
        raise ValueError(f"vertices must be finite; vertex {int(bad[0])} is {v[bad[0]].tolist()}")
    if f.min() < 0 or f.max() >= v.shape[0]:
        raise ValueError(f"faces index vertices 0..{v.shape[0] - 1}; got indices "
                         f"{int(f.min())}..{int(f.max())}")
    return v, f.astype(np.int64, copy=False)


def corner_cotangents(vertices, faces):
    """Cotangent of every triangle corner.

    Returns
    -------
    numpy.ndarray, shape (m, 3), float64
        Entry ``[t, k]`` is the cotangent of the angle at corner ``k`` of face
        ``t``, which is opposite the edge ``(faces[t, k+1], faces[t, k+2])``.
        Degenerate (zero-area) faces give 0, so they drop out of ``L``.
    """
    p = vertices[faces]                                   # (m, 3, 3)
    cots = np.empty((faces.shape[0], 3))
    for k in range(3):
        a = p[:, (k + 1) % 3] - p[:, k]
        b = p[:, (k + 2) % 3] - p[:, k]
        cross = np.linalg.norm(np.cross(a, b), axis=1)
        dot = np.einsum("ij,ij->i", a, b)
        with np.errstate(divide="ignore", invalid="ignore"):
            cots[:, k] = np.where(cross > 0.0, dot / cross, 0.0)
    return cots


def cotan_laplacian(vertices, faces):
    """Cotan Laplacian (negative semi-definite, rows sum to zero).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
        ``L_ij = (cot a_ij + cot b_ij) / 2`` for every edge ij.
    """
    n = vertices.shape[0]
    cots = corner_cotangents(vertices, faces)
    i = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
    j = np.concatenate([faces[:, 2], faces[:, 0], faces[:, 1]])
    w = 0.5 * np.concatenate([cots[:, 0], cots[:, 1], cots[:, 2]])
    off = sp.coo_matrix((w, (i, j)), shape=(n, n))
    off = (off + off.T).tocsr()
    return (off - sp.diags(np.asarray(off.sum(axis=1)).ravel())).tocsr()


def face_areas(vertices, faces):
    """Area of every face, shape (m,), float64 (model units squared)."""
    p = vertices[faces]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def surface_area(vertices, faces):
    """Total area of a triangle mesh (model units squared)."""
    v, f = validate_mesh(vertices, faces)
    return float(face_areas(v, f).sum())


def mixed_areas(vertices, faces):
    """Mixed Voronoi area per vertex (Meyer et al. 2003).

    Voronoi areas inside non-obtuse triangles; for an obtuse triangle half its
    area goes to the obtuse corner and a quarter to each of the others, so the
    areas are positive and sum to the mesh area.

    Returns
    -------
    numpy.ndarray, shape (n,), float64
    """
    n = vertices.shape[0]
    p = vertices[faces]
    area = face_areas(vertices, faces)
    cots = corner_cotangents(vertices, faces)
    sq = np.stack([np.sum((p[:, (k + 2) % 3] - p[:, (k + 1) % 3]) ** 2, axis=1)
                   for k in range(3)], axis=1)            # squared edge opposite corner k
    obtuse = cots < 0.0
    any_obtuse = obtuse.any(axis=1)
    out = np.zeros(n)
    for k in range(3):
        # Voronoi share of corner k: the two edges at k, weighted by the
        # cotangents of the angles opposite them.
        voronoi = (sq[:, (k + 1) % 3] * cots[:, (k + 1) % 3]
                   + sq[:, (k + 2) % 3] * cots[:, (k + 2) % 3]) / 8.0
        share = np.where(any_obtuse, np.where(obtuse[:, k], area / 2.0, area / 4.0), voronoi)
        np.add.at(out, faces[:, k], share)
    return out


def mean_curvature(vertices, faces):
    """Unsigned discrete mean curvature per vertex.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
    faces : array_like, shape (m, 3), int

    Returns
    -------
    numpy.ndarray, shape (n,), float64
        ``|H| = |L X| / (2 A_mixed)`` (1 / model units). Meaningless on
        boundary vertices, where ``L X`` is the boundary's curvature force.
    """
    v, f = validate_mesh(vertices, faces)
    lx = cotan_laplacian(v, f) @ v
    a = mixed_areas(v, f)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a > 0.0, np.linalg.norm(lx, axis=1) / (2.0 * a), 0.0)


def surface_report(vertices, faces, boundary):
    """Area and mean-curvature statistics of a surface patch.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
    faces : array_like, shape (m, 3), int
    boundary : array_like of int
        Boundary vertex indices, excluded from the curvature statistics.

    Returns
    -------
    dict
        ``area`` (model units squared); ``max_abs_H`` and ``mean_abs_H``
        (1 / model units) over interior vertices, the mean weighted by mixed
        area. Both are 0 for a mesh with no interior vertex.
    """
    v, f = validate_mesh(vertices, faces)
    interior = np.ones(v.shape[0], dtype=bool)
    b = np.asarray(boundary, dtype=np.int64).ravel()
    if b.size and (b.min() < 0 or b.max() >= v.shape[0]):
        raise ValueError(f"boundary indexes vertices 0..{v.shape[0] - 1}; got "
                         f"{int(b.min())}..{int(b.max())}")
    interior[b] = False
    interior &= np.bincount(f.ravel(), minlength=v.shape[0]) > 0
    h = mean_curvature(v, f)[interior]
    weights = mixed_areas(v, f)[interior]
    if h.size == 0:
        return {"area": float(face_areas(v, f).sum()), "max_abs_H": 0.0, "mean_abs_H": 0.0}
    return {"area": float(face_areas(v, f).sum()),
            "max_abs_H": float(h.max()),
            "mean_abs_H": float(np.sum(h * weights) / np.sum(weights))}
