"""Import and export of the user's input fields: density, stress / orientation, infill map.

Two formats, chosen by the suffix:

``.npz`` (numpy)
    Arrays by name: ``rho`` (required, grid ``(ny, nx)`` or ``(nz, ny, nx)``,
    values in [0, 1]); optional ``sigma`` (grid + ``(d, d)``, symmetric
    stress tensors), ``R`` (or ``rotation``; grid + ``(d, d)``, principal
    directions as columns, a zero column meaning "undefined"), ``gamma``
    (grid, in [0, 1], the painted infill map ``Gamma_c``), ``spacing`` and
    ``origin`` (d floats, x first). Other arrays are ignored; pickled
    objects are refused.

``.vti`` (VTK XML ImageData), read by a parser of our own. Supported subset:
    one ``Piece`` covering the ``WholeExtent``; axis-aligned (``Direction``
    absent or identity); ``CellData`` or ``PointData`` arrays (cell data
    win when a name is in both); ``DataArray`` formats ``ascii``,
    ``binary`` (inline base64) and ``appended`` (``AppendedData`` encoding
    ``raw`` or ``base64``); ``header_type`` UInt32 or UInt64; either byte
    order; no compressor, ``vtkZLibDataCompressor`` or
    ``vtkLZMADataCompressor``; numeric types Int8 ... UInt64, Float32,
    Float64. A 2D grid is one with a single point layer along z
    (``WholeExtent`` ``... 0 0``). Tensor components: 2D ``sigma`` 4 (2 x 2
    row-major), 3 (xx, yy, xy) or 9 (3 x 3 row-major, the in-plane block is
    kept); 3D ``sigma`` 9 or 6 (VTK symmetric order xx, yy, zz, xy, yz,
    xz); ``R`` d x d (or 9 in 2D) row-major, i.e. component ``row * d +
    col``. Not supported: multi-piece files, LZ4 compression, ``Bit``
    arrays, oriented images.

Values are returned in the shared conventions: grids ``[y, x]`` /
``[z, y, x]``, tensors (..., d, d) in (x, y[, z]) order. Every refusal
names the file, the array and the problem.
"""

from __future__ import annotations

import base64
import io
import lzma
import re
import warnings
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from engine.fileio import write_atomic

from .tensor_field import check_tensor_field, format_cell

__all__ = ["FieldFileError", "RDFields", "load_fields", "save_fields", "SUPPORTED_SUFFIXES"]

SUPPORTED_SUFFIXES = (".npz", ".vti")
# [0, 1] fields may overshoot by round-off this much; they are clipped.
_RANGE_TOL = 1e-6
# A rotation column is unit (or zero) and the columns orthogonal to this tolerance.
_ORTHO_TOL = 1e-3

_VTK_TYPES = {"Int8": "i1", "UInt8": "u1", "Int16": "i2", "UInt16": "u2", "Int32": "i4", "UInt32": "u4",
              "Int64": "i8", "UInt64": "u8", "Float32": "f4", "Float64": "f8"}


class FieldFileError(ValueError):
    """A field file that cannot be used; the message names file, array and problem."""


@dataclass(frozen=True)
class RDFields:
    """Input fields on one grid (arrays are read-only).

    rho : (ny, nx) or (nz, ny, nx) float64 in [0, 1]
    sigma : grid + (d, d) float64, symmetric, or None
    rotation : grid + (d, d) float64, or None
    gamma : grid float64 in [0, 1], or None
    spacing, origin : tuple of d floats, (x, y[, z]) order, model units
    source : str, the file read ("" when built in memory)
    """

    rho: np.ndarray
    sigma: np.ndarray | None = None
    rotation: np.ndarray | None = None
    gamma: np.ndarray | None = None
    spacing: tuple = field(default=None)
    origin: tuple = field(default=None)
    source: str = ""

    def __post_init__(self):
        d = np.ndim(self.rho)
        for name in ("rho", "sigma", "rotation", "gamma"):
            a = getattr(self, name)
            if a is not None:
                a = np.array(a, dtype=np.float64)
                a.flags.writeable = False
                object.__setattr__(self, name, a)
        for name in ("spacing", "origin"):
            v = getattr(self, name)
            object.__setattr__(self, name, tuple(float(x) for x in v) if v is not None
                               else tuple([1.0 if name == "spacing" else 0.0] * d))

    @property
    def ndim(self):
        """Grid dimension, 2 or 3."""
        return self.rho.ndim


