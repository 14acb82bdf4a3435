"""Linear elasticity of homogenized cells: notation conversions, engineering
constants, symmetry class, bounds and the directional Young's modulus.

Convention (shared with the homogenization solvers)
---------------------------------------------------
3D: ``C`` is a 6x6 Voigt matrix with *engineering* shear strains, order
(xx, yy, zz, yz, xz, xy)::

    [s_xx, s_yy, s_zz, s_yz, s_xz, s_xy] = C @ [e_xx, e_yy, e_zz, 2 e_yz, 2 e_xz, 2 e_xy]

so ``C[I, J] = C_ijkl`` with no factors. 2D plane stress: 3x3, order
(xx, yy, xy), same rule. ``S = inv(C)`` in the same convention, hence
``S[0, 0] = S_1111``, ``S[1, 0] = S_2211`` and
``S[3, 3] = 4 S_2323 = 1 / G_yz`` (a factor 2 for each shear index).

Mandel notation scales each shear row and column by sqrt(2):
``C_m = W C W`` and ``S_m = inv(W) S inv(W)`` with ``W = diag(1, 1, 1, r, r, r)``,
``r = sqrt(2)``. It is orthonormal: ``inv(C_m) = S_m``, its eigenvalues are
the Kelvin moduli, and ``A_m - B_m`` positive semidefinite means
``e:A:e >= e:B:e`` for every strain, which the bound checks use.

Engineering constants are those of eqs. 1-8 of Liu et al., "Growth rules
for irregular architected materials with programmable properties" (the
"virtual growth" paper): ``E_x = 1/S_1111``, ``nu_xy = -S_2211/S_1111``
(strain along y over strain along x under stress along x), ``E_avg`` and
``nu_avg`` are plain means. Its eqs. 7-8 write ``G_xy = 1/S_1212`` with the
Voigt matrix entry in mind: with the tensor component, ``1/S_1212`` would be
``4 G_xy``. Here ``G_xy = 1/S[5, 5]`` (3D) and ``G = 1/S[2, 2]`` (2D), the
ratio of shear stress to engineering shear strain.

All functions are pure: they never modify their inputs and return new
float64 arrays or plain floats. Moduli carry whatever unit ``C`` has.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "voigt_to_tensor", "tensor_to_voigt", "voigt_to_mandel", "mandel_to_voigt",
    "rotate_stiffness", "compliance",
    "isotropic_stiffness", "isotropic_plane_stress",
    "engineering_constants", "voigt_reuss_moduli", "universal_anisotropy_index",
    "symmetry_class", "zener_ratio", "is_singular",
    "hashin_shtrikman_bounds", "inside_hashin_shtrikman", "BoundsCheck",
    "directional_young", "directional_young_polar",
]

# A stiffness whose largest asymmetry |C - C.T| exceeds this fraction of
# max|C| is refused; smaller asymmetry (solver round-off) is averaged away.
SYMMETRY_RTOL = 1e-6
# The smallest eigenvalue must exceed this fraction of the largest for C to
# count as invertible (a cell that is a mechanism has zero eigenvalues).
DEFINITE_RTOL = 1e-12

VOIGT_PAIRS_3D = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))
VOIGT_PAIRS_2D = ((0, 0), (1, 1), (0, 1))
KINDS = ("stiffness", "compliance")


# ----------------------------------------------------------------- validation

def _scalar(value, name):
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number; got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite; got {value!r}")
    return x


def _check_kind(kind):
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}; got {kind!r}")
    return kind


def _check_matrix(C, name="C"):
    """Return ``C`` as a symmetric float64 (6, 6) or (3, 3) array."""
    try:
        a = np.array(C, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a numeric 6x6 (3D) or 3x3 (2D) Voigt matrix; "
                         f"got {type(C).__name__}") from None
    if a.shape not in ((6, 6), (3, 3)):
        raise ValueError(f"{name} must be a 6x6 (3D) or 3x3 (2D plane stress) Voigt matrix; "
                         f"got shape {a.shape}")
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        raise ValueError(f"{name} must be finite; got {a[tuple(bad[0])]} at index {tuple(bad[0].tolist())}")
    scale = np.abs(a).max()
    if scale == 0:
        raise ValueError(f"{name} is all zeros; the cell carries no load" if name == "C"
                         else f"{name} is all zeros")
    asym = np.abs(a - a.T).max()
    if asym > SYMMETRY_RTOL * scale:
        raise ValueError(f"{name} must be symmetric; largest |{name} - {name}.T| is {asym:.3g}, "
                         f"{asym / scale:.2g} of max|{name}| (tolerance {SYMMETRY_RTOL:g})")
    return 0.5 * (a + a.T)


def _pairs(n):
    return VOIGT_PAIRS_3D if n == 6 else VOIGT_PAIRS_2D


def _shear_weights(n, kind):
    """Per-index factor f with ``A_voigt[I, J] = f_I f_J A_ijkl``."""
    d = 3 if n == 6 else 2
    f = np.ones(n)
    if kind == "compliance":
        f[d:] = 2.0
    return f


def _mandel_scale(n, kind):
    d = 3 if n == 6 else 2
    w = np.ones(n)
    w[d:] = math.sqrt(2.0) if kind == "stiffness" else 1.0 / math.sqrt(2.0)
    return np.outer(w, w)


def compliance(C):
    """``S = inv(C)`` after checking that ``C`` is symmetric positive definite.

    Parameters
    ----------
    C : (6, 6) or (3, 3) array_like, float
        Voigt stiffness (module convention).

    Returns
    -------
    S : same shape, float64, symmetric
    """
    a = _check_matrix(C)
    lam = np.linalg.eigvalsh(a)  # congruent to the Mandel form: same signs
    if lam[0] <= DEFINITE_RTOL * lam[-1]:
        raise ValueError(f"C must be positive definite to invert; smallest eigenvalue {lam[0]:.3g} "
                         f"(largest {lam[-1]:.3g}): the cell is a mechanism or its solid does not "
                         "connect across the cell")
    s = np.linalg.inv(a)
    return 0.5 * (s + s.T)


# ---------------------------------------------------------- notation changes

def voigt_to_tensor(A, *, kind="stiffness"):
    """Full 4th-order tensor from a Voigt matrix.

    Parameters
    ----------
    A : (6, 6) or (3, 3) array_like, float
        Voigt stiffness or compliance (module convention).
    kind : {"stiffness", "compliance"}
        Compliance entries with shear indices carry factors 2 that are
        removed here.

    Returns
    -------
    T : (3, 3, 3, 3) or (2, 2, 2, 2) float64
        With major and minor symmetries.
    """
    _check_kind(kind)
    a = _check_matrix(A, "A")
    f = _shear_weights(a.shape[0], kind)
    pairs = _pairs(a.shape[0])
    d = 3 if a.shape[0] == 6 else 2
    t = np.zeros((d, d, d, d))
    for I, (i, j) in enumerate(pairs):
        for J, (k, l) in enumerate(pairs):
            v = a[I, J] / (f[I] * f[J])
            t[i, j, k, l] = t[j, i, k, l] = t[i, j, l, k] = t[j, i, l, k] = v
    return t


def tensor_to_voigt(T, *, kind="stiffness", rtol=SYMMETRY_RTOL):
    """Voigt matrix from a 4th-order tensor with minor symmetries.

    Parameters
    ----------
    T : (3, 3, 3, 3) or (2, 2, 2, 2) array_like, float
    kind : {"stiffness", "compliance"}
    rtol : float
        Allowed violation of the minor symmetries, relative to max|T|.

    Returns
    -------
    A : (6, 6) or (3, 3) float64
    """
    _check_kind(kind)
    t = np.asarray(T, dtype=np.float64)
    if t.shape not in ((3, 3, 3, 3), (2, 2, 2, 2)) or not np.all(np.isfinite(t)):
        raise ValueError(f"T must be a finite (3, 3, 3, 3) or (2, 2, 2, 2) tensor; got shape {t.shape}")
    scale = max(np.abs(t).max(), np.finfo(float).tiny)
    minor = max(np.abs(t - t.transpose(1, 0, 2, 3)).max(), np.abs(t - t.transpose(0, 1, 3, 2)).max())
    if minor > rtol * scale:
        raise ValueError(f"T must have minor symmetries T_ijkl = T_jikl = T_ijlk; largest violation "
                         f"{minor:.3g} ({minor / scale:.2g} of max|T|)")
    n = 6 if t.shape[0] == 3 else 3
    pairs, f = _pairs(n), _shear_weights(n, kind)
    a = np.empty((n, n))
    for I, (i, j) in enumerate(pairs):
        for J, (k, l) in enumerate(pairs):
            a[I, J] = t[i, j, k, l] * f[I] * f[J]
    return a


def voigt_to_mandel(A, *, kind="stiffness"):
    """Mandel (orthonormal) matrix from a Voigt matrix of the same kind.

    Returns
    -------
    (6, 6) or (3, 3) float64; ``inv(voigt_to_mandel(C)) ==
    voigt_to_mandel(inv(C), kind="compliance")``.
    """
    a = _check_matrix(A, "A")
    return a * _mandel_scale(a.shape[0], _check_kind(kind))


def mandel_to_voigt(M, *, kind="stiffness"):
    """Inverse of :func:`voigt_to_mandel`."""
    m = _check_matrix(M, "M")
    return m / _mandel_scale(m.shape[0], _check_kind(kind))


def rotate_stiffness(A, R, *, kind="stiffness"):
    """Express a stiffness (or compliance) in axes rotated by ``R``.

    Parameters
    ----------
    A : (6, 6) or (3, 3) array_like
        Voigt matrix (module convention).
    R : (3, 3) or (2, 2) array_like
        Proper or improper orthogonal matrix; a material direction ``d``
        becomes ``R @ d``.
    kind : {"stiffness", "compliance"}

    Returns
    -------
    Voigt matrix of the rotated material, ``A'_ijkl = R_ia R_jb R_kc R_ld A_abcd``.
    """
    t = voigt_to_tensor(A, kind=kind)
    r = np.asarray(R, dtype=np.float64)
    d = t.shape[0]
    if r.shape != (d, d) or not np.allclose(r @ r.T, np.eye(d), atol=1e-10):
        raise ValueError(f"R must be an orthogonal {d}x{d} matrix; got shape {r.shape}")
    t2 = np.einsum("ia,jb,kc,ld,abcd->ijkl", r, r, r, r, t, optimize=True)
    return tensor_to_voigt(t2, kind=kind, rtol=1e-9)


# ------------------------------------------------------------- isotropic law

def _check_young_poisson(E, nu, nu_max, what):
    E = _scalar(E, "E")
    nu = _scalar(nu, "nu")
    if E <= 0:
        raise ValueError(f"E must be > 0 (Young's modulus); got {E!r}")
    if not -1.0 < nu < nu_max:
        raise ValueError(f"nu must lie in the open interval (-1, {nu_max}) for {what}; got {nu!r}")
    return E, nu


def isotropic_stiffness(E, nu):
    """6x6 Voigt stiffness of an isotropic solid.

    Parameters
    ----------
    E : float > 0
        Young's modulus.
    nu : float in (-1, 0.5)
        Poisson's ratio (the open interval keeps ``C`` positive definite).

    Returns
    -------
    C : (6, 6) float64
    """
    E, nu = _check_young_poisson(E, nu, 0.5, "a 3D isotropic solid")
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    c = np.zeros((6, 6))
    c[:3, :3] = lam
    c[np.arange(3), np.arange(3)] += 2 * mu
    c[np.arange(3, 6), np.arange(3, 6)] = mu
    return c


def isotropic_plane_stress(E, nu):
    """3x3 plane-stress stiffness, order (xx, yy, xy), engineering shear.

    Parameters
    ----------
    E : float > 0
    nu : float in (-1, 1)

    Returns
    -------
    C : (3, 3) float64
    """
    E, nu = _check_young_poisson(E, nu, 1.0, "plane stress")
    k = E / (1 - nu * nu)
    return np.array([[k, k * nu, 0.0], [k * nu, k, 0.0], [0.0, 0.0, k * (1 - nu) / 2]])


# ------------------------------------------------------ engineering constants

def voigt_reuss_moduli(C):
    """Voigt and Reuss averages of the bulk and shear moduli.

    3D: ``K_V = (C11+C22+C33 + 2(C12+C13+C23))/9``,
    ``G_V = (C11+C22+C33 - (C12+C13+C23) + 3(C44+C55+C66))/15``,
    ``1/K_R = S11+S22+S33 + 2(S12+S13+S23)``,
    ``15/G_R = 4(S11+S22+S33) - 4(S12+S13+S23) + 3(S44+S55+S66)``.
    2D (area bulk modulus, ``(s_xx+s_yy)/2 = K (e_xx+e_yy)``):
    ``K_V = (C11+C22+2 C12)/4``, ``G_V = (C11+C22-2 C12+4 C33)/8``,
    ``1/K_R = S11+S22+2 S12``, ``2/G_R = S11+S22-2 S12+S33``. These are the
    projections of ``C`` (resp. ``S``) on the isotropic tensors. ``K_R`` is
    the response to hydrostatic stress of the anisotropic material itself.

    Returns
    -------
    dict of float: ``K_voigt``, ``K_reuss``, ``G_voigt``, ``G_reuss``
    """
    c = _check_matrix(C)
    s = compliance(c)
    if c.shape[0] == 6:
        kv = (np.trace(c[:3, :3]) + 2 * (c[0, 1] + c[0, 2] + c[1, 2])) / 9
        gv = (np.trace(c[:3, :3]) - (c[0, 1] + c[0, 2] + c[1, 2]) + 3 * np.trace(c[3:, 3:])) / 15
        kr = 1 / (np.trace(s[:3, :3]) + 2 * (s[0, 1] + s[0, 2] + s[1, 2]))
        gr = 15 / (4 * np.trace(s[:3, :3]) - 4 * (s[0, 1] + s[0, 2] + s[1, 2]) + 3 * np.trace(s[3:, 3:]))
    else:
        kv = (c[0, 0] + c[1, 1] + 2 * c[0, 1]) / 4
        gv = (c[0, 0] + c[1, 1] - 2 * c[0, 1] + 4 * c[2, 2]) / 8
        kr = 1 / (s[0, 0] + s[1, 1] + 2 * s[0, 1])
        gr = 2 / (s[0, 0] + s[1, 1] - 2 * s[0, 1] + s[2, 2])
    return {"K_voigt": float(kv), "K_reuss": float(kr), "G_voigt": float(gv), "G_reuss": float(gr)}


def engineering_constants(C):
    """Young's moduli, Poisson's ratios and shear moduli from ``S = inv(C)``.

    Parameters
    ----------
    C : (6, 6) or (3, 3) array_like
        Symmetric positive definite Voigt stiffness (module convention).

    Returns
    -------
    dict of float
        3D: ``E_x, E_y, E_z, nu_xy, nu_yx, nu_yz, nu_zy, nu_xz, nu_zx, G_xy,
        G_yz, G_xz, E_avg, nu_avg`` (eqs. 1, 3, 4, 6, 8 of the virtual-growth
        paper, ``nu_ij = -S_jjii / S_iiii``) plus ``K_voigt, K_reuss,
        G_voigt, G_reuss`` (see :func:`voigt_reuss_moduli`).
        2D: ``E_x, E_y, nu_xy, nu_yx, G, E_avg, nu_avg`` (eqs. 1, 2, 4, 5, 7)
        plus the same four averages in their 2D form.
    """
    s = compliance(C)
    out = {}
    if s.shape[0] == 6:
        ex, ey, ez = 1 / s[0, 0], 1 / s[1, 1], 1 / s[2, 2]
        out.update(E_x=ex, E_y=ey, E_z=ez,
                   nu_xy=-s[1, 0] / s[0, 0], nu_yx=-s[0, 1] / s[1, 1],
                   nu_yz=-s[2, 1] / s[1, 1], nu_zy=-s[1, 2] / s[2, 2],
                   nu_xz=-s[2, 0] / s[0, 0], nu_zx=-s[0, 2] / s[2, 2],
                   G_xy=1 / s[5, 5], G_yz=1 / s[3, 3], G_xz=1 / s[4, 4])
        out["E_avg"] = (ex + ey + ez) / 3
        out["nu_avg"] = sum(out[k] for k in ("nu_xy", "nu_yx", "nu_yz", "nu_zy", "nu_xz", "nu_zx")) / 6
    else:
        ex, ey = 1 / s[0, 0], 1 / s[1, 1]
        out.update(E_x=ex, E_y=ey, nu_xy=-s[1, 0] / s[0, 0], nu_yx=-s[0, 1] / s[1, 1], G=1 / s[2, 2])
        out["E_avg"] = (ex + ey) / 2
        out["nu_avg"] = (out["nu_xy"] + out["nu_yx"]) / 2
    out = {k: float(v) for k, v in out.items()}
    out.update(voigt_reuss_moduli(C))
    return out


def universal_anisotropy_index(C):
    """Universal anisotropy index of Ranganathan and Ostoja-Starzewski (2008).

    3D: ``A^U = 5 G_V/G_R + K_V/K_R - 6``. 2D: ``A^U = 2 G_V/G_R + K_V/K_R - 3``
    (same construction, ``C_V :: S_R`` minus the dimension of the space of
    symmetric strains, with the 2D averages of :func:`voigt_reuss_moduli`).
    Zero exactly for isotropic ``C``, positive otherwise.

    Returns
    -------
    float
    """
    m = voigt_reuss_moduli(C)
    shear_dims, total = (5, 6) if np.shape(C)[0] == 6 else (2, 3)
    return float(shear_dims * m["G_voigt"] / m["G_reuss"] + m["K_voigt"] / m["K_reuss"] - total)


# ------------------------------------------------------------------ symmetry

def _shear_index(i, j):
    return 6 - i - j  # {1,2} -> 3 (yz), {0,2} -> 4 (xz), {0,1} -> 5 (xy)


def _four_fold_about(c, k, close):
    p, q = (a for a in range(3) if a != k)
    return (close(c[p, p], c[q, q]) and close(c[k, p], c[k, q])
            and close(c[_shear_index(k, p), _shear_index(k, p)], c[_shear_index(k, q), _shear_index(k, q)]))


def symmetry_class(C, tol=1e-6):
    """Elastic symmetry of ``C`` with respect to the cell axes.

    Entries are compared with an absolute tolerance ``tol * max|C|``.

    3D: ``"orthotropic"`` if normal/shear couplings and shear/shear
    off-diagonals vanish; ``"tetragonal"`` if moreover some axis ``k`` is a
    4-fold axis (the two other axes are equivalent: ``C_pp = C_qq``,
    ``C_kp = C_kq`` and equal transverse shears; transversely isotropic
    ``C`` falls here); ``"cubic"`` if all three are; ``"isotropic"`` if
    moreover ``C44 = (C11 - C12)/2``. Anything else, including a cubic
    material in rotated axes, is ``"anisotropic"``.

    2D: ``"orthotropic"`` (no xx-xy or yy-xy coupling), ``"tetragonal"``
    (square symmetry: also ``C11 = C22``), ``"isotropic"`` (also
    ``C33 = (C11 - C12)/2``), else ``"anisotropic"``.

    Parameters
    ----------
    C : (6, 6) or (3, 3) array_like
    tol : float >= 0

    Returns
    -------
    str
    """
    c = _check_matrix(C)
    tol = _scalar(tol, "tol")
    if tol < 0:
        raise ValueError(f"tol must be >= 0; got {tol!r}")
    eps = tol * np.abs(c).max()

    def close(x, y):
        return abs(x - y) <= eps

    if c.shape[0] == 3:
        if not (close(c[0, 2], 0) and close(c[1, 2], 0)):
            return "anisotropic"
        if not close(c[0, 0], c[1, 1]):
            return "orthotropic"
        return "isotropic" if close(c[2, 2], (c[0, 0] - c[0, 1]) / 2) else "tetragonal"
    if np.abs(c[:3, 3:]).max() > eps or max(abs(c[3, 4]), abs(c[3, 5]), abs(c[4, 5])) > eps:
        return "anisotropic"
    axes = [k for k in range(3) if _four_fold_about(c, k, close)]
    if not axes:
        return "orthotropic"
    if len(axes) < 3:
        return "tetragonal"
    return "isotropic" if close(c[3, 3], (c[0, 0] - c[0, 1]) / 2) else "cubic"


def zener_ratio(C):
    """Zener ratio ``2 C44 / (C11 - C12)`` (2D: ``2 C33 / (C11 - C12)``).

    Meaningful for cubic (2D: square) symmetry only; computed regardless,
    callers decide. ``nan`` when ``C11 == C12``.
    """
    c = _check_matrix(C)
    shear = c[3, 3] if c.shape[0] == 6 else c[2, 2]
    den = c[0, 0] - c[0, 1]
    return float(2 * shear / den) if den != 0 else math.nan


# -------------------------------------------------------------------- bounds

def _bulk_shear(E, nu, dim):
    if dim == 3:
        return E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    return E / (2 * (1 - nu)), E / (2 * (1 + nu))  # plane stress, 2D area bulk modulus


def _young_poisson(K, G, dim):
    if K == 0 and G == 0:
        return 0.0, math.nan
    if dim == 3:
        return 9 * K * G / (3 * K + G), (3 * K - 2 * G) / (2 * (3 * K + G))
    return 4 * K * G / (K + G), (K - G) / (K + G)


def _hs(K, G, f, K0, G0, dim):
    """Walpole's form of the HS bound with comparison moduli (K0, G0)."""
    a = 4 * G0 / 3 if dim == 3 else G0
    if dim == 3:
        z = G0 * (9 * K0 + 8 * G0) / (6 * (K0 + 2 * G0)) if K0 + 2 * G0 > 0 else 0.0
    else:
        z = G0 * K0 / (K0 + 2 * G0) if K0 + 2 * G0 > 0 else 0.0
    live = [i for i in range(len(f)) if f[i] > 0]
    if len(live) == 1:  # exact, instead of a rounded (x - a) + a
        return K[live[0]], G[live[0]]
    # A phase with K + a == 0 (void against a void reference) makes the sum
    # infinite and the bound zero.
    sk = sum(f[i] / (K[i] + a) if K[i] + a > 0 else math.inf for i in live)
    sg = sum(f[i] / (G[i] + z) if G[i] + z > 0 else math.inf for i in live)
    return 1 / sk - a, 1 / sg - z


