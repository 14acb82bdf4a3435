"""Material sphere: the directional Young's modulus drawn as a closed surface.

Section 6.6 / Fig. 11(c) of "Procedural Metamaterials" displays the
(an)isotropy of a homogenized ``C`` as a sphere whose distance to the centre
and colour follow the response to uniaxial stress in each direction. Here
the surface is ``r(d) = E(d) d`` over unit directions ``d``, with ``E(d)``
from :func:`engine.physics.elastic.directional_young`; an isotropic material
gives a sphere of radius ``E``. ``quantity="compliance"`` draws
``1 / E(d)`` instead (strain per unit uniaxial stress), the figure's literal
wording; stiff directions then sit close to the centre.

Directions are the vertices of an icosphere (trimesh), so the sampling is
nearly uniform and the surface is a closed triangle mesh.
"""

from __future__ import annotations

import numpy as np

from .elastic import compliance, directional_young, directional_young_polar

__all__ = ["material_sphere", "material_sphere_polydata", "material_polar", "QUANTITIES"]

QUANTITIES = ("young", "compliance")
_ARRAY_NAMES = {"young": "E", "compliance": "1/E"}


def _check_quantity(quantity):
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {QUANTITIES}; got {quantity!r}")
    return quantity


def _check_int(value, name, lo, hi):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise ValueError(f"{name} must be an integer in [{lo}, {hi}]; got {value!r}")
    return int(value)


def material_sphere(C, *, subdivisions=4, quantity="young"):
    """Surface ``r(d) = E(d) d`` of a 3D stiffness over an icosphere.

    Parameters
    ----------
    C : (6, 6) array_like
        Positive definite Voigt stiffness (convention of
        :mod:`engine.physics.elastic`).
    subdivisions : int in [0, 7]
        Icosphere refinement: ``10 * 4**s + 2`` vertices (4: 2562).
    quantity : {"young", "compliance"}
        Radius and value ``E(d)``, or ``1 / E(d)``.

    Returns
    -------
    vertices : (v, 3) float64
        ``value(d) * d``, same unit as ``C`` (or its inverse).
    faces : (f, 3) int64
        Outward-wound triangles (the surface is star-shaped about 0).
    values : (v,) float64
        ``E(d)`` (or ``1 / E(d)``) per vertex, for colouring.
    """
    import trimesh

    s = compliance(C)
    if s.shape != (6, 6):
        raise ValueError(f"C must be a 6x6 (3D) stiffness for a material sphere; got {s.shape}; "
                         "use material_polar in 2D")
    subdivisions = _check_int(subdivisions, "subdivisions", 0, 7)
    _check_quantity(quantity)
    ico = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    d = np.asarray(ico.vertices, dtype=np.float64)
    d /= np.linalg.norm(d, axis=1)[:, None]
    e = directional_young(s, d, kind="compliance")
    values = e if quantity == "young" else 1.0 / e
    return d * values[:, None], np.asarray(ico.faces, dtype=np.int64), values


def material_sphere_polydata(C, *, subdivisions=4, quantity="young"):
    """:func:`material_sphere` as a ``pyvista.PolyData`` for display.

    Returns
    -------
    pyvista.PolyData
        Triangles with the point array ``"E"`` (``"1/E"`` for
        ``quantity="compliance"``) set as active scalars.
    """
    import pyvista as pv

    vertices, faces, values = material_sphere(C, subdivisions=subdivisions, quantity=quantity)
    cells = np.hstack([np.full((faces.shape[0], 1), 3, dtype=np.int64), faces]).ravel()
    mesh = pv.PolyData(vertices, cells)
    name = _ARRAY_NAMES[quantity]
    mesh.point_data[name] = values
    mesh.set_active_scalars(name)
    return mesh


def material_polar(C2d, *, n=360, quantity="young"):
    """Polar curve of the in-plane Young's modulus of a 2D material.

    Parameters
    ----------
    C2d : (3, 3) array_like
        Plane-stress Voigt stiffness, order (xx, yy, xy).
    n : int >= 3
        Number of angles, ``theta_k = 2 pi k / n`` (endpoint excluded).
    quantity : {"young", "compliance"}

    Returns
    -------
    theta : (n,) float64
        Radians from x towards y.
    values : (n,) float64
        ``E(theta)`` or ``1 / E(theta)``; the curve is ``values * (cos, sin)``.
    """
    s = compliance(C2d)
    if s.shape != (3, 3):
        raise ValueError(f"C2d must be a 3x3 plane-stress stiffness; got {s.shape}; "
                         "use material_sphere in 3D")
    n = _check_int(n, "n", 3, 10**7)
    _check_quantity(quantity)
    theta = 2 * np.pi * np.arange(n) / n
    e = directional_young_polar(s, theta, kind="compliance")
    return theta, (e if quantity == "young" else 1.0 / e)