def _fail(path, array, problem):
    where = f"array {array!r}: " if array else ""
    raise FieldFileError(f"{path}: {where}{problem}")


# ---------------------------------------------------------------- validation

def _check_unit(path, name, a, grid):
    if a.shape != grid:
        _fail(path, name, f"shape {a.shape} does not match rho's grid {grid}")
    bad = ~np.isfinite(a)
    if bad.any():
        _fail(path, name, f"NaN or infinite value at cell {format_cell(np.argwhere(bad)[0], a.ndim)}")
    lo, hi = float(a.min()), float(a.max())
    if lo < -_RANGE_TOL or hi > 1 + _RANGE_TOL:
        _fail(path, name, f"values must lie in [0, 1]; got [{lo:.6g}, {hi:.6g}]")
    return np.clip(a, 0.0, 1.0)


def _check_rotation(path, name, r, grid):
    d = len(grid)
    if r.shape != grid + (d, d):
        _fail(path, name, f"shape {r.shape} does not match rho's grid {grid} + ({d}, {d})")
    bad = ~np.isfinite(r).all(axis=(-2, -1))
    if bad.any():
        _fail(path, name, f"NaN or infinite value at cell {format_cell(np.argwhere(bad)[0], d)}")
    norms = np.linalg.norm(r, axis=-2)                       # (..., d) column lengths
    used = norms > 1e-12
    gram = np.swapaxes(r, -1, -2) @ r
    expect = np.zeros_like(gram)
    idx = np.arange(d)
    expect[..., idx, idx] = used
    err = np.abs(gram - expect).max(axis=(-2, -1))
    if (err > _ORTHO_TOL).any():
        first = np.argwhere(err > _ORTHO_TOL)[0]
        _fail(path, name, f"columns are not orthonormal (or zero) at cell {format_cell(first, d)}: "
                          f"|R^T R - I| = {err[tuple(first)]:.3g}")
    return r


def _assemble(path, arrays, spacing=None, origin=None):
    """Validate named arrays (float64) into :class:`RDFields`."""
    if "rho" not in arrays:
        names = ", ".join(sorted(arrays)) or "none"
        _fail(path, "rho", f"missing; the density array is required (arrays present: {names})")
    rho = arrays["rho"]
    if rho.ndim not in (2, 3) or min(rho.shape) < 1:
        _fail(path, "rho", f"must be a 2D (ny, nx) or 3D (nz, ny, nx) grid; got shape {rho.shape}")
    grid = rho.shape
    d = len(grid)
    rho = _check_unit(path, "rho", rho, grid)
    sigma = rot = gamma = None
    if "sigma" in arrays:
        s = arrays["sigma"]
        if s.shape != grid + (d, d):
            _fail(path, "sigma", f"shape {s.shape} does not match rho's grid {grid} + ({d}, {d})")
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                sigma = check_tensor_field(s, name="sigma")
        except ValueError as exc:
            _fail(path, "sigma", str(exc).removeprefix("sigma "))
        for w in caught:
            warnings.warn(f"{path}: array 'sigma': {str(w.message).removeprefix('sigma: ')}",
                          w.category, stacklevel=4)
    if "R" in arrays:
        rot = _check_rotation(path, "R", arrays["R"], grid)
    if "gamma" in arrays:
        gamma = _check_unit(path, "gamma", arrays["gamma"], grid)
    for name, v in (("spacing", spacing), ("origin", origin)):
        if v is not None and (len(v) != d or not np.isfinite(v).all()
                              or (name == "spacing" and min(v) <= 0)):
            _fail(path, name, f"must be {d} finite numbers{' > 0' if name == 'spacing' else ''}; got {list(v)}")
    return RDFields(rho, sigma, rot, gamma, spacing=spacing, origin=origin, source=str(path))