def hashin_shtrikman_bounds(E, nu, volume_fraction, *, dim=3, void_E=0.0, void_nu=0.0):
    """Hashin-Shtrikman bounds for an isotropic solid / void composite.

    Parameters
    ----------
    E, nu : float
        Solid Young's modulus (> 0) and Poisson's ratio; in 2D the solid is
        taken in plane stress.
    volume_fraction : float in [0, 1]
        Solid fraction ``f``.
    dim : {2, 3}
    void_E, void_nu : float
        The void phase; 0 (default) is true void. A soft "ersatz" void
        (``0 < void_E <= E``) must be no stiffer than the solid in bulk and
        shear (well-ordered phases).

    Returns
    -------
    dict of float
        ``K_upper, G_upper, E_upper, nu_upper, K_lower, G_lower, E_lower,
        nu_lower``. In 2D, ``K`` is the area bulk modulus
        (``E / (2 (1 - nu))`` for the solid). With true void the upper bulk
        bound is ``4 G K f / (3 K (1 - f) + 4 G)`` (3D) and the lower bounds
        are zero (``nu_lower`` is then nan). ``E`` and ``nu`` follow from
        ``K`` and ``G``; ``E_upper`` bounds ``E`` because ``E(K, G)`` grows
        with both.
    """
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3; got {dim!r}")
    nu_max = 0.5 if dim == 3 else 1.0
    E, nu = _check_young_poisson(E, nu, nu_max, f"a {dim}D solid")
    f = _scalar(volume_fraction, "volume_fraction")
    if not 0 <= f <= 1:
        raise ValueError(f"volume_fraction must lie in [0, 1]; got {volume_fraction!r}")
    k1, g1 = _bulk_shear(E, nu, dim)
    k2, g2 = _void_moduli(void_E, void_nu, dim, k1, g1)
    K, G, fr = (k1, k2), (g1, g2), (f, 1 - f)
    ku, gu = _hs(K, G, fr, k1, g1, dim)
    kl, gl = _hs(K, G, fr, k2, g2, dim)
    eu, nuu = _young_poisson(ku, gu, dim)
    el, nul = _young_poisson(kl, gl, dim)
    return {"K_upper": ku, "G_upper": gu, "E_upper": eu, "nu_upper": nuu,
            "K_lower": kl, "G_lower": gl, "E_lower": el, "nu_lower": nul}


