"""Marching cubes over slabs of a grid, in calls short enough that progress,
cancel and other threads get a turn.

scikit-image's Lewiner marching cubes holds the GIL for the whole call (about
25 ns per sample here), so one call over a 24-plane slab of a 387^2 grid
stalled every other Python thread, the window's GUI thread included, for
80-150 ms. The mesh is defined as before: the grid is cut along x into frames
of ``FRAME_CELLS`` cell layers; each frame is meshed in its own coordinates
and shifted by its first plane (float32), and frames are welded on their
shared planes. That rounding is kept bit for bit, so meshes and exported bytes
do not change. What changed is the work per call: a frame is meshed in
several calls of about ``SLAB_SAMPLES`` samples, each over the whole frame
with skimage's ``mask`` restricting it to a few cell layers, so the vertices
come out in the frame's coordinates exactly as one call over the frame places
them. Within a frame the pieces share their boundary plane; the Lewiner face
test depends on the face's samples only, so both sides triangulate a shared
face alike and the copies of its vertices are bitwise equal; they are welded
onto the first one, where the one call over the frame created it, so faces
and vertices come out in that call's order. That holds when the vertices on
the shared plane are exactly those of the plane's own edges at distinct
positions; a plane where a vertex could round onto a grid node (a sample next
to the level, common in symmetric fields) is not used as a piece boundary
(:func:`_clear_of_nodes`), so a piece may grow up to a whole frame.

The welding and re-indexing work plane by plane and piece by piece, so no
numpy call spans the whole mesh.
"""

from __future__ import annotations

import numpy as np

from engine.progress import report

__all__ = ["slab_marching_cubes", "slab_cells", "SLAB_SAMPLES", "take_chunked", "index_of_kept", "compress_rows"]

# Cell layers per coordinate frame: the slab of one skimage call before the
# calls were split; kept because it fixes the float32 rounding of the output.
FRAME_CELLS = 24
# Samples meshed per marching-cubes call: ~10 ms of GIL on this machine (median,
# gyroid 3 x 3 x 3), short against the 100 ms a GUI frame may wait; the
# per-call overhead (the mask scan of the frame) costs ~20 % more meshing time.
SLAB_SAMPLES = 300_000
# Rows per numpy call when re-indexing a whole mesh.
CHUNK_ROWS = 1 << 18