# ---------------------------------------------------------------- npz

def _load_npz(path):
    try:
        with np.load(path, allow_pickle=False) as z:
            raw = {k: z[k] for k in z.files}
    except ValueError as exc:
        _fail(path, None, f"cannot read as .npz ({exc})")
    except (OSError, EOFError) as exc:
        _fail(path, None, f"cannot read as .npz ({exc})")
    except Exception as exc:          # zipfile.BadZipFile and friends
        _fail(path, None, f"cannot read as .npz ({type(exc).__name__}: {exc})")
    arrays = {}
    for key, name in (("rho", "rho"), ("sigma", "sigma"), ("R", "R"), ("rotation", "R"), ("gamma", "gamma")):
        if key in raw:
            a = raw[key]
            if not np.issubdtype(a.dtype, np.number) or np.iscomplexobj(a):
                _fail(path, key, f"must be a real numeric array; got dtype {a.dtype}")
            arrays[name] = a.astype(np.float64)
    extra = {k: np.asarray(raw[k], dtype=np.float64).ravel() for k in ("spacing", "origin") if k in raw}
    return _assemble(path, arrays, extra.get("spacing"), extra.get("origin"))


def _save_npz(path, fields):
    arrays = {"rho": fields.rho, "spacing": np.array(fields.spacing), "origin": np.array(fields.origin)}
    for name, key in (("sigma", "sigma"), ("rotation", "R"), ("gamma", "gamma")):
        if getattr(fields, name) is not None:
            arrays[key] = getattr(fields, name)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    write_atomic(path, buf.getvalue())


# ---------------------------------------------------------------- vti reading