def _void_moduli(void_E, void_nu, dim, k1, g1):
    ve = _scalar(void_E, "void_E")
    if ve == 0:
        return 0.0, 0.0
    nu_max = 0.5 if dim == 3 else 1.0
    ve, vn = _check_young_poisson(ve, void_nu, nu_max, "the void phase")
    k2, g2 = _bulk_shear(ve, vn, dim)
    if k2 > k1 or g2 > g1:
        raise ValueError(f"void_E={ve!r}, void_nu={vn!r} give a void stiffer than the solid "
                         f"(K {k2:.3g} vs {k1:.3g}, G {g2:.3g} vs {g1:.3g}); the bounds need the "
                         "solid stiffer in both")
    return k2, g2


@dataclass(frozen=True)
class BoundsCheck:
    """Result of :func:`inside_hashin_shtrikman`; truthy when inside.

    Attributes
    ----------
    inside : bool
    bulk_reuss : float
        ``K_R`` of the tested ``C`` (its response to hydrostatic stress).
    bulk_upper : float
        Hashin-Shtrikman upper bulk modulus.
    voigt_excess : float
        Largest eigenvalue of ``C_m - C_voigt_m`` (Mandel) over the largest
        eigenvalue of ``C_voigt_m``; <= 0 when the Voigt bound holds.
    reasons : tuple of str
        One sentence per violated bound.
    """

    inside: bool
    bulk_reuss: float
    bulk_upper: float
    voigt_excess: float
    reasons: tuple

    def __bool__(self):
        return self.inside


