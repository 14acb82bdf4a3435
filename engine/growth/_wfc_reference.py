"""Plain-Python growth: the same algorithm as ``_wfc_kernel`` with sets.

Admissible sets are frozensets of tile indices, compatibility is a list of
sets, entropies are recomputed for every free cell at every step (memoised
on the admissible set when hints do not change). It walks cells, tiles and
faces in the same order and reads the same pre-drawn random numbers as the
compiled kernel, so for the same seed both give the same tiling; it exists
to be read and to test the fast path against.
"""

from __future__ import annotations

import math

FREE, ASSIGNED, DEFECT = 0, 1, 2
TIE_EPS = 1e-9


class ReferenceGrowth:
    """Growth state: ``domain[c]`` (frozenset), ``status[c]``, ``tiles[c]``.

    Parameters
    ----------
    domains : list of frozenset, initial admissible tiles per cell
    status, tiles : list of int, per cell (fixed cells already ASSIGNED)
    nbr : list of list of int, neighbour per face or -1
    allowed : (n_dirs, n_tiles, n_tiles) bool array
    weights : list of list of float, one row or one per cell
    block_of : list of int, block of each tile
    initial : list of float or None, availability per block (inf = unlimited)
    randoms : sequence of float, two per observation
    """

    def __init__(self, domains, status, tiles, nbr, allowed, weights, block_of, initial,
                 randoms):
        self.domain = list(domains)
        self.status = list(status)
        self.tiles = list(tiles)
        self.nbr = nbr
        n_dirs, n_tiles = allowed.shape[0], allowed.shape[1]
        self.support = [[frozenset(b for b in range(n_tiles) if allowed[d, a, b])
                         for a in range(n_tiles)] for d in range(n_dirs)]
        self.weights = weights
        self.block_of = block_of
        self.limited = initial is not None
        self.initial = list(initial) if self.limited else []
        self.remaining = list(initial) if self.limited else []
        self.randoms = randoms
        self.events = []
        self.n_obs = 0
        self._memo = {}

    # ------------------------------------------------------------- hints
    def weight(self, c, t):
        w = self.weights[c if len(self.weights) > 1 else 0][t]
        if self.limited:
            b = self.block_of[t]
            if math.isfinite(self.initial[b]):
                w = w * (self.remaining[b] / self.initial[b])
        return w

    def entropy(self, c):
        """Eq. S1 over the admissible tiles, probabilities = normalised hints."""
        key = (c if len(self.weights) > 1 else 0, self.domain[c])
        if not self.limited and key in self._memo:
            return self._memo[key]
        ts = sorted(self.domain[c])
        total = 0.0
        for t in ts:
            total += self.weight(c, t)
        s = 0.0
        for t in ts:
            p = self.weight(c, t) / total
            s -= p * math.log(p)
        if not self.limited:
            self._memo[key] = s
        return s

    # ------------------------------------------------------------- bans
    def defect(self, c):
        self.status[c] = DEFECT
        self.tiles[c] = -1
        self.domain[c] = frozenset()
        self.events.append((c, -1))

    def propagate(self, stack):
        on_stack = set(stack)
        while stack:
            c = stack.pop()
            on_stack.discard(c)
            if self.status[c] == DEFECT:
                continue
            for d, nb in enumerate(self.nbr[c]):
                if nb < 0 or self.status[nb] != FREE:
                    continue
                sup = frozenset().union(*(self.support[d][a] for a in self.domain[c]))
                new = self.domain[nb] & sup
                if new != self.domain[nb]:
                    if not new:
                        self.defect(nb)
                    else:
                        self.domain[nb] = new
                        if nb not in on_stack:
                            on_stack.add(nb)
                            stack.append(nb)

    def ban_block(self, b):
        stack = []
        for c in range(len(self.domain)):
            if self.status[c] != FREE:
                continue
            new = frozenset(t for t in self.domain[c] if self.block_of[t] != b)
            if new != self.domain[c]:
                if not new:
                    self.defect(c)
                else:
                    self.domain[c] = new
                    if c not in stack:
                        stack.append(c)
        self.propagate(stack)

    def start(self):
        for c in range(len(self.domain)):
            if self.status[c] == FREE and not self.domain[c]:
                self.defect(c)
        self.propagate([c for c in range(len(self.domain)) if self.status[c] == ASSIGNED])

    # ------------------------------------------------------------- observe
    def step(self):
        free = [c for c in range(len(self.domain)) if self.status[c] == FREE]
        ent = {c: self.entropy(c) for c in free}
        smin = min(ent.values())
        ties = [c for c in free if ent[c] <= smin + TIE_EPS]
        u_cell, u_tile = self.randoms[2 * self.n_obs], self.randoms[2 * self.n_obs + 1]
        c = ties[min(int(u_cell * len(ties)), len(ties) - 1)]
        ts = sorted(self.domain[c])
        total = 0.0
        for t in ts:
            total += self.weight(c, t)
        r = u_tile * total
        acc = 0.0
        for t in ts:
            acc += self.weight(c, t)
            if r < acc:
                break
        self.domain[c] = frozenset([t])
        self.status[c] = ASSIGNED
        self.tiles[c] = t
        self.events.append((c, t))
        self.n_obs += 1
        self.propagate([c])
        if self.limited:
            b = self.block_of[t]
            if math.isfinite(self.initial[b]):
                self.remaining[b] -= 1.0
                if self.remaining[b] <= 0.0:
                    self.ban_block(b)

    def run(self, budget):
        done = 0
        while done < budget and FREE in self.status:
            self.step()
            done += 1
        return done
