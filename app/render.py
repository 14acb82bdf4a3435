"""Off-screen rendering of a mesh to PNG (pyvista/VTK, EGL when there is no display)."""

from __future__ import annotations

import numpy as np


def render_mesh_png(vertices: np.ndarray, faces: np.ndarray, path: str, *, size=(1024, 768)) -> None:
    import pyvista as pv

    cells = np.hstack([np.full((len(faces), 1), 3), np.asarray(faces)]).ravel()
    mesh = pv.PolyData(np.asarray(vertices, float), cells)
    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        plotter.set_background("white")
        plotter.add_mesh(mesh, color="#7aa6d6", smooth_shading=True, specular=0.3)
        plotter.add_mesh(mesh.outline(), color="black")
        plotter.camera_position = "iso"
        plotter.screenshot(path)
    finally:
        plotter.close()