def inside_hashin_shtrikman(C, E, nu, volume_fraction, *, void_E=0.0, void_nu=0.0, rtol=1e-6):
    """Check the effective ``C`` of a solid/void cell against rigorous bounds.

    What is rigorous for an *anisotropic* effective stiffness of a two-phase
    composite with isotropic, well-ordered phases at solid fraction ``f``:

    1. Voigt (uniform strain is an admissible trial field):
       ``e:C:e <= e:(f C_solid + (1-f) C_void):e`` for every strain ``e``,
       i.e. the Mandel difference is negative semidefinite.
    2. Hashin-Shtrikman on the bulk modulus in its anisotropic form (Milton
       and Kohn 1988): the response to hydrostatic stress,
       ``K_R = 1 / sum_{i,j<=d} S_ij``, is at most the HS upper bulk modulus.
       Neither ``K_V = (C11+C22+C33+2(C12+C13+C23))/9`` nor the shear moduli
       are bounded by the isotropic HS formulas in general, so they are not
       tested.
    3. With a soft void (``void_E > 0``) also the Reuss bound
       ``S <= f S_solid + (1-f) S_void`` and the HS lower bound
       ``K_V >= K_lower`` (hydrostatic strain). With true void the lower
       bounds are zero and reduce to ``C`` positive definite.

    A displacement finite-element ``C`` over-estimates the exact one, so a
    near-optimal cell on a coarse grid may exceed bound 2 by its
    discretization error; loosen ``rtol`` for such sanity checks. ``f`` must
    be the solid fraction of the grid the solver saw.

    Parameters
    ----------
    C : (6, 6) or (3, 3) array_like
        Positive definite effective stiffness (3x3: plane stress).
    E, nu : float
        Solid properties.
    volume_fraction : float in [0, 1]
    void_E, void_nu : float
        As in :func:`hashin_shtrikman_bounds`.
    rtol : float >= 0
        Relative slack on every inequality.

    Returns
    -------
    BoundsCheck
    """
    c = _check_matrix(C)
    dim = 3 if c.shape[0] == 6 else 2
    rtol = _scalar(rtol, "rtol")
    hs = hashin_shtrikman_bounds(E, nu, volume_fraction, dim=dim, void_E=void_E, void_nu=void_nu)
    f = float(volume_fraction)
    iso = isotropic_stiffness if dim == 3 else isotropic_plane_stress
    solid = iso(E, nu)
    void = iso(void_E, void_nu) if float(void_E) > 0 else np.zeros_like(solid)
    voigt = voigt_to_mandel(f * solid + (1 - f) * void) if f > 0 or float(void_E) > 0 else None
    cm = voigt_to_mandel(c)
    reasons = []
    if voigt is None:
        excess = 1.0
        reasons.append("C is not zero although the cell holds no material")
    else:
        excess = float(np.linalg.eigvalsh(cm - voigt)[-1] / np.linalg.eigvalsh(voigt)[-1])
        if excess > rtol:
            reasons.append(f"C exceeds the Voigt bound f*C_solid in some strain mode "
                           f"(by {excess:.3g} of its largest modulus)")
    moduli = voigt_reuss_moduli(c)
    kr = moduli["K_reuss"]
    if kr > hs["K_upper"] * (1 + rtol):
        reasons.append(f"bulk modulus under hydrostatic stress K_R={kr:.6g} exceeds the "
                       f"Hashin-Shtrikman upper bound {hs['K_upper']:.6g} at f={f:g}")
    if float(void_E) > 0:
        reuss = voigt_to_mandel(f * compliance(solid) + (1 - f) * compliance(void), kind="compliance")
        sm = voigt_to_mandel(compliance(c), kind="compliance")
        if np.linalg.eigvalsh(sm - reuss)[-1] > rtol * np.linalg.eigvalsh(reuss)[-1]:
            reasons.append("C is below the Reuss bound in some stress mode")
        if moduli["K_voigt"] < hs["K_lower"] * (1 - rtol):
            reasons.append(f"bulk modulus under hydrostatic strain K_V={moduli['K_voigt']:.6g} is "
                           f"below the Hashin-Shtrikman lower bound {hs['K_lower']:.6g}")
    return BoundsCheck(not reasons, kr, hs["K_upper"], excess, tuple(reasons))