class _Binary:
    """Decoder for VTK's binary blocks (header + optionally compressed data)."""

    def __init__(self, header_type, byte_order, compressor):
        order = "<" if byte_order == "LittleEndian" else ">"
        self.order = order
        self.hdt = np.dtype(order + ("u4" if header_type == "UInt32" else "u8"))
        self.compressor = compressor

    def _header_len(self, first):
        """Header byte count, given at least its first integer."""
        if self.compressor is None:
            return self.hdt.itemsize
        nblocks = int(np.frombuffer(first[:self.hdt.itemsize], self.hdt)[0])
        return (3 + nblocks) * self.hdt.itemsize

    def _payload_len(self, header):
        ints = np.frombuffer(header, self.hdt)
        return int(ints[0]) if self.compressor is None else int(ints[3:].sum())

    def _inflate(self, header, payload):
        if self.compressor is None:
            return payload
        ints = np.frombuffer(header, self.hdt)
        out, pos = [], 0
        for size in ints[3:]:
            chunk = payload[pos:pos + int(size)]
            pos += int(size)
            out.append(zlib.decompress(chunk) if self.compressor == "zlib" else lzma.decompress(chunk))
        return b"".join(out)

    def raw(self, buf, pos):
        h = self._header_len(buf[pos:pos + self.hdt.itemsize])
        header = buf[pos:pos + h]
        n = self._payload_len(header)
        payload = buf[pos + h:pos + h + n]
        if len(payload) != n:
            raise ValueError(f"appended data ends after {len(payload)} of {n} bytes")
        return self._inflate(header, payload)

    def b64(self, text, pos):
        def dec(a, b):
            return base64.b64decode(text[a:b], validate=True)

        def chars(nbytes):
            return 4 * -(-nbytes // 3)

        h = self._header_len(dec(pos, pos + chars(self.hdt.itemsize)))
        hc = chars(h)
        header = dec(pos, pos + hc)[:h]
        n = self._payload_len(header)
        if h % 3 and text[pos + hc - 1:pos + hc] != "=":
            # header and data were encoded as one base64 stream
            payload = dec(pos, pos + chars(h + n))[h:h + n]
        else:
            payload = dec(pos + hc, pos + hc + chars(n))[:n]
        if len(payload) != n:
            raise ValueError(f"base64 data ends after {len(payload)} of {n} bytes")
        return self._inflate(header, payload)


def _split_appended(raw):
    """(xml bytes without the AppendedData element, appended bytes or None, encoding)."""
    start = raw.find(b"<AppendedData")
    if start < 0:
        return raw, None, None
    tag_end = raw.index(b">", start)
    m = re.search(rb'encoding\s*=\s*"([^"]*)"', raw[start:tag_end])
    encoding = m.group(1).decode() if m else "raw"
    underscore = raw.index(b"_", tag_end)
    end = raw.rfind(b"</AppendedData>")
    if end < 0:
        end = len(raw)
    return raw[:start] + b"</VTKFile>", raw[underscore + 1:end], encoding


def _ints(text, count, what):
    vals = [int(float(v)) for v in text.split()]
    if len(vals) != count:
        raise ValueError(f"{what} must have {count} numbers; got {text!r}")
    return vals


def _floats(text, count, what):
    vals = [float(v) for v in text.split()]
    if len(vals) != count:
        raise ValueError(f"{what} must have {count} numbers; got {text!r}")
    return vals


def _read_vti(path):
    """Parse a .vti into grid info and {association: {name: (n, ncomp) float64}}."""
    from lxml import etree

    raw = Path(path).read_bytes()
    xml, appended, app_enc = _split_appended(raw)
    try:
        root = etree.fromstring(xml, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError as exc:
        _fail(path, None, f"not a readable VTK XML file ({exc})")
    if root.tag != "VTKFile" or root.get("type") != "ImageData":
        _fail(path, None, f"expected a VTKFile of type ImageData; got <{root.tag} type={root.get('type')!r}>")
    comp = root.get("compressor")
    comp = {None: None, "": None, "vtkZLibDataCompressor": "zlib", "vtkLZMADataCompressor": "lzma"}.get(comp, comp)
    if comp not in (None, "zlib", "lzma"):
        _fail(path, None, f"compressor {root.get('compressor')!r} is not supported (zlib or LZMA only)")
    header_type = root.get("header_type", "UInt32")
    if header_type not in ("UInt32", "UInt64") or root.get("byte_order", "LittleEndian") not in (
            "LittleEndian", "BigEndian"):
        _fail(path, None, f"header_type {header_type!r} / byte_order {root.get('byte_order')!r} not supported")
    binary = _Binary(header_type, root.get("byte_order", "LittleEndian"), comp)
    image = root.find("ImageData")
    if image is None:
        _fail(path, None, "no <ImageData> element")
    pieces = image.findall("Piece")
    if len(pieces) != 1:
        _fail(path, None, f"exactly one <Piece> is supported; got {len(pieces)}")
    try:
        ext = _ints(image.get("WholeExtent", ""), 6, "WholeExtent")
        origin = _floats(image.get("Origin", "0 0 0"), 3, "Origin")
        spacing = _floats(image.get("Spacing", "1 1 1"), 3, "Spacing")
        direction = _floats(image.get("Direction", "1 0 0 0 1 0 0 0 1"), 9, "Direction")
        piece_ext = _ints(pieces[0].get("Extent", image.get("WholeExtent")), 6, "Piece Extent")
    except ValueError as exc:
        _fail(path, None, str(exc))
    if piece_ext != ext:
        _fail(path, None, f"the piece extent {piece_ext} must cover the whole extent {ext}")
    if not np.allclose(direction, np.eye(3).ravel()):
        _fail(path, None, f"oriented images are not supported; Direction = {direction}")
    npts = [ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1]   # x, y, z
    if min(npts) < 1 or npts[0] < 2 or npts[1] < 2:
        _fail(path, None, f"WholeExtent {ext} is not a 2D or 3D image")
    dim = 2 if npts[2] == 1 else 3
    grids = {"PointData": tuple(reversed(npts[:dim])),
             "CellData": tuple(reversed([max(n - 1, 1) for n in npts[:dim]]))}
    data = {"CellData": {}, "PointData": {}}
    for assoc in data:
        node = pieces[0].find(assoc)
        for arr in ([] if node is None else node.findall("DataArray")):
            name = arr.get("Name")
            if name is None:
                continue
            ntuples = int(np.prod(grids[assoc]))
            try:
                data[assoc][name] = _read_data_array(arr, ntuples, binary, appended, app_enc)
            except (ValueError, KeyError, zlib.error, lzma.LZMAError) as exc:
                _fail(path, name, f"cannot decode ({exc})")
    return dim, grids, data, tuple(spacing[:dim]), tuple(origin[:dim])


def _read_data_array(arr, ntuples, binary, appended, app_enc):
    vtype = arr.get("type")
    if vtype not in _VTK_TYPES:
        raise ValueError(f"type {vtype!r} is not supported")
    ncomp = int(arr.get("NumberOfComponents", "1"))
    fmt = arr.get("format", "ascii")
    if fmt == "ascii":
        flat = np.array((arr.text or "").split(), dtype=np.float64)
    else:
        if fmt == "binary":
            buf = binary.b64("".join((arr.text or "").split()), 0)
        elif fmt == "appended":
            if appended is None:
                raise ValueError("format 'appended' but the file has no <AppendedData>")
            off = int(arr.get("offset", "0"))
            buf = (binary.raw(appended, off) if app_enc == "raw"
                   else binary.b64(appended.decode("ascii").strip(), off))
        else:
            raise ValueError(f"format {fmt!r} is not supported")
        dt = np.dtype(_VTK_TYPES[vtype]).newbyteorder(binary.order)
        if len(buf) % dt.itemsize:
            raise ValueError(f"{len(buf)} bytes is not a whole number of {vtype} values")
        flat = np.frombuffer(buf, dt).astype(np.float64)
    if flat.size != ntuples * ncomp:
        raise ValueError(f"holds {flat.size} values; expected {ntuples} tuples x {ncomp} components "
                         f"= {ntuples * ncomp}")
    return flat.reshape(ntuples, ncomp)


def _tensor_from_components(path, name, flat, d, symmetric):
    n, c = flat.shape
    if c == d * d:
        return flat.reshape(n, d, d)
    if d == 2 and c == 9:
        return flat.reshape(n, 3, 3)[:, :2, :2]
    if symmetric and d == 2 and c == 3:            # xx, yy, xy
        xx, yy, xy = flat.T
        return np.stack([np.stack([xx, xy], -1), np.stack([xy, yy], -1)], -2)
    if symmetric and d == 3 and c == 6:            # VTK order: xx, yy, zz, xy, yz, xz
        xx, yy, zz, xy, yz, xz = flat.T
        return np.stack([np.stack([xx, xy, xz], -1), np.stack([xy, yy, yz], -1),
                         np.stack([xz, yz, zz], -1)], -2)
    allowed = {(2, True): "4, 3 or 9", (3, True): "9 or 6", (2, False): "4 or 9", (3, False): "9"}[(d, symmetric)]
    _fail(path, name, f"has {c} components; a {d}D {'tensor' if symmetric else 'rotation'} needs {allowed}")


def _load_vti(path):
    dim, grids, data, spacing, origin = _read_vti(path)
    arrays = {}
    for name, key, kind in (("rho", "rho", "scalar"), ("gamma", "gamma", "scalar"), ("sigma", "sigma", "sym"),
                            ("R", "R", "rot"), ("rotation", "R", "rot")):
        assoc = "CellData" if name in data["CellData"] else "PointData" if name in data["PointData"] else None
        if assoc is None or key in arrays:
            continue
        flat = data[assoc][name]
        grid = grids[assoc]
        if kind == "scalar":
            if flat.shape[1] != 1:
                _fail(path, name, f"has {flat.shape[1]} components; expected a scalar (1)")
            arrays[key] = flat[:, 0].reshape(grid)
        else:
            t = _tensor_from_components(path, name, flat, dim, kind == "sym")
            arrays[key] = t.reshape(grid + (dim, dim))
    if "rho" not in arrays:
        names = sorted(set(data["CellData"]) | set(data["PointData"]))
        _fail(path, "rho", f"missing; the density array is required (arrays present: {', '.join(names) or 'none'})")
    return _assemble(path, arrays, spacing, origin)


# ---------------------------------------------------------------- vti writing

def _save_vti(path, fields, encoding):
    d = fields.ndim
    grid = fields.rho.shape
    nx, ny = grid[-1], grid[-2]
    nz = grid[0] if d == 3 else 0
    ext = f"0 {nx} 0 {ny} 0 {nz}"
    sp = list(fields.spacing) + [1.0] * (3 - d)
    org = list(fields.origin) + [0.0] * (3 - d)
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">',
             f'  <ImageData WholeExtent="{ext}" Origin="{" ".join(map(repr, org))}" '
             f'Spacing="{" ".join(map(repr, sp))}">',
             f'    <Piece Extent="{ext}">', '      <CellData>']
    for name, key in (("rho", "rho"), ("gamma", "gamma"), ("sigma", "sigma"), ("rotation", "R")):
        a = getattr(fields, name)
        if a is None:
            continue
        flat = np.ascontiguousarray(a, dtype="<f8").reshape(int(np.prod(grid)), -1)
        ncomp = flat.shape[1]
        if encoding == "ascii":
            body = " ".join(repr(float(v)) for v in flat.ravel())
        else:
            blob = flat.tobytes()
            body = base64.b64encode(np.array([len(blob)], "<u8").tobytes() + blob).decode("ascii")
        lines.append(f'        <DataArray type="Float64" Name="{key}" NumberOfComponents="{ncomp}" '
                     f'format="{"ascii" if encoding == "ascii" else "binary"}">')
        lines.append("          " + body)
        lines.append("        </DataArray>")
    lines += ["      </CellData>", "    </Piece>", "  </ImageData>", "</VTKFile>", ""]
    write_atomic(path, "\n".join(lines).encode("ascii"))


# ---------------------------------------------------------------- public

def _suffix(path):
    suffix = Path(path).suffix.lower()
    if suffix not in SUPPORTED_SUFFIXES:
        raise FieldFileError(f"{path}: file name must end in .npz or .vti; got {Path(path).suffix!r}")
    return suffix


def load_fields(path):
    """Read the input fields of a reaction/diffusion design from .npz or .vti.

    Parameters
    ----------
    path : str or os.PathLike
        An existing ``.npz`` or ``.vti`` file (see the module notes for the
        array names and the supported VTK subset).

    Returns
    -------
    RDFields

    Raises
    ------
    FieldFileError
        Missing ``rho``, a shape that does not match ``rho``'s grid, NaN or
        infinite values (the first bad cell is named), values of ``rho`` /
        ``gamma`` outside [0, 1], a grossly non-symmetric ``sigma``, a
        non-orthonormal ``R``, or an unreadable / unsupported file. A
        slightly non-symmetric ``sigma`` is symmetrised with a warning.
    """
    suffix = _suffix(path)
    if not Path(path).is_file():
        raise FieldFileError(f"{path}: no such file")
    return _load_npz(path) if suffix == ".npz" else _load_vti(path)


def save_fields(path, fields, *, encoding="base64"):
    """Write :class:`RDFields` as .npz or .vti (cell data), atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Ends in ``.npz`` or ``.vti``.
    fields : RDFields
    encoding : {"base64", "ascii"}
        For .vti: inline base64 binary (Float64, UInt64 header) or ascii.
    """
    if encoding not in ("base64", "ascii"):
        raise ValueError(f"encoding must be 'base64' or 'ascii'; got {encoding!r}")
    if _suffix(path) == ".npz":
        _save_npz(path, fields)
    else:
        _save_vti(path, fields, encoding)
