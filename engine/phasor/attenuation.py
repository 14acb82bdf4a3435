"""Filter attenuation A(x) from the local angular spread (Tricard et al. 4.2.4).

The evaluation filter keeps only kernels whose frequency vector is close to
the local F(x) e(x); with A = 1 a kernel tilted by ~8 degrees already loses
most of its weight, which would erase the spread the designer asked for with
Gamma.  The paper derives A from "the local angular spread of the phasor
noise, a combination of Gamma and the gradient of D" without a formula;
this module uses

    theta(x) = Gamma(x) + lambda * R * |grad D|(x)          (radians)
    A(x)     = 1 - smoothstep(theta(x) / theta_full)

with ``|grad D|`` the Frobenius norm of the Jacobian of D (rad/mm for small
turns), R the kernel radius, ``smoothstep(t) = 3 t^2 - 2 t^3`` clamped to
[0, 1].  So A = 1 (full filter) where Gamma = 0 and D is uniform, A = 0 (a
plain wider Gaussian, no preferred orientation) once the spread reaches
``theta_full`` (default pi / 10: at Gamma = pi / 20 A = 1/2), and A is C1
in theta.  The gradient term is damped by ``lambda`` (default 1/4): D
turning smoothly is exactly where the oriented filter helps (paper fig. 14),
so only turns of tens of degrees within one kernel radius (a painted
discontinuity) should switch it off.

A is computed on the fields' grid and sampled trilinearly, so a shader can
read it as one more 3-D texture.
"""

from __future__ import annotations

import math

import numpy as np

from .fields import PhasorFields

FULL_SPREAD = math.pi / 10
GRADIENT_WEIGHT = 0.25


def direction_gradient_norm(fields: PhasorFields) -> np.ndarray:
    """|grad D| (nz, ny, nx) float64, 1/mm: Frobenius norm of the Jacobian of D.

    Central differences between cell centres (one-sided at the faces); an
    axis with a single cell contributes nothing.
    """
    d = fields.direction
    total = np.zeros(fields.shape)
    for axis, step in zip((2, 1, 0), fields.spacing):  # grid axes x, y, z
        if d.shape[axis] < 2:
            continue
        deriv = np.gradient(d, float(step), axis=axis)
        total += np.sum(deriv * deriv, axis=-1)
    return np.sqrt(total)


def angular_spread(fields: PhasorFields, *, radius: float, gradient_weight: float = GRADIENT_WEIGHT) -> np.ndarray:
    """Effective spread theta = Gamma + lambda R |grad D|, (nz, ny, nx) radians.

    radius : float, mm, the kernel radius R (``kernels.radius``)
    """
    if not (math.isfinite(radius) and radius > 0):
        raise ValueError(f"radius: expected the positive kernel radius in mm, got {radius!r}")
    if not (math.isfinite(gradient_weight) and gradient_weight >= 0):
        raise ValueError(f"gradient_weight: expected a number >= 0, got {gradient_weight!r}")
    return fields.spread + gradient_weight * radius * direction_gradient_norm(fields)


def attenuation_from_spread(theta, *, full_spread: float = FULL_SPREAD) -> np.ndarray:
    """A = 1 - smoothstep(theta / full_spread), float64 in [0, 1]."""
    if not (math.isfinite(full_spread) and full_spread > 0):
        raise ValueError(f"full_spread: expected a positive angle in radians, got {full_spread!r}")
    t = np.clip(np.asarray(theta, dtype=np.float64) / full_spread, 0.0, 1.0)
    return 1.0 - t * t * (3.0 - 2.0 * t)


def attenuation_grid(fields: PhasorFields, *, radius: float, full_spread: float = FULL_SPREAD,
                     gradient_weight: float = GRADIENT_WEIGHT) -> np.ndarray:
    """A(x) on the fields' cells, (nz, ny, nx) float64 in [0, 1].

    Pass it as ``attenuation=`` to :func:`engine.phasor.noise.phasor_complex`.

    Parameters
    ----------
    fields : PhasorFields
    radius : float, mm, kernel radius R
    full_spread : float, radians, effective spread at which A reaches 0
    gradient_weight : float, lambda, weight of R |grad D| in the spread
    """
    theta = angular_spread(fields, radius=radius, gradient_weight=gradient_weight)
    return attenuation_from_spread(theta, full_spread=full_spread)
