"""What each view of the RD dock shows: the pictures of the fields and structures on one slice.

`RDPictures` turns the data the dock holds (fields, structures, compiled
density, a live frame) into what the canvas draws for a view key ("rho",
"gamma", "tensor<i>", "s<i>", "combined") on the current slice of the view
grid: values, colours, scale, direction glyphs or streamlines, a note.
Pure computation over numpy arrays: no widgets.
"""

from __future__ import annotations

import numpy as np

from engine.rd.preview import (glyph_segments, grid_slice, principal_glyphs, principal_streamlines,
                               rescale_index, slice_shape)

from .phasor_canvas import apply_lut, colour_lut
from .rd_view_controls import ORDINAL

GLYPHS = 18              # glyphs / streamline seeds along the longer side


class RDPictures:
    """Pictures of one slice.

    view : the dock's view state: ``axis`` ("x", "y", "z"), ``index`` (layer of the
        view grid, None in 2D), ``view_grid()`` (shape of the grid picture cells refer
        to), ``iso()`` (the infill space threshold), ``direction_style``
        ("glyphs" or "streamlines")
    """

    def __init__(self, view):
        self.view = view
        self._magnitude_cache = (None, None)

    def _layer(self, source_shape) -> int | None:
        """The layer of a grid of ``source_shape`` under the current slice of the view grid."""
        if len(source_shape) != 3:
            return None
        g = {"z": 0, "y": 1, "x": 2}[self.view.axis]
        return rescale_index(self.view.index, self.view.view_grid()[g], source_shape[g])

    def _to_view(self, source_shape) -> np.ndarray:
        """(2,) factors from a source grid's slice cells to the view grid's slice cells."""
        n_v, n_u = slice_shape(source_shape, self.view.axis)
        m_v, m_u = slice_shape(self.view.view_grid(), self.view.axis)
        return np.array([m_u / n_u, m_v / n_v])

    # -- pictures -----------------------------------------------------------------------------
    def _magnitude_range(self, fields) -> tuple | None:
        if fields is None or fields.magnitude is None:
            return None
        key, rng = self._magnitude_cache
        if key is not fields:
            m = np.asarray(fields.magnitude[..., 0])
            rng = (float(m.min()), float(m.max()) if m.max() > m.min() else float(m.min()) + 1.0)
            self._magnitude_cache = (fields, rng)
        return rng

    def _structure_source(self, data):
        """(s (n,) + grid, directions) to show: the live growth, else the node's output."""
        live = data.get("live")
        if live is not None:
            return live.s, tuple(live.directions)
        st = data.get("structures")
        return (None, ()) if st is None else (st.s, tuple(st.directions))

    def picture(self, data: dict, key: str) -> dict | None:
        """What view ``key`` shows of ``data`` on the current slice:
        ``{values, source, index, rgb, scale, segments, colours, lines, glyphs, note}``; None
        when there is nothing to show."""
        fields = data.get("fields")
        out = {"segments": None, "colours": None, "lines": [], "glyphs": None, "note": "", "scale": None}
        if key in ("rho", "gamma") or key.startswith("tensor"):
            if fields is None:
                return None
            index = self._layer(fields.grid_shape)
            axis = self.view.axis
            rho = np.asarray(grid_slice(fields.rho, axis, index or 0))
            out.update(source="fields", index=index)
            if key == "gamma":
                out["values"] = np.asarray(grid_slice(fields.gamma, axis, index or 0))
                out["scale"] = (colour_lut("magma"), 0.0, 1.0, "Gamma")
                out["rgb"] = apply_lut(out["values"], 0.0, 1.0, out["scale"][0])
            elif key == "rho":
                out["values"] = rho
                out["scale"] = (colour_lut("Greys"), 0.0, 1.0, "rho")
                out["rgb"] = apply_lut(rho, 0.0, 1.0, out["scale"][0])
            else:
                out["values"] = rho
                out["rgb"] = apply_lut(rho, 0.0, 3.5, colour_lut("Greys"))   # a light background
                self._tensor_overlay(fields, int(key[-1]), index, out)
            return out
        s, dirs = self._structure_source(data)
        if key == "combined":
            compiled = data.get("compiled")
            if compiled is not None and data.get("live") is None:
                grid = tuple(compiled.grid_shape)
                index = self._layer(grid)
                values = np.asarray(grid_slice(compiled.values, self.view.axis, index or 0, ndim=len(grid)))
                out["note"] = "RDCompile density"
            elif s is not None:
                index = self._layer(s.shape[1:])
                values = np.asarray(grid_slice(np.max(s, axis=0), self.view.axis, index or 0))
                out["note"] = "union max_i s_i (RDCompile's result once evaluated)" if data.get("live") is None \
                    else "live: union max_i s_i"
            else:
                return None
        else:
            i = int(key[-1])
            if s is None:
                return None
            if i not in dirs:
                out["note"] = f"the {ORDINAL[i]} direction is not grown (RDGrow directions)"
                return None
            index = self._layer(s.shape[1:])
            values = np.asarray(grid_slice(s[dirs.index(i)], self.view.axis, index or 0))
            out["note"] = "live growth" if data.get("live") is not None else ""
        out.update(source="growth", index=index, values=values)
        out["scale"] = (colour_lut("Greys"), 0.0, 1.0, "s")
        out["rgb"] = apply_lut(values, 0.0, 1.0, out["scale"][0])
        return out

    def _tensor_overlay(self, fields, direction: int, index, out: dict) -> None:
        axis = self.view.axis
        mask = np.asarray(fields.rho) >= self.view.iso()
        magnitude = None if fields.magnitude is None else fields.magnitude[..., 0]
        factors = self._to_view(fields.grid_shape)
        if self.view.direction_style == "streamlines":
            lines = principal_streamlines(fields.rotation, direction=direction, mask=mask, axis=axis,
                                          index=index or 0, count=GLYPHS)
            out["lines"] = [line * factors for line in lines]
            return
        g = principal_glyphs(fields.rotation, direction=direction, magnitude=magnitude, mask=mask, axis=axis,
                             index=index or 0, count=GLYPHS)
        out["glyphs"] = g
        n_v, n_u = slice_shape(fields.grid_shape, axis)
        spacing = max(n_v, n_u) / GLYPHS * float(factors.mean())
        out["segments"] = glyph_segments(g.centres * factors, g.vectors * factors / factors.mean(),
                                         0.8 * spacing)
        rng = self._magnitude_range(fields)
        if rng is not None:
            lut = colour_lut("viridis")
            out["colours"] = apply_lut(g.values, *rng, lut)
            out["scale"] = (lut, rng[0], rng[1], "|sigma_1|")
