"""Mesh preparation for the 3D viewport, run off the GUI thread.

Plain functions (numpy + pyvista data objects, no Qt, no render window), so a
`ui.task_runner.TaskRunner` can run them in a worker thread: the GUI thread
then only hands the finished arrays to its actors.

Smooth shading needs point normals.  They are computed once per solid and
level of detail, on the single cell, with numpy (area-weighted face normals
summed at each vertex); a tiling draws translated copies of the cell
(`ui.solid_actors`), which have the same normals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyvista as pv


@dataclass(frozen=True)
class PreparedCell:
    """One cell's mesh ready to tile: vertices (n, 3) float32 mm, faces (m, 3)
    int64, unit point normals (n, 3) float32; `error` (mm) the measured deviation
    from the solid's full mesh (0 for the full mesh itself, `ui.scene_lod.surface_deviation`)."""

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    error: float = 0.0


def point_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(n, 3) float32 unit normals at the vertices: the area-weighted sum of the
    normals of the triangles around each vertex (zero for a vertex no triangle uses)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if not len(f):
        return np.zeros((len(v), 3), np.float32)
    face_n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])  # |n| = 2 * area
    acc = np.zeros((len(v), 3))
    for axis in range(3):
        w = np.repeat(face_n[:, axis], 3)
        acc[:, axis] = np.bincount(f.ravel(), weights=w, minlength=len(v))
    length = np.linalg.norm(acc, axis=1)
    length[length == 0] = 1.0
    return (acc / length[:, None]).astype(np.float32)


def prepare_cell(vertices: np.ndarray, faces: np.ndarray, error: float = 0.0) -> PreparedCell:
    """The cell's arrays in the dtypes the renderer takes, with point normals."""
    v = np.ascontiguousarray(vertices, dtype=np.float32)
    f = np.ascontiguousarray(faces, dtype=np.int64).reshape(-1, 3)
    return PreparedCell(v, f, point_normals(v, f), float(error))


def skeleton_polydata(polylines: list[np.ndarray]) -> pv.PolyData | None:
    """All polylines (each (p, 3) mm, p >= 2) as one line mesh; None if there is none."""
    polylines = [np.asarray(p, dtype=float).reshape(-1, 3) for p in polylines]
    polylines = [p for p in polylines if len(p) >= 2]
    if not polylines:
        return None
    points = np.concatenate(polylines)
    cells, start = [], 0
    for p in polylines:
        cells.append(np.concatenate([[len(p)], np.arange(start, start + len(p))]))
        start += len(p)
    return pv.PolyData(points, lines=np.concatenate(cells).astype(np.int64))


def surfaces_polydata(surfaces: list[tuple[np.ndarray, np.ndarray]]) -> pv.PolyData | None:
    """Triangle meshes ((v, 3) mm, (f, 3)) merged into one; None if none has a face."""
    parts = [(np.asarray(v, float), np.asarray(f, np.int64).reshape(-1, 3)) for v, f in surfaces]
    parts = [(v, f) for v, f in parts if len(f)]
    if not parts:
        return None
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    v = np.concatenate([v for v, _ in parts])
    f = np.concatenate([f + o for (_, f), o in zip(parts, offsets)])
    return pv.PolyData.from_regular_faces(v, f)
