"""Marlin-flavoured G-code: a streaming writer and a small reader.

The writer takes :class:`~engine.fab.toolpaths.Layer` objects one at a time
and streams lines to a temporary sibling of the target, renamed over it at
the end; a cancelled or failed write leaves an existing file untouched.

Filament fed per mm of path: ``E = L * w * h * multiplier / (pi * (d_f/2)^2)``
(``w`` line width = nozzle diameter, ``h`` layer height, ``d_f`` filament
diameter), see :attr:`PrintSettings.filament_per_mm`.
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine.progress import report
from .print_settings import PrintSettings

GENERATOR = "Mesoforge engine.fab"
XY_DECIMALS = 3          # 1 µm
E_DECIMALS = 5
Z_LIFT_AT_END = 5.0      # mm the nozzle rises after the last layer
_COUNT_WIDTH = 10        # characters reserved for the layer count


@dataclass(frozen=True)
class GcodeSummary:
    """What a G-code file contains.

    Attributes
    ----------
    path : str
    layers : int
    extrusion_length, travel_length : float
        mm of nozzle path while extruding / travelling in XY.
    filament_length : float
        mm of filament fed (net of retractions).
    print_time : float
        s, lower bound from lengths and speeds (no acceleration).
    """

    path: str
    layers: int
    extrusion_length: float
    travel_length: float
    filament_length: float
    print_time: float


class _AtomicOutput:
    """Binary file written to a temporary sibling and renamed on success."""

    def __init__(self, path):
        self.path = Path(path)

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, self.tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".tmp",
                                        dir=self.path.parent)
        self.f = os.fdopen(fd, "w+b", buffering=1 << 20)
        return self.f

    def __exit__(self, kind, exc, tb):
        try:
            if kind is None:
                self.f.flush()
                os.fsync(self.f.fileno())
            self.f.close()
            if kind is None:
                os.replace(self.tmp, self.path)
        finally:
            if os.path.exists(self.tmp):
                os.unlink(self.tmp)
        return False


class _Emitter:
    """Machine state and line formatting for one print."""

    def __init__(self, settings: PrintSettings, out):
        self.s = settings
        self.out = out
        self.ox, self.oy = settings.offset
        self.x = self.y = 0.0
        self.z = 0.0
        self.e = 0.0                  # absolute E position (machine)
        self.retracted = False
        self.per_mm = settings.filament_per_mm
        self.extruded = self.travelled = self.filament = self.time = 0.0
        self.count_at = None

    def write(self, lines):
        self.out.write("".join(lines).encode("ascii"))

    def header(self):
        s = self.s
        lines = [";FLAVOR:Marlin\n", f";Generated with {GENERATOR}\n"]
        head = "".join(lines).encode("ascii")
        self.out.write(head)
        self.count_at = len(head) + len(";LAYER_COUNT:")
        lines = [f";LAYER_COUNT:{'?':>{_COUNT_WIDTH}}\n"]
        for key, value in s.to_dict().items():
            lines.append(f";SETTING {key} = {value}\n")
        lines += [
            f"M140 S{s.bed_temperature:g} ; bed\n",
            f"M104 S{s.nozzle_temperature:g} ; nozzle\n",
            f"M190 S{s.bed_temperature:g} ; wait for bed\n",
            f"M109 S{s.nozzle_temperature:g} ; wait for nozzle\n",
            "G28 ; home\n",
            "G90 ; absolute positions\n",
            "M83 ; relative extrusion\n" if s.relative_extrusion else "M82 ; absolute extrusion\n",
            "G92 E0\n",
        ]
        self.write(lines)

    def _e_word(self, delta):
        if self.s.relative_extrusion:
            return f"E{delta:.{E_DECIMALS}f}"
        return f"E{self.e:.{E_DECIMALS}f}"

    def _retract(self, lines):
        r = self.s.retraction_length
        if r <= 0 or self.retracted:
            return
        self.e -= r
        lines.append(f"G1 {self._e_word(-r)} F{60 * self.s.retraction_speed:.0f}\n")
        self.retracted = True

    def _unretract(self, lines):
        if not self.retracted:
            return
        r = self.s.retraction_length
        self.e += r
        lines.append(f"G1 {self._e_word(r)} F{60 * self.s.retraction_speed:.0f}\n")
        self.retracted = False

    def _travel(self, lines, x, y):
        d = math.hypot(x - self.x, y - self.y)
        if d < 10.0 ** -XY_DECIMALS:
            return
        if d >= self.s.retraction_min_travel:
            self._retract(lines)
        lines.append(f"G0 X{x:.{XY_DECIMALS}f} Y{y:.{XY_DECIMALS}f} F{60 * self.s.travel_speed:.0f}\n")
        self.x, self.y = x, y
        self.travelled += d
        self.time += d / self.s.travel_speed

    def layer(self, index, layer):
        s = self.s
        lines = [f";LAYER:{index}\n"]
        self._retract(lines)
        self.z = layer.z
        lines.append(f"G0 Z{layer.z:.{XY_DECIMALS}f} F{60 * s.travel_speed:.0f}\n")
        speed = s.first_layer_speed if index == 0 else s.print_speed
        kind = None
        for path, k in zip(layer.paths, layer.kinds):
            pts = path + (self.ox, self.oy)
            step = np.diff(pts, axis=0)
            seg = np.hypot(step[:, 0], step[:, 1])
            moving = seg > 0
            pts = np.concatenate([pts[:1], pts[1:][moving]])
            seg = seg[moving]
            if len(seg) == 0:
                continue
            if k != kind:
                lines.append(f";TYPE:{k}\n")
                kind = k
            self._travel(lines, float(pts[0, 0]), float(pts[0, 1]))
            self._unretract(lines)
            de = seg * self.per_mm
            evals = de if s.relative_extrusion else self.e + np.cumsum(de)
            lines.append(f"G1 F{60 * speed:.0f}\n")
            xf, yf, ef = f".{XY_DECIMALS}f", f".{XY_DECIMALS}f", f".{E_DECIMALS}f"
            lines.extend(f"G1 X{x:{xf}} Y{y:{yf}} E{e:{ef}}\n" for x, y, e in
                         zip(pts[1:, 0].tolist(), pts[1:, 1].tolist(), evals.tolist()))
            self.e += float(de.sum())
            self.filament += float(de.sum())
            length = float(seg.sum())
            self.extruded += length
            self.time += length / speed
            self.x, self.y = float(pts[-1, 0]), float(pts[-1, 1])
        self.write(lines)

    def footer(self, n_layers):
        lines = [";END\n"]
        self._retract(lines)
        lines += [
            f"G0 Z{self.z + Z_LIFT_AT_END:.{XY_DECIMALS}f} F{60 * self.s.travel_speed:.0f}\n",
            "M104 S0 ; nozzle off\n",
            "M140 S0 ; bed off\n",
            "M84 ; motors off\n",
            f";FILAMENT_USED_MM:{self.filament:.2f}\n",
            f";PRINT_TIME_S:{self.time:.0f}\n",
        ]
        self.write(lines)
        self.out.seek(self.count_at)
        self.out.write(f"{n_layers:>{_COUNT_WIDTH}}".encode("ascii"))
        self.out.seek(0, os.SEEK_END)


def write_gcode(layers, path, *, settings=None, n_layers=None, progress=None) -> GcodeSummary:
    """Stream layers to a G-code file.

    Parameters
    ----------
    layers : iterable of Layer
        In print order, lowest first; may be a generator (consumed once).
    path : str or os.PathLike
        Target file; replaced atomically.
    settings : PrintSettings or None
        Defaults when None.
    n_layers : int or None
        Expected number of layers for progress; ``len(layers)`` when None and
        available, else the total reported is 0 ("unknown").
    progress : callable or None
        ``progress(done, total) -> bool`` after each layer; False cancels
        (raises :class:`~engine.progress.Cancelled`, file untouched).

    Returns
    -------
    GcodeSummary
    """
    settings = settings or PrintSettings()
    if n_layers is None:
        n_layers = len(layers) if hasattr(layers, "__len__") else 0
    report(progress, 0, n_layers)
    count = 0
    with _AtomicOutput(path) as f:
        em = _Emitter(settings, f)
        em.header()
        for layer in layers:
            em.layer(count, layer)
            count += 1
            report(progress, count, max(n_layers, count) if n_layers else 0)
        em.footer(count)
    return GcodeSummary(path=str(path), layers=count, extrusion_length=em.extruded,
                        travel_length=em.travelled, filament_length=em.filament,
                        print_time=em.time)


@dataclass(frozen=True, eq=False)
class GcodeLayer:
    """Extruding paths read back from G-code (machine coordinates minus the
    ``offset`` given to :func:`read_gcode_paths`).

    Attributes
    ----------
    z : float
    paths : tuple of (m, 2) float64
        Runs of consecutive extruding moves.
    kinds : tuple of str
        From ``;TYPE:`` comments; ``"unknown"`` without one.
    filament : (n_paths,) float64
        mm of filament fed along each path.
    """

    z: float
    paths: tuple
    kinds: tuple
    filament: np.ndarray

    def __post_init__(self):
        for a in (*self.paths, self.filament):
            a.flags.writeable = False


def _words(code):
    out = {}
    for w in code.split()[1:]:
        try:
            out[w[0].upper()] = float(w[1:])
        except (ValueError, IndexError):
            pass
    return out


def read_gcode_paths(path, *, offset=(0.0, 0.0)) -> list:
    """Extruding paths of a G-code file, grouped by layer (by Z).

    A move extrudes when it changes X/Y and feeds filament; travel moves end
    a path; filament-only moves (retractions) do not. Understands G0/G1,
    G90/G91, M82/M83 and G92.

    Parameters
    ----------
    path : str or os.PathLike
    offset : (2,) float
        Subtracted from X and Y (the part placement on the bed).

    Returns
    -------
    list of GcodeLayer
    """
    ox, oy = (float(v) for v in offset)
    x = y = z = e = 0.0
    rel_xyz = rel_e = False
    kind = "unknown"
    layers = []
    cur = None           # [z, paths, kinds, filament]
    run, run_e = None, 0.0

    def close_run():
        nonlocal run, run_e
        if run is not None and len(run) >= 2:
            cur[1].append(np.array(run) - (ox, oy))
            cur[2].append(run_kind)
            cur[3].append(run_e)
        run, run_e = None, 0.0

    run_kind = kind
    with open(path, "r", encoding="ascii", errors="replace") as fh:
        for raw in fh:
            line = raw.strip()
            if not line:
                continue
            if line[0] == ";":
                if line.startswith(";TYPE:"):
                    kind = line[6:].strip()
                continue
            code = line.split(";", 1)[0].strip()
            head = code.split(None, 1)[0].upper() if code else ""
            if head in ("G0", "G1", "G00", "G01"):
                w = _words(code)
                nx = (x + w["X"] if rel_xyz else w["X"]) if "X" in w else x
                ny = (y + w["Y"] if rel_xyz else w["Y"]) if "Y" in w else y
                nz = (z + w["Z"] if rel_xyz else w["Z"]) if "Z" in w else z
                de = 0.0
                if "E" in w:
                    de = w["E"] if rel_e else w["E"] - e
                    e = e + de
                moved = nx != x or ny != y
                if nz != z:
                    close_run()
                if moved and de > 0:
                    if cur is None or cur[0] != nz:
                        close_run()
                        cur = [nz, [], [], []]
                        layers.append(cur)
                    if run is None or kind != run_kind:
                        close_run()
                        run, run_kind = [(x, y)], kind
                    run.append((nx, ny))
                    run_e += de
                elif moved:
                    close_run()
                x, y, z = nx, ny, nz
            elif head == "G90":
                rel_xyz = False
            elif head == "G91":
                rel_xyz = True
            elif head == "M82":
                rel_e = False
            elif head == "M83":
                rel_e = True
            elif head == "G92":
                w = _words(code)
                if "E" in w:
                    e = w["E"]
    close_run()
    return [GcodeLayer(z=c[0], paths=tuple(c[1]), kinds=tuple(c[2]),
                       filament=np.array(c[3], dtype=np.float64)) for c in layers]
