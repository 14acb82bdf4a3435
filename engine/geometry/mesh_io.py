"""Mesh export / import for the Object node (STL, OBJ, PLY, 3MF).

All four formats go through trimesh (3MF needs lxml and networkx, which are
dependencies for that reason).

Every export is atomic: the file is written to a temporary sibling, fsynced
and renamed over the target, so a crash never leaves a truncated mesh.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from engine.fileio import write_atomic

__all__ = ["export_mesh", "load_mesh", "mesh_summary", "SUPPORTED_SUFFIXES"]

SUPPORTED_SUFFIXES = (".stl", ".obj", ".ply", ".3mf")

def _suffix(path):
    suffix = Path(path).suffix.lower()
    if suffix not in SUPPORTED_SUFFIXES:
        raise ValueError(f"path must end in one of {', '.join(SUPPORTED_SUFFIXES)}; "
                         f"got {str(path)!r}")
    return suffix


def _check_mesh(vertices, faces):
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
        raise ValueError(f"vertices must be a finite (v, 3) array; got shape {v.shape}")
    f = np.asarray(faces)
    if f.ndim != 2 or f.shape[1] != 3 or f.shape[0] == 0 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be a non-empty integer (f, 3) array; got shape {f.shape} "
                         f"dtype {f.dtype}")
    f = f.astype(np.int64)
    if f.min() < 0 or f.max() >= v.shape[0]:
        raise ValueError(f"faces must index vertices 0..{v.shape[0] - 1}; got {f.min()}..{f.max()}")
    return v, f


def export_mesh(vertices, faces, path):
    """Write a triangle mesh, format chosen by the file suffix.

    Parameters
    ----------
    vertices : array_like, shape (v, 3), float
        Model units (3MF declares millimetres).
    faces : array_like, shape (f, 3), int
        Non-empty; vertex indices.
    path : str or os.PathLike
        Ends in .stl (binary), .obj, .ply (binary) or .3mf (any case). The
        directory must exist; an existing file is replaced atomically.
    """
    suffix = _suffix(path)
    v, f = _check_mesh(vertices, faces)
    if suffix == ".stl":          # chunked, trimesh's bytes (engine.geometry.stl_encode)
        from .stl_encode import binary_stl

        write_atomic(path, binary_stl(v, f))
        return
    import trimesh

    data = trimesh.Trimesh(v, f, process=False).export(file_type=suffix[1:])
    if isinstance(data, str):
        data = data.encode("utf-8")
    write_atomic(path, data)


def load_mesh(path):
    """Read a mesh written by :func:`export_mesh` (or another tool).

    Coincident vertices are merged (STL stores a triangle soup), so a closed
    mesh comes back watertight.

    Returns
    -------
    vertices : numpy.ndarray, shape (v, 3), float64
    faces : numpy.ndarray, shape (f, 3), int64
    """
    import trimesh

    suffix = _suffix(path)
    if not Path(path).is_file():
        raise ValueError(f"path must be an existing file; got {str(path)!r}")
    mesh = trimesh.load_mesh(str(path), file_type=suffix[1:], process=True)
    if isinstance(mesh, trimesh.Scene):  # 3MF loads as a scene of placed meshes
        mesh = mesh.to_mesh() if hasattr(mesh, "to_mesh") else mesh.dump(concatenate=True)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def mesh_summary(vertices, faces):
    """Counts and basic measures of a triangle mesh.

    Returns
    -------
    dict
        ``vertex_count`` (int), ``face_count`` (int), ``watertight`` (bool:
        every edge shared by exactly two consistently wound faces),
        ``volume`` (float, signed, model units cubed; meaningful when
        watertight), ``area`` (float), ``bounds`` (((xmin, ymin, zmin),
        (xmax, ymax, zmax)) floats, or None for an empty mesh).
    """
    import trimesh

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (v, 3); got {v.shape}")
    if f.shape[0] == 0:
        bounds = None if v.shape[0] == 0 else (tuple(v.min(0).tolist()), tuple(v.max(0).tolist()))
        return {"vertex_count": int(v.shape[0]), "face_count": 0, "watertight": False,
                "volume": 0.0, "area": 0.0, "bounds": bounds}
    mesh = trimesh.Trimesh(v, f, process=False)
    bounds = np.asarray(mesh.bounds, dtype=np.float64)
    return {"vertex_count": int(v.shape[0]), "face_count": int(f.shape[0]),
            "watertight": bool(mesh.is_watertight and mesh.is_winding_consistent),
            "volume": float(mesh.volume), "area": float(mesh.area),
            "bounds": (tuple(bounds[0].tolist()), tuple(bounds[1].tolist()))}