# ------------------------------------------------------ directional modulus

def _compliance_from(A, kind):
    return _check_matrix(A, "S") if _check_kind(kind) == "compliance" else compliance(A)


def directional_young(C, directions, *, kind="stiffness"):
    """Young's modulus along each direction, ``1 / (d d : S : d d)``.

    Parameters
    ----------
    C : (6, 6) array_like
        Voigt stiffness, or compliance when ``kind="compliance"``.
    directions : (n, 3) or (3,) array_like
        Non-zero vectors; normalised here.
    kind : {"stiffness", "compliance"}
        Whether the first argument is ``C`` or already ``S``.

    Returns
    -------
    E : (n,) float64, or float for a single direction
    """
    s = _compliance_from(C, kind)
    if s.shape != (6, 6):
        raise ValueError(f"directional_young needs a 6x6 (3D) matrix; got {s.shape}; "
                         "use directional_young_polar in 2D")
    d = np.asarray(directions, dtype=np.float64)
    single = d.ndim == 1
    d = np.atleast_2d(d)
    if d.ndim != 2 or d.shape[1] != 3 or not np.all(np.isfinite(d)):
        raise ValueError(f"directions must be a finite (n, 3) array; got shape {np.shape(directions)}")
    norm = np.linalg.norm(d, axis=1)
    if np.any(norm == 0):
        raise ValueError(f"directions must be non-zero; row {int(np.argmin(norm))} is zero")
    d = d / norm[:, None]
    # With engineering shear in S, d d : S : d d = a . S . a for
    # a = (d1^2, d2^2, d3^2, d2 d3, d1 d3, d1 d2): the factor 2 of the
    # shear strains cancels the double counting of the off-diagonal pairs.
    a = np.column_stack([d[:, 0] ** 2, d[:, 1] ** 2, d[:, 2] ** 2,
                         d[:, 1] * d[:, 2], d[:, 0] * d[:, 2], d[:, 0] * d[:, 1]])
    e = 1.0 / np.einsum("ni,ij,nj->n", a, s, a)
    return float(e[0]) if single else e


