"""Method of moving asymptotes (Svanberg 1987) for one inequality constraint.

Each step replaces the objective ``f`` and the constraint ``g <= 0`` by
convex separable approximations around the current point ``x``::

    f~(y) = r + sum_j p_j / (U_j - y_j) + q_j / (y_j - L_j)
    p_j = (U_j - x_j)^2 (max(df_j, 0) + eps),  q_j = (x_j - L_j)^2 (max(-df_j, 0) + eps)

which match value and gradient at ``x`` (``eps`` adds a little curvature so
every variable has a unique minimiser). With a single constraint the
subproblem is solved through its dual: for a multiplier ``lam`` each
variable minimises ``P/(U - y) + Q/(y - L)`` (``P = p0 + lam p1``,
``Q = q0 + lam q1``), whose minimiser is
``y = (sqrt(P) L + sqrt(Q) U) / (sqrt(P) + sqrt(Q))`` clipped to the move
bounds, and the approximate constraint is monotone in ``lam``, so ``lam`` is
found by bisection (``lam = 0`` if the unconstrained step is feasible).

Asymptotes follow Svanberg's heuristic: at first ``x -+ 0.5 (xmax - xmin)``,
then pulled in by 0.7 where a variable oscillates and pushed out by 1.2
where it keeps moving the same way.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MMA"]


class MMA:
    """State of an MMA run (asymptotes and the two previous iterates).

    Parameters
    ----------
    lower, upper : (n,) float64 bounds of the variables.
    move : float or (n,), largest step as a fraction of ``upper - lower``.
    min_spacing : float or (n,), closest approach of an asymptote to its
        variable, as a fraction of the range (caps how far an oscillating
        variable keeps swinging).
    """

    def __init__(self, lower, upper, *, move=0.2, s_init=0.5, shrink=0.7, grow=1.2, min_spacing=0.01):
        self.xmin = np.asarray(lower, dtype=np.float64)
        self.xmax = np.asarray(upper, dtype=np.float64)
        self.range = self.xmax - self.xmin
        if np.any(self.range <= 0):
            raise ValueError("MMA: every upper bound must exceed its lower bound")
        self.move, self.s_init, self.shrink, self.grow = move, s_init, shrink, grow
        self.min_spacing = min_spacing
        self.history = []
        self.low = self.upp = None

    def _asymptotes(self, x):
        if len(self.history) < 2:
            self.low = x - self.s_init * self.range
            self.upp = x + self.s_init * self.range
            return
        x1, x2 = self.history[-1], self.history[-2]
        trend = (x - x1) * (x1 - x2)
        factor = np.where(trend < 0, self.shrink, np.where(trend > 0, self.grow, 1.0))
        low = x - factor * (x1 - self.low)
        upp = x + factor * (self.upp - x1)
        near = self.min_spacing * self.range
        self.low = np.clip(low, x - 10.0 * self.range, x - near)
        self.upp = np.clip(upp, x + near, x + 10.0 * self.range)

    @staticmethod
    def _terms(x, grad, low, upp):
        eps = 1e-6 * (np.abs(grad).mean() + 1e-300)
        p = (upp - x) ** 2 * (np.maximum(grad, 0.0) + eps)
        q = (x - low) ** 2 * (np.maximum(-grad, 0.0) + eps)
        return p, q

    def step(self, x, df, g, dg):
        """The next iterate.

        Parameters
        ----------
        x : (n,) float64, current point (within the bounds).
        df : (n,) float64, objective gradient at ``x``.
        g : float, constraint value at ``x`` (feasible when ``<= 0``).
        dg : (n,) float64, constraint gradient at ``x``.

        Returns
        -------
        (n,) float64
        """
        x = np.asarray(x, dtype=np.float64)
        self._asymptotes(x)
        low, upp = self.low, self.upp
        alpha = np.maximum.reduce([self.xmin, low + 0.1 * (x - low), x - self.move * self.range])
        beta = np.minimum.reduce([self.xmax, upp - 0.1 * (upp - x), x + self.move * self.range])
        p0, q0 = self._terms(x, df, low, upp)
        p1, q1 = self._terms(x, dg, low, upp)
        r1 = g - np.sum(p1 / (upp - x) + q1 / (x - low))

        def primal(lam):
            sp = np.sqrt(p0 + lam * p1)
            sq = np.sqrt(q0 + lam * q1)
            return np.clip((sp * low + sq * upp) / (sp + sq), alpha, beta)

        def constraint(y):
            return r1 + np.sum(p1 / (upp - y) + q1 / (y - low))

        y = primal(0.0)
        if constraint(y) > 0.0:
            lo, hi = 0.0, 1.0
            while constraint(primal(hi)) > 0.0 and hi < 1e40:
                lo, hi = hi, hi * 10.0
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if constraint(primal(mid)) > 0.0:
                    lo = mid
                else:
                    hi = mid
                if hi - lo <= 1e-12 * hi:
                    break
            y = primal(hi)
        self.history = (self.history + [x])[-2:]
        return y
