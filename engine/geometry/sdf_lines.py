"""Signed distance grid of thickened line skeletons (paper sections 5.3, 6.5).

Grid convention (shared by every SDF kernel here): a periodic box cell
``[0, Lx] x [0, Ly] x [0, Lz]`` (the unit cube by default, see
:mod:`engine.geometry.box_cell`) sampled at the nodes ``x_i = i * Lx / nx``,
``i = 0 .. nx-1``, and likewise along y and z; array index order
``[i, j, k] = [x, y, z]``. Node ``nx`` would coincide with node 0, so
appending the first plane reproduces the values at ``x = Lx`` and opposite
faces of a tile are identical by construction.

Each polyline segment becomes one convex element with a closed-form SDF:

* ``"spherical"``: the union of spheres swept along the segment with linearly
  varying radius. That union is exactly the convex hull of the two end
  spheres (a "round cone"; a capsule for equal radii), whose SDF reduces to a
  2D problem in (axial, radial) coordinates: nearest end sphere or the
  tangent line between them.
* ``"normal"``: a circular cross-section swept along the segment, i.e. a
  frustum with flat ends (exact 2D distance to a trapezoid); spheres at the
  interior vertices (and at the seam of a closed polyline) fill the wedge
  gaps at bends. Free ends stay flat.

The field is the minimum of the element SDFs, clamped to ``+band``:
exact outside the solid up to ``band`` (default 3 voxels), correct in sign
everywhere, and inside equal to minus the depth in the deepest element (so
exact near the surface except where elements meet).

Only grid nodes whose distance to a segment's axis could be below
``max radius + band`` are visited; the rest keep ``+band``. With
``periodic=True`` node indices are unwrapped (so a segment crossing ``x = Lx``
is measured against its own unwrapped coordinates) and stored modulo the
axis' node count, which makes the field exactly periodic with the box period.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .box_cell import check_cell, check_grid_shape, default_band
from engine.progress import run_chunked

__all__ = ["line_sdf_grid", "line_sdf_reference", "METHODS"]

METHODS = ("spherical", "normal")
KIND_ROUND, KIND_FRUSTUM = 0, 1
# Column layout of the per-element float table passed to the kernel.
_RA, _RB, _LEN, _DX, _DY, _DZ, _NS, _NQ, _REACH, _DEG = range(10)


# ----------------------------------------------------------------- validation

def check_resolution(resolution):
    """Validate a grid resolution and return it as int (shared with triangles)."""
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) \
            or resolution < 2:
        raise ValueError(f"resolution must be an integer >= 2; got {resolution!r}")
    return int(resolution)


def check_band(band, n, cell=None):
    """Default band is 3 voxels (along the coarsest axis of a box of ``n`` nodes
    per axis, an int or three); an explicit one must be finite and > 0."""
    if band is None:
        return 3.0 / n if cell is None else default_band(cell, n)
    b = float(band)
    if not math.isfinite(b) or b <= 0.0:
        raise ValueError(f"band must be a finite distance > 0; got {band!r}")
    return b


def _check_inputs(polylines, radii, method):
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}; got {method!r}")
    if len(polylines) != len(radii):
        raise ValueError(f"radii must have one entry per polyline; got {len(radii)} "
                         f"for {len(polylines)} polylines")
    out = []
    for k, (pl, rr) in enumerate(zip(polylines, radii)):
        p = np.asarray(pl, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 2:
            raise ValueError(f"polylines[{k}] must have shape (m, 3) with m >= 2; got {p.shape}")
        r = np.asarray(rr, dtype=np.float64)
        r = np.full(p.shape[0], float(r)) if r.ndim == 0 else r
        if r.shape != (p.shape[0],):
            raise ValueError(f"radii[{k}] must have shape ({p.shape[0]},) to match "
                             f"polylines[{k}]; got {r.shape}")
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(r))):
            raise ValueError(f"polylines[{k}] and radii[{k}] must be finite; got NaN or inf")
        if np.any(r < 0):
            raise ValueError(f"radii[{k}] must be >= 0; got minimum {r.min()!r}")
        out.append((p, r))
    return out


def _is_loop(p, periodic, cell=(1.0, 1.0, 1.0)):
    """A polyline whose ends coincide (modulo the lattice when periodic)."""
    gap = p[-1] - p[0]
    if periodic:
        box = np.asarray(cell, dtype=np.float64)
        gap = gap - box * np.round(gap / box)
    return p.shape[0] > 2 and float(np.abs(gap).max()) <= 1e-9


def build_elements(polylines, radii, *, method, periodic, cell=(1.0, 1.0, 1.0)):
    """Decompose polylines into elements.

    Returns
    -------
    a, b : (E, 3) float64 end points; ra, rb : (E,) float64 radii;
    kind : (E,) int8, KIND_ROUND (round cone / sphere) or KIND_FRUSTUM.
    """
    rows = []
    for p, r in _check_inputs(polylines, radii, method):
        m = p.shape[0]
        if method == "spherical":
            rows += [(p[i], p[i + 1], r[i], r[i + 1], KIND_ROUND) for i in range(m - 1)]
            continue
        for i in range(m - 1):
            if np.linalg.norm(p[i + 1] - p[i]) > 1e-12:   # a flat disc has no volume
                rows.append((p[i], p[i + 1], r[i], r[i + 1], KIND_FRUSTUM))
        joints = [(p[i], r[i]) for i in range(1, m - 1)]
        if _is_loop(p, periodic, cell):
            joints.append((p[0], min(r[0], r[-1])))
        rows += [(c, c, rc, rc, KIND_ROUND) for c, rc in joints]
    if not rows:
        z = np.zeros((0, 3))
        return z, z.copy(), np.zeros(0), np.zeros(0), np.zeros(0, np.int8)
    a = np.array([row[0] for row in rows], dtype=np.float64)
    b = np.array([row[1] for row in rows], dtype=np.float64)
    ra = np.array([row[2] for row in rows], dtype=np.float64)
    rb = np.array([row[3] for row in rows], dtype=np.float64)
    kind = np.array([row[4] for row in rows], dtype=np.int8)
    return a, b, ra, rb, kind


def _element_table(a, b, ra, rb, band):
    """Per-element constants so the kernel does no redundant work per node."""
    e = a.shape[0]
    geo = np.zeros((e, 10))
    geo[:, _RA], geo[:, _RB] = ra, rb
    v = b - a
    length = np.linalg.norm(v, axis=1)
    geo[:, _LEN] = length
    safe = np.where(length > 1e-12, length, 1.0)
    geo[:, _DX:_DZ + 1] = np.where(length[:, None] > 1e-12, v / safe[:, None], [1.0, 0.0, 0.0])
    # Round cone: outward normal of the tangent line is (ns, nq) in
    # (axial, radial) coordinates with ns = (ra - rb) / L. If one end sphere
    # contains the other there is no tangent line: the element is a sphere.
    dr = ra - rb
    deg = length <= np.abs(dr) + 1e-12
    ns = np.where(deg, 0.0, dr / safe)
    geo[:, _NS] = ns
    geo[:, _NQ] = np.sqrt(np.maximum(0.0, 1.0 - ns * ns))
    geo[:, _DEG] = deg
    geo[:, _REACH] = np.maximum(ra, rb) + band
    return geo


def index_ranges(lo_xyz, hi_xyz, n, cell=None):
    """Unwrapped node index ranges [lo, hi] covering boxes given in cell units.

    n : int or (3,) nodes per axis; cell : (3,) box edges (None: the unit cube).
    """
    if cell is None:
        lo = np.ceil(lo_xyz * n - 1e-9).astype(np.int64)
        hi = np.floor(hi_xyz * n + 1e-9).astype(np.int64)
        return lo, hi
    n = np.asarray(n, dtype=np.int64)
    box = np.asarray(cell, dtype=np.float64)
    lo = np.ceil(lo_xyz * n / box - 1e-9).astype(np.int64)
    hi = np.floor(hi_xyz * n / box + 1e-9).astype(np.int64)
    return lo, hi


# --------------------------------------------------------------- numba kernel

@njit(cache=True, fastmath=False, nogil=True)
def _element_sdf(px, py, pz, ax, ay, az, g, kind):
    wx, wy, wz = px - ax, py - ay, pz - az
    s = wx * g[_DX] + wy * g[_DY] + wz * g[_DZ]
    qx, qy, qz = wx - s * g[_DX], wy - s * g[_DY], wz - s * g[_DZ]
    q = math.sqrt(qx * qx + qy * qy + qz * qz)
    ra, rb, length = g[_RA], g[_RB], g[_LEN]
    if kind == KIND_ROUND:
        if g[_DEG] != 0.0:
            return min(math.sqrt(s * s + q * q) - ra, math.sqrt((s - length) ** 2 + q * q) - rb)
        ns, nq = g[_NS], g[_NQ]
        tau = s * nq - q * ns                   # position along the tangent line
        if tau < 0.0:
            return math.sqrt(s * s + q * q) - ra
        if tau > length * nq:
            return math.sqrt((s - length) ** 2 + q * q) - rb
        return s * ns + q * nq - ra
    # Frustum: 2D distance to the trapezoid (0,0)-(0,ra)-(L,rb)-(L,0), q >= 0.
    da = abs(s) if q <= ra else math.sqrt(s * s + (q - ra) ** 2)
    db = abs(s - length) if q <= rb else math.sqrt((s - length) ** 2 + (q - rb) ** 2)
    vy = rb - ra
    t = (s * length + (q - ra) * vy) / (length * length + vy * vy)
    t = min(1.0, max(0.0, t))
    ds = math.sqrt((s - t * length) ** 2 + (q - ra - t * vy) ** 2)
    d = min(da, min(db, ds))
    if 0.0 <= s <= length and q <= ra + vy * (s / length):
        return -d
    return d


@njit(cache=True, fastmath=False, nogil=True)
def _param_window(a, dlt, x, reach, t0, t1):
    """Narrow [t0, t1] to the t where |a + t * dlt - x| <= reach."""
    if abs(dlt) < 1e-15:
        if abs(a - x) > reach:
            return 1.0, 0.0
        return t0, t1
    u = (x - reach - a) / dlt
    v = (x + reach - a) / dlt
    if u > v:
        u, v = v, u
    return max(t0, u), min(t1, v)


@njit(cache=True, fastmath=False, parallel=True, nogil=True)
def _sdf_planes(field, p0, p1, a, b, geo, kind, lo, hi, shape, box, periodic, band):
    nel = a.shape[0]
    nx, ny, nz = shape[0], shape[1], shape[2]
    lx, ly, lz = box[0], box[1], box[2]
    for pp in prange(p1 - p0):
        p = p0 + pp
        plane = field[p]
        plane[:, :] = band
        for e in range(nel):
            ilo, ihi = lo[e, 0], hi[e, 0]
            reach = geo[e, _REACH]
            ax, ay, az = a[e, 0], a[e, 1], a[e, 2]
            ex, ey, ez = b[e, 0] - ax, b[e, 1] - ay, b[e, 2] - az
            g = geo[e]
            # Unwrapped indices congruent to p within [ilo, ihi].
            i = ilo + (p - ilo) % nx if periodic else p
            while i <= ihi and i >= ilo:
                x = i * lx / nx
                # Parameter window of points whose x is within reach, then
                # the y (and per row z) span of that sub-segment +- reach:
                # a box bound much tighter than the segment's bounding box
                # for diagonal segments.
                tx0, tx1 = _param_window(ax, ex, x, reach, 0.0, 1.0)
                if tx0 <= tx1:
                    ylo = min(ay + tx0 * ey, ay + tx1 * ey) - reach
                    yhi = max(ay + tx0 * ey, ay + tx1 * ey) + reach
                    jlo = int(math.ceil(ylo * ny / ly - 1e-9))
                    jhi = int(math.floor(yhi * ny / ly + 1e-9))
                    if not periodic:
                        jlo, jhi = max(jlo, 0), min(jhi, ny - 1)
                    for j in range(jlo, jhi + 1):
                        y = j * ly / ny
                        t0, t1 = _param_window(ay, ey, y, reach, tx0, tx1)
                        if t0 > t1:
                            continue
                        zlo = min(az + t0 * ez, az + t1 * ez) - reach
                        zhi = max(az + t0 * ez, az + t1 * ez) + reach
                        klo = int(math.ceil(zlo * nz / lz - 1e-9))
                        khi = int(math.floor(zhi * nz / lz + 1e-9))
                        if not periodic:
                            klo, khi = max(klo, 0), min(khi, nz - 1)
                        jj = j % ny
                        kk = klo % nz
                        for k in range(klo, khi + 1):
                            v = _element_sdf(x, y, k * lz / nz, ax, ay, az, g, kind[e])
                            if v < plane[jj, kk]:
                                plane[jj, kk] = v
                            kk += 1
                            if kk == nz:
                                kk = 0
                if not periodic:
                    break
                i += nx


# ------------------------------------------------------------------ public API

def grid_of(resolution, cell):
    """(shape, box) of a kernel call: ``resolution`` an int (nodes along the
    box's longest edge, see :func:`engine.geometry.box_cell.box_grid_shape`)
    or three ints ``(nx, ny, nz)``; ``cell`` three edges or None (unit cube)."""
    from .box_cell import box_grid_shape

    box = check_cell(cell)
    if isinstance(resolution, (tuple, list, np.ndarray)):
        return check_grid_shape(resolution), box
    n = check_resolution(resolution)
    return ((n, n, n) if box == (1.0, 1.0, 1.0) else box_grid_shape(box, n)), box


def line_sdf_grid(polylines, radii, *, resolution, method="spherical", periodic=True,
                  band=None, progress=None, cell=None):
    """Signed distance field of thickened polylines on the periodic box cell.

    Parameters
    ----------
    polylines : sequence of array_like, each shape (m_k, 3), float
        Skeleton polylines in cell units (m_k >= 2). Points may lie outside
        the box; with ``periodic`` they wrap with the box period.
    radii : sequence of array_like, each shape (m_k,) (or a scalar), float
        Radius (half the thickness, cell units, >= 0) at each vertex; varies
        linearly along each segment.
    resolution : int or (3,) int
        N >= 2: nodes along the longest box edge (N per axis on the unit
        cube; other edges get ``round(N * L_i / L_max)``); or the grid shape
        ``(nx, ny, nz)``, each >= 2. Nodes at ``i * Lx / nx`` etc.
    method : {"spherical", "normal"}
        Swept spheres (round ends) or a swept circular section (flat free
        ends, spherical joints).
    periodic : bool
        Wrap elements across the cell faces (field exactly periodic). If
        False, elements are clipped to the grid, which then covers
        ``[0, (nx-1) Lx / nx]`` etc.
    band : float, optional
        Distance (cell units) beyond the surface up to which values are
        exact; farther nodes hold ``+band``. Default 3 voxels, ``3 / N`` on
        the unit cube (``max(3 L_i / n_i)`` on a box).
    progress : callable, optional
        ``progress(done_planes, nx) -> bool``; returning False raises
        :class:`engine.geometry.Cancelled`. Consulted every ~40 ms.
    cell : (3,) float, optional
        Box edges ``(Lx, Ly, Lz)`` in cell units, each in (0, 100]; default
        the unit cube.

    Returns
    -------
    numpy.ndarray, shape (nx, ny, nz), float32
        Signed distance in cell units, negative inside, ``[x, y, z]`` order.
    """
    shape, box = grid_of(resolution, cell)
    band = check_band(band, shape, box)
    a, b, ra, rb, kind = build_elements(polylines, radii, method=method, periodic=bool(periodic),
                                        cell=box)
    geo = _element_table(a, b, ra, rb, band)
    reach = geo[:, _REACH:_REACH + 1]
    lo, hi = index_ranges(np.minimum(a, b) - reach, np.maximum(a, b) + reach, shape, box)
    field = np.empty(shape, dtype=np.float32)
    per = bool(periodic)
    shape_arr, box_arr = np.array(shape, dtype=np.int64), np.array(box, dtype=np.float64)

    def work(start, stop):
        _sdf_planes(field, start, stop, a, b, geo, kind, lo, hi, shape_arr, box_arr, per, band)

    run_chunked(work, shape[0], progress)
    return field


# ------------------------------------------------------- slow reference (tests)

_SPHERE_SAG = 2e-5      # max dent between neighbouring sampled spheres, cell units
_RIM_SPACING = 3e-4     # spacing of the sampled rims; distance error <= spacing / 2


def grid_nodes(shape, box):
    """(nx*ny*nz, 3) node positions ``i * L / n``, ``[x, y, z]`` C order."""
    axes = [np.arange(n) * float(L) / n for n, L in zip(shape, box)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def _offsets(nodes, centres, periodic, box):
    d = nodes[:, None, :] - centres[None, :, :]
    if periodic:
        # Nearest image of a point is exact for a box lattice; for circles
        # and discs it is exact while radius + band < min(L) / 4 (checked below).
        d -= box * np.round(d / box)
    return d


def _chunks(count, nodes):
    step = max(1, int(2e6 // nodes.shape[0]))
    return [slice(s, s + step) for s in range(0, count, step)]


def _swept_spheres(nodes, a, b, ra, rb, periodic, box):
    """min over densely sampled spheres of (|p - c| - r)."""
    length = float(np.linalg.norm(b - a))
    rmin = max(min(ra, rb), 1e-3)
    # Two spheres of radius r at spacing h leave a dent of about h^2 / (8 r)
    # at the surface; deep inside, near the axis, the error is up to h / 2.
    spacing = min(math.sqrt(8.0 * rmin * _SPHERE_SAG), 1.5e-3)
    count = int(math.ceil(length / spacing)) + 1
    t = np.linspace(0.0, 1.0, max(count, 2))
    centres, rads = a + t[:, None] * (b - a), ra + t * (rb - ra)
    best = np.full(nodes.shape[0], np.inf)
    for sl in _chunks(t.size, nodes):
        dist = np.linalg.norm(_offsets(nodes, centres[sl], periodic, box), axis=2) - rads[None, sl]
        best = np.minimum(best, dist.min(axis=1))
    return best


def _circle_distance(d, axis, radius, solid):
    """Distance from offsets d (.., 3) to a circle (or, if solid, a disc)."""
    h = d @ axis
    rho = np.linalg.norm(d - h[..., None] * axis, axis=-1)
    gap = np.maximum(rho - radius, 0.0) if solid else rho - radius
    return np.sqrt(h * h + gap * gap)


def _frustum_boundary_distance(nodes, a, b, ra, rb, periodic, box):
    """Distance to the frustum surface: two cap discs plus densely sampled rims."""
    axis = (b - a) / np.linalg.norm(b - a)
    best = np.minimum(_circle_distance(_offsets(nodes, a[None], periodic, box)[:, 0], axis, ra, True),
                      _circle_distance(_offsets(nodes, b[None], periodic, box)[:, 0], axis, rb, True))
    slant = math.hypot(float(np.linalg.norm(b - a)), rb - ra)
    t = np.linspace(0.0, 1.0, int(math.ceil(slant / _RIM_SPACING)) + 1)
    centres, rads = a + t[:, None] * (b - a), ra + t * (rb - ra)
    for sl in _chunks(t.size, nodes):
        dist = _circle_distance(_offsets(nodes, centres[sl], periodic, box), axis, rads[None, sl], False)
        best = np.minimum(best, dist.min(axis=1))
    return best


def _inside_frustum(nodes, a, b, ra, rb, periodic, box):
    """Point-in-frustum test, brute force over every lattice image that can reach the cell."""
    v = b - a
    length = float(np.linalg.norm(v))
    d = v / length
    offsets = np.zeros((1, 3))
    if periodic:
        lo = np.floor((np.minimum(a, b) - max(ra, rb)) / box) - 1
        hi = np.ceil((np.maximum(a, b) + max(ra, rb)) / box) + 1
        rng = [np.arange(lo[i], hi[i] + 1) for i in range(3)]
        offsets = np.stack(np.meshgrid(*rng, indexing="ij"), -1).reshape(-1, 3) * box
    inside = np.zeros(nodes.shape[0], dtype=bool)
    for o in offsets:
        w = nodes + o - a
        s = w @ d
        q = np.linalg.norm(w - s[:, None] * d, axis=1)
        inside |= (s >= 0) & (s <= length) & (q <= ra + (rb - ra) * s / length)
    return inside


def line_sdf_reference(polylines, radii, *, resolution, method="spherical", periodic=True,
                       band=None, cell=None):
    """Slow, plain-numpy version of :func:`line_sdf_grid` for tests and benches.

    Swept spheres are densely sampled spheres. A frustum's sign comes from a
    point-in-frustum test over all periodic images, its magnitude from the
    distance to its two cap discs and to densely sampled rim circles. Same
    parameters, grid, element decomposition and band as
    :func:`line_sdf_grid`; accurate to about 2e-4 cell units near the
    surface and 8e-4 deep inside swept spheres. Periodic mode requires
    radius + band < min(L) / 4 (0.25 on the unit cube).
    """
    shape, box = grid_of(resolution, cell)
    band = check_band(band, shape, box)
    a, b, ra, rb, kind = build_elements(polylines, radii, method=method, periodic=bool(periodic),
                                        cell=box)
    limit = 0.25 * min(box)
    if periodic and a.shape[0] and float(np.maximum(ra, rb).max()) + band >= limit:
        raise ValueError(f"radii + band must stay below {limit!r} for the periodic reference; "
                         f"got {float(np.maximum(ra, rb).max()) + band!r}")
    box_arr = np.array(box)
    nodes = grid_nodes(shape, box)
    field = np.full(nodes.shape[0], band)
    for e in range(a.shape[0]):
        if kind[e] == KIND_ROUND:
            val = _swept_spheres(nodes, a[e], b[e], ra[e], rb[e], periodic, box_arr)
        else:
            dist = _frustum_boundary_distance(nodes, a[e], b[e], ra[e], rb[e], periodic, box_arr)
            inside = _inside_frustum(nodes, a[e], b[e], ra[e], rb[e], periodic, box_arr)
            val = np.where(inside, -dist, dist)
        field = np.minimum(field, val)
    return field.reshape(shape).astype(np.float32)