def slab_cells(shape) -> int:
    """Cell layers meshed per call for a grid of ``shape``: ``SLAB_SAMPLES``
    over the samples of one plane, at least 1, at most ``FRAME_CELLS``."""
    plane = int(shape[1]) * int(shape[2])
    return min(FRAME_CELLS, max(1, SLAB_SAMPLES // max(plane, 1) - 1))


def take_chunked(table, index, rows=CHUNK_ROWS):
    """``table[index]`` for an integer (n, ...) ``index``, done ``rows`` rows at a time."""
    index = np.asarray(index)
    out = np.empty(index.shape + np.shape(table)[1:], dtype=np.asarray(table).dtype)
    for r0 in range(0, index.shape[0], rows):
        out[r0:r0 + rows] = table[index[r0:r0 + rows]]
    return out


def index_of_kept(used, rows=CHUNK_ROWS):
    """``np.cumsum(used) - 1`` (int64) for a boolean ``used``, ``rows`` at a time:
    the new index of each kept row."""
    out = np.empty(used.shape[0], dtype=np.int64)
    offset = -1
    for r0 in range(0, used.shape[0], rows):
        part = np.cumsum(used[r0:r0 + rows], dtype=np.int64) + offset
        out[r0:r0 + rows] = part
        if part.size:
            offset = int(part[-1])
    return out


def compress_rows(a, keep, rows=CHUNK_ROWS):
    """``a[keep]`` for a boolean ``keep`` over the rows of ``a``, ``rows`` at a time."""
    return np.concatenate([a[r0:r0 + rows][keep[r0:r0 + rows]] for r0 in range(0, a.shape[0], rows)]
                          or [a[:0]])


def _crossing(a, b):
    """Mask of the edges whose ends lie on either side of the level and their
    parameters ``a / (a - b)`` (``a``, ``b``: samples minus the level, float64)."""
    cross = (a > 0) != (b > 0)
    return cross, a[cross] / (a[cross] - b[cross])


def _near_nodes(a, b, axis, tau, stride):
    """Flat (y, z) node indices onto which the crossings of the plane's edges
    along ``axis`` (0: y, 1: z) may round (parameter within ``tau`` of 0 or 1)."""
    cross, t = _crossing(a, b)
    iy, iz = np.nonzero(cross)
    up = t > 0.5
    near = (t < tau) | (1 - t < tau)
    iy, iz, up = iy[near], iz[near], up[near]
    if axis == 0:
        iy = iy + up
    else:
        iz = iz + up
    return iy * stride + iz


def _clear_of_nodes(grid, level, p):
    """True if the vertices with x == p that the pieces on both sides of plane
    ``p`` make are exactly the vertices of the plane's own edges, at distinct
    positions.

    Then each appears once per side with bitwise equal coordinates, and welding
    them by coordinates joins exactly the copies one call would share.
    Checked with margins far above float32 rounding: crossings of the x edges
    next to the plane and the cells' centre weights (Lewiner's interior vertex)
    stay ``2^-14`` off 0 and 1, so no such vertex rounds onto the plane; of the
    plane's own crossings those within ``2^(m - 21)`` of a node (coordinates
    below ``2^m``) may round onto it, and no node may get two.
    """
    lv = float(level)
    below, on, above = (grid[i].astype(np.float64) - lv for i in (p - 1, p, p + 1))
    tx = 2.0 ** -14
    for a, b in ((below, on), (on, above)):
        t = _crossing(a, b)[1]
        if t.size and (t.min() < tx or t.max() > 1 - tx):
            return False
    tyz = 2.0 ** (max(grid.shape[1:]).bit_length() - 21)
    nodes = np.concatenate([_near_nodes(on[:-1], on[1:], 0, tyz, on.shape[1]),
                            _near_nodes(on[:, :-1], on[:, 1:], 1, tyz, on.shape[1])])
    if np.unique(nodes).size != nodes.size:
        return False
    for lo, hi in ((below, on), (on, above)):
        corners = [c[dy:c.shape[0] - 1 + dy, dz:c.shape[1] - 1 + dz] for c in (lo, hi) for dy in (0, 1) for dz in (0, 1)]
        stack = np.stack(corners)
        crossing = (stack > 0).any(axis=0) & ~(stack > 0).all(axis=0)
        w = 1.0 / (1e-7 + np.abs(stack[:, crossing]))
        if w.size:
            cx = w[4:].sum(axis=0) / w.sum(axis=0)
            if cx.min() < tx or cx.max() > 1 - tx:
                return False
    return True


def _pieces(grid, level, step, progress=None):
    """(frame start, frame end, piece start, piece end) plane indices, in order.

    A piece ends ``step`` layers on, or at the nearest plane before (else after)
    that is clear of nodes, or at the frame's end.
    """
    n0 = grid.shape[0]
    out = []
    for f0 in range(0, n0 - 1, FRAME_CELLS):
        f1 = min(f0 + FRAME_CELLS, n0 - 1)
        p0 = f0
        while p0 < f1:
            p1 = min(p0 + step, f1)
            cut = p1
            while cut > p0 and cut < f1 and not _clear_of_nodes(grid, level, cut):
                cut -= 1
            if cut == p0:
                cut = p1 + 1
                while cut < f1 and not _clear_of_nodes(grid, level, cut):
                    cut += 1
                cut = min(cut, f1)
            out.append((f0, f1, p0, cut))
            p0 = cut
        report(progress, 0, 1)              # planning a frame: a chance to cancel
    return out


def _weld_plane(verts, lo, hi, plane, remap):
    """Weld equal vertices with x == ``plane`` among ``verts[lo:hi]`` (the two
    pieces sharing it) onto their first copy, recorded in ``remap``."""
    cand = lo + np.flatnonzero(verts[lo:hi, 0] == plane)
    if cand.size < 2:
        return
    _, first, inverse = np.unique(verts[cand], axis=0, return_index=True, return_inverse=True)
    remap[cand] = cand[first][inverse.ravel()]


def _mesh_piece(grid, level, f0, f1, p0, p1, mask):
    """Vertices (float32, global x as the frame's call gives them) and faces of
    cell layers p0..p1-1 of the frame f0..f1; None if nothing crosses there."""
    from skimage.measure import marching_cubes

    piece = grid[p0:p1 + 1]
    if not ((piece < level).any() and (piece > level).any()):
        return None
    frame = grid[f0:f1 + 1]
    if (p0, p1) == (f0, f1):
        v, f, _, _ = marching_cubes(frame, level=level, gradient_direction="descent", allow_degenerate=True)
    else:
        # skimage meshes the cell whose far corner the mask marks
        mask[p0 - f0 + 1:p1 - f0 + 1] = True
        try:
            v, f, _, _ = marching_cubes(frame, level=level, gradient_direction="descent",
                                        allow_degenerate=True, mask=mask)
        finally:
            mask[p0 - f0 + 1:p1 - f0 + 1] = False
    v[:, 0] += f0
    return v, f.astype(np.int64)


def slab_marching_cubes(grid, level, progress):
    """Marching cubes (skimage, Lewiner, ``gradient_direction="descent"``,
    degenerate triangles allowed) over frames of ``FRAME_CELLS`` cell layers
    along x, each meshed ``slab_cells`` layers per call.

    Parameters
    ----------
    grid : (n0, n1, n2) float32
    level : float
    progress : callable(done, total) -> bool, optional
        Called between calls; returning False raises Cancelled.

    Returns
    -------
    vertices : (v, 3) float32, grid index units
    faces : (f, 3) int64
        For a grid of at most ``FRAME_CELLS + 1`` planes, equal bit for bit and
        in order to one ``marching_cubes`` call on ``grid``; for a longer grid
        the frames' meshes welded on their shared planes (each vertex within
        a float32 rounding of one call's); empty arrays if no surface.
    """
    pieces = _pieces(grid, level, slab_cells(grid.shape), progress)
    report(progress, 0, len(pieces))
    all_v, all_f, bases, base = [], [], [], 0
    mask, mask_frame = None, None
    for k, (f0, f1, p0, p1) in enumerate(pieces):
        if mask_frame != (f0, f1):
            mask = np.zeros((f1 - f0 + 1,) + grid.shape[1:], dtype=bool)
            mask_frame = (f0, f1)
        bases.append(base)
        out = _mesh_piece(grid, level, f0, f1, p0, p1, mask)
        if out is None:
            out = (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int64))
        all_v.append(out[0])
        all_f.append(out[1] + base)
        base += out[0].shape[0]
        report(progress, k + 1, len(pieces))
    bases.append(base)
    if base == 0:
        return np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int64)
    verts = np.concatenate(all_v)
    if len(pieces) == 1:
        return verts, all_f[0]
    remap = np.arange(base)
    for k in range(1, len(pieces)):
        _weld_plane(verts, bases[k - 1], bases[k + 1], verts.dtype.type(pieces[k][2]), remap)
    used = np.zeros(base, dtype=bool)
    for k, f in enumerate(all_f):
        f = remap[f]
        all_f[k] = f
        used[f.ravel()] = True
    new_index = index_of_kept(used)
    faces = np.concatenate([new_index[f] for f in all_f])
    return take_chunked(verts, np.flatnonzero(used)), faces