def directional_young_polar(C, angles, *, kind="stiffness"):
    """In-plane Young's modulus along ``(cos t, sin t)`` for a 2D material.

    Parameters
    ----------
    C : (3, 3) array_like
        Plane-stress Voigt stiffness, or compliance when ``kind="compliance"``.
    angles : (n,) array_like or float
        Radians from the x axis towards y.

    Returns
    -------
    E : (n,) float64, or float for a scalar angle
    """
    s = _compliance_from(C, kind)
    if s.shape != (3, 3):
        raise ValueError(f"directional_young_polar needs a 3x3 (2D) matrix; got {s.shape}")
    t = np.asarray(angles, dtype=np.float64)
    if not np.all(np.isfinite(t)):
        raise ValueError("angles must be finite")
    c, sn = np.cos(t.ravel()), np.sin(t.ravel())
    a = np.column_stack([c * c, sn * sn, c * sn])
    e = 1.0 / np.einsum("ni,ij,nj->n", a, s, a)
    return float(e[0]) if t.ndim == 0 else e.reshape(t.shape)


def is_singular(C, rtol: float = 1e-9) -> bool:
    """True when ``C`` is numerically not positive definite (a mechanism:
    the cell carries no load along some strain), smallest over largest
    eigenvalue of its symmetric part at most ``rtol``."""
    c = np.asarray(C, dtype=np.float64)
    eig = np.linalg.eigvalsh(0.5 * (c + c.T))
    return bool(eig[0] <= rtol * max(eig[-1], 1e-300))
