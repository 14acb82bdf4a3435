"""Binary STL encoding in chunks: the bytes trimesh writes, without one long GIL hold.

``trimesh.Trimesh(...).export("stl")`` builds the whole file in a few numpy
calls over the whole mesh (triangle gather, cross products, normals, packing,
``tobytes`` and a concatenation), each holding the GIL for tens of ms on a
few million triangles, so a worker thread encoding a 3 x 3 x 3 block stalled
the window's GUI thread for hundreds of ms (and importing trimesh the first
time another ~100 ms).  :func:`binary_stl` computes the same row-wise
arithmetic in the same order (edge vectors, their cross product, its length as
a dot product with ones, normals of faces longer than ``ZERO_LENGTH``, zero
otherwise) ``CHUNK_FACES`` triangles at a time into one preallocated buffer,
so the bytes are trimesh's (tested against its exporter) and no call runs long.
"""

from __future__ import annotations

import numpy as np

__all__ = ["binary_stl", "CHUNK_FACES"]

CHUNK_FACES = 1 << 16          # ~3 MB of output per step, a few ms each
ZERO_LENGTH = 100 * float(np.finfo(np.float64).resolution)   # shorter cross products: no normal

_RECORD = np.dtype([("normals", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
_HEADER = np.dtype([("header", np.void, 80), ("face_count", "<u4")])


def binary_stl(vertices, faces, *, chunk=CHUNK_FACES) -> memoryview:
    """The binary STL of a triangle mesh, as trimesh's exporter writes it.

    Parameters
    ----------
    vertices : (v, 3) float64
    faces : (f, 3) int64, indices into ``vertices``
    chunk : int > 0, triangles encoded per step

    Returns
    -------
    memoryview of bytes: 80-byte zero header, uint32 face count, then per face
    the unit normal (zero for a degenerate face), the three corners (float32)
    and a zero attribute word.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = f.shape[0]
    buf = np.zeros(_HEADER.itemsize + n * _RECORD.itemsize, dtype=np.uint8)
    header = buf[:_HEADER.itemsize].view(_HEADER)
    header["face_count"] = n
    records = buf[_HEADER.itemsize:].view(_RECORD)
    for c0 in range(0, n, int(chunk)):
        tri = v[f[c0:c0 + chunk]]
        edge = tri[:, 1:, :] - tri[:, :2, :]
        normals = np.cross(edge[:, 0], edge[:, 1])
        length = np.sqrt(np.dot(normals * normals, [1.0, 1.0, 1.0]))
        valid = length > ZERO_LENGTH
        length[valid] **= -1
        normals *= length.reshape((-1, 1))
        normals[~valid] = 0.0
        rec = records[c0:c0 + chunk]
        rec["normals"] = normals
        rec["vertices"] = tri
    return memoryview(buf)
