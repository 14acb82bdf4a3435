"""Mesh export / import for the Object node (STL, OBJ, PLY, 3MF).

STL, OBJ and PLY go through trimesh. trimesh's 3MF writer needs ``lxml``,
which is not a dependency here, so 3MF is written and read by a small
stdlib (zipfile + ElementTree) implementation of the 3MF core spec: one mesh
object, units in millimetres.

Every export is atomic: the file is written to a temporary sibling, fsynced
and renamed over the target, so a crash never leaves a truncated mesh.
"""

from __future__ import annotations

import io
import os
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

__all__ = ["export_mesh", "load_mesh", "mesh_summary", "SUPPORTED_SUFFIXES"]

SUPPORTED_SUFFIXES = (".stl", ".obj", ".ply", ".3mf")

_NS_3MF = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
_CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" '
    'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" '
    'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    '</Types>')
_RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    '</Relationships>')


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


def _threemf_bytes(v, f):
    lines = [f'<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" '
             f'xml:lang="en-US" xmlns="{_NS_3MF}"><resources><object id="1" type="model">'
             '<mesh><vertices>']
    lines += [f'<vertex x="{x:.10g}" y="{y:.10g}" z="{z:.10g}"/>' for x, y, z in v.tolist()]
    lines.append('</vertices><triangles>')
    lines += [f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in f.tolist()]
    lines.append('</triangles></mesh></object></resources><build><item objectid="1"/></build></model>')
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("[Content_Types].xml", _CONTENT_TYPES)
        z.writestr("_rels/.rels", _RELS)
        z.writestr("3D/3dmodel.model", "\n".join(lines))
    return buf.getvalue()


def _read_threemf(path):
    """Mesh objects placed by build items (with their transforms), concatenated."""
    with zipfile.ZipFile(path) as z:
        name = next((n for n in z.namelist() if n.lower().endswith(".model")), None)
        if name is None:
            raise ValueError(f"path {str(path)!r} is not a 3MF package: no .model part")
        root = ET.fromstring(z.read(name))
    ns = {"m": root.tag[1:].split("}")[0]} if root.tag.startswith("{") else {"m": ""}
    q = (lambda tag: f"m:{tag}") if ns["m"] else (lambda tag: tag)
    meshes = {}
    for obj in root.iterfind(f"{q('resources')}/{q('object')}", ns):
        mesh = obj.find(q("mesh"), ns)
        if mesh is None:
            raise ValueError(f"path {str(path)!r}: 3MF components are not supported, only meshes")
        verts = [[float(e.get(k)) for k in "xyz"] for e in mesh.iterfind(f"{q('vertices')}/{q('vertex')}", ns)]
        tris = [[int(e.get(k)) for k in ("v1", "v2", "v3")]
                for e in mesh.iterfind(f"{q('triangles')}/{q('triangle')}", ns)]
        meshes[obj.get("id")] = (np.array(verts, dtype=np.float64).reshape(-1, 3),
                                 np.array(tris, dtype=np.int64).reshape(-1, 3))
    all_v, all_f, base = [], [], 0
    for item in root.iterfind(f"{q('build')}/{q('item')}", ns):
        v, f = meshes[item.get("objectid")]
        if item.get("transform"):
            m = np.array([float(x) for x in item.get("transform").split()]).reshape(4, 3)
            v = v @ m[:3] + m[3]          # 3MF uses row vectors: p' = p M + t
        all_v.append(v)
        all_f.append(f + base)
        base += v.shape[0]
    if not all_v:
        raise ValueError(f"path {str(path)!r}: the 3MF build places no mesh")
    return np.concatenate(all_v), np.concatenate(all_f)


def _atomic_write(path, data):
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    try:  # make the rename itself durable; not possible on every platform
        dfd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)
    except OSError:
        pass


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
    if suffix == ".3mf":
        data = _threemf_bytes(v, f)
    else:
        import trimesh
        data = trimesh.Trimesh(v, f, process=False).export(file_type=suffix[1:])
        if isinstance(data, str):
            data = data.encode("utf-8")
    _atomic_write(path, data)


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
    if suffix == ".3mf":
        v, f = _read_threemf(path)
        mesh = trimesh.Trimesh(v, f, process=True)
    else:
        mesh = trimesh.load_mesh(str(path), file_type=suffix[1:], process=True)
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
