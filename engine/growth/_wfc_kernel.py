"""Compiled core of the growth: Observe, Propagate, Ban on flat bitsets.

State lives in flat arrays indexed by cell ``c`` (row-major over the grid):

* ``wave[c, w]`` uint64 -- bit ``t & 63`` of word ``t >> 6`` set while tile
  ``t`` is admissible at ``c`` (multi-word, so any number of tiles).
* ``status[c]`` int8 -- FREE, ASSIGNED or DEFECT; ``tiles[c]`` int32.
* ``entropy[c]`` float64 cache, recomputed where ``dirty[c]``; cells
  turning dirty are listed in ``dlist`` so only they are recomputed.
* ``nbr[c, d]`` int32 -- neighbour across face ``d`` or -1 (open boundary).
* ``masks[d, a, w]`` uint64 -- tiles allowed across face ``d`` of tile ``a``.
* ``counters`` int64 -- [observations, events, free cells, dirty-list
  length, heap size].
* ``hS, hC, hV`` -- a min-heap of (entropy, cell, version) with lazy
  deletion, so finding the minimal-entropy cells does not scan the grid.

Random numbers are drawn beforehand by the caller, two per observation
(cell among ties, tile), so the pure-Python reference consumes exactly the
same stream and must produce the same tiling.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

FREE, ASSIGNED, DEFECT = 0, 1, 2
TIE_EPS = 1e-9          # entropies closer than this count as equal (ties)
_ONE = np.uint64(1)


@njit(cache=True, nogil=True)
def _has(wave, c, t):
    return ((wave[c, t >> 6] >> np.uint64(t & 63)) & _ONE) != 0


@njit(cache=True, nogil=True)
def _weight(c, t, weights, block_of, remaining, initial, limited):
    """Current hint of tile ``t`` at cell ``c`` (field row, availability factor)."""
    w = weights[c if weights.shape[0] > 1 else 0, t]
    if limited:
        b = block_of[t]
        if math.isfinite(initial[b]):
            w = w * (remaining[b] / initial[b])
    return w


@njit(cache=True, nogil=True)
def _entropy(c, wave, weights, block_of, remaining, initial, limited):
    """Shannon entropy (eq. S1) of the normalised hints of admissible tiles."""
    n_tiles = weights.shape[1]
    total = 0.0
    for t in range(n_tiles):
        if _has(wave, c, t):
            total += _weight(c, t, weights, block_of, remaining, initial, limited)
    s = 0.0
    for t in range(n_tiles):
        if _has(wave, c, t):
            p = _weight(c, t, weights, block_of, remaining, initial, limited) / total
            s -= p * math.log(p)
    return s


@njit(cache=True, nogil=True)
def _mark_defect(c, status, tiles, events, counters):
    status[c] = DEFECT
    tiles[c] = -1
    k = counters[1]
    events[k, 0] = c
    events[k, 1] = -1
    counters[1] = k + 1
    counters[2] -= 1


@njit(cache=True, nogil=True)
def _mark_dirty(c, dirty, dlist, counters):
    if not dirty[c]:
        dirty[c] = True
        dlist[counters[3]] = c
        counters[3] += 1


@njit(cache=True, nogil=True)
def _propagate(sp, stack, on_stack, wave, status, tiles, dirty, dlist, nbr, masks, events,
               counters):
    """Remove unsupported tiles until nothing changes (AC-3 with a LIFO stack).

    A cell left with no tile becomes a defect and is not pushed, so it
    constrains nobody; only FREE cells are revised.
    """
    n_dirs = nbr.shape[1]
    n_tiles = masks.shape[1]
    n_words = wave.shape[1]
    sup = np.empty(n_words, dtype=np.uint64)
    while sp > 0:
        sp -= 1
        c = stack[sp]
        on_stack[c] = False
        if status[c] == DEFECT:
            continue
        for d in range(n_dirs):
            nb = nbr[c, d]
            if nb < 0 or status[nb] != FREE:
                continue
            sup[:] = 0
            for t in range(n_tiles):
                if _has(wave, c, t):
                    for w in range(n_words):
                        sup[w] |= masks[d, t, w]
            sp = _narrow(nb, sup, False, sp, stack, on_stack, wave, status, tiles, dirty, dlist,
                         events, counters)
    return sp


@njit(cache=True, nogil=True)
def _narrow(c, keep, invert, sp, stack, on_stack, wave, status, tiles, dirty, dlist, events,
            counters):
    """Intersect cell ``c``'s wave with ``keep`` (or its complement when
    ``invert``); a cell left empty is a defect, a changed one is pushed for
    propagation.  Returns the new stack size."""
    changed = False
    empty = True
    for w in range(wave.shape[1]):
        new = wave[c, w] & (~keep[w] if invert else keep[w])
        if new != wave[c, w]:
            changed = True
            wave[c, w] = new
        if new != 0:
            empty = False
    if changed:
        if empty:
            _mark_defect(c, status, tiles, events, counters)
        else:
            _mark_dirty(c, dirty, dlist, counters)
            if not on_stack[c]:
                on_stack[c] = True
                stack[sp] = c
                sp += 1
    return sp


@njit(cache=True, nogil=True)
def _ban_block(b, block_masks, stack, on_stack, wave, status, tiles, dirty, dlist, nbr, masks,
               events, counters):
    """Availability of block ``b`` ran out: remove its tiles everywhere, propagate."""
    sp = 0
    for c in range(wave.shape[0]):
        if status[c] != FREE:
            continue
        sp = _narrow(c, block_masks[b], True, sp, stack, on_stack, wave, status, tiles, dirty,
                     dlist, events, counters)
    _propagate(sp, stack, on_stack, wave, status, tiles, dirty, dlist, nbr, masks, events,
               counters)


@njit(cache=True, nogil=True)
def init_state(wave, status, tiles, dirty, dlist, nbr, masks, stack, on_stack, events, counters):
    """Cells with no admissible tile become defects; fixed cells propagate."""
    n = wave.shape[0]
    for c in range(n):
        if status[c] == FREE:
            empty = True
            for w in range(wave.shape[1]):
                if wave[c, w] != 0:
                    empty = False
            if empty:
                _mark_defect(c, status, tiles, events, counters)
    sp = 0
    for c in range(n):
        if status[c] == ASSIGNED:
            on_stack[c] = True
            stack[sp] = c
            sp += 1
    _propagate(sp, stack, on_stack, wave, status, tiles, dirty, dlist, nbr, masks, events,
               counters)


@njit(cache=True, nogil=True)
def _pick_cell(u, status, entropy, dirty, wave, weights, block_of, remaining, initial, limited):
    """Observe: a free cell of minimal entropy, uniformly among ties."""
    n = status.shape[0]
    smin = np.inf
    for c in range(n):
        if status[c] == FREE:
            if dirty[c]:
                entropy[c] = _entropy(c, wave, weights, block_of, remaining, initial, limited)
                dirty[c] = False
            if entropy[c] < smin:
                smin = entropy[c]
    lim = smin + TIE_EPS
    k = 0
    for c in range(n):
        if status[c] == FREE and entropy[c] <= lim:
            k += 1
    pick = min(int(u * k), k - 1)
    for c in range(n):
        if status[c] == FREE and entropy[c] <= lim:
            if pick == 0:
                return c
            pick -= 1
    return -1


@njit(cache=True, nogil=True)
def _pick_tile(c, u, wave, weights, block_of, remaining, initial, limited):
    """Sample an admissible tile with probability proportional to its hint."""
    n_tiles = weights.shape[1]
    total = 0.0
    for t in range(n_tiles):
        if _has(wave, c, t):
            total += _weight(c, t, weights, block_of, remaining, initial, limited)
    r = u * total
    acc = 0.0
    chosen = -1
    for t in range(n_tiles):
        if _has(wave, c, t):
            acc += _weight(c, t, weights, block_of, remaining, initial, limited)
            chosen = t
            if r < acc:
                break
    return chosen


# ------------------------------------------------------------------ heap
# Lazy-deletion binary min-heap of (entropy, cell, version), ordered by
# entropy then cell. An entry is valid while its cell is FREE and its
# version equals ``ver[cell]``; each free cell has exactly one valid entry.
# (Comparisons are written out: small helpers here measured 5x slower.)

@njit(cache=True, nogil=True)
def _heap_push(hS, hC, hV, size, s, c, v):
    i = size
    hS[i] = s
    hC[i] = c
    hV[i] = v
    while i > 0:
        p = (i - 1) >> 1
        if not (hS[i] < hS[p] or (hS[i] == hS[p] and hC[i] < hC[p])):
            break
        hS[i], hS[p] = hS[p], hS[i]
        hC[i], hC[p] = hC[p], hC[i]
        hV[i], hV[p] = hV[p], hV[i]
        i = p
    return size + 1


@njit(cache=True, nogil=True)
def _heap_pop(hS, hC, hV, size):
    """Drop the top entry; returns the new size."""
    size -= 1
    hS[0] = hS[size]
    hC[0] = hC[size]
    hV[0] = hV[size]
    i = 0
    while True:
        m = i
        k = 2 * i + 1
        if k < size and (hS[k] < hS[m] or (hS[k] == hS[m] and hC[k] < hC[m])):
            m = k
        k += 1
        if k < size and (hS[k] < hS[m] or (hS[k] == hS[m] and hC[k] < hC[m])):
            m = k
        if m == i:
            return size
        hS[i], hS[m] = hS[m], hS[i]
        hC[i], hC[m] = hC[m], hC[i]
        hV[i], hV[m] = hV[m], hV[i]
        i = m


@njit(cache=True, nogil=True)
def _pick_cell_heap(u, status, entropy, dirty, dlist, ver, hS, hC, hV, tmp, walk, counters,
                    wave, weights, block_of, remaining, initial, limited):
    """Same choice as ``_pick_cell`` without scanning the grid."""
    size = counters[4]
    for i in range(counters[3]):
        c = dlist[i]
        if not dirty[c]:
            continue
        dirty[c] = False
        if status[c] != FREE:
            continue
        ver[c] += 1
        entropy[c] = _entropy(c, wave, weights, block_of, remaining, initial, limited)
        if size == hS.shape[0]:         # full of stale entries: rebuild from valid ones
            size = 0
            for cc in range(status.shape[0]):
                if status[cc] == FREE and not dirty[cc]:
                    size = _heap_push(hS, hC, hV, size, entropy[cc], cc, ver[cc])
        else:
            size = _heap_push(hS, hC, hV, size, entropy[c], c, ver[c])
    counters[3] = 0
    while status[hC[0]] != FREE or hV[0] != ver[hC[0]]:
        size = _heap_pop(hS, hC, hV, size)
    counters[4] = size
    # all valid entries within TIE_EPS of the top: walk the tree, prune above
    lim = hS[0] + TIE_EPS
    k = 0
    stale = 0
    top = 0
    walk[0] = 0
    while top >= 0:
        i = walk[top]
        top -= 1
        c = hC[i]
        if status[c] == FREE and hV[i] == ver[c]:
            tmp[k] = c
            k += 1
        else:
            stale += 1
        j = 2 * i + 1
        if j < size and hS[j] <= lim:
            top += 1
            walk[top] = j
        j += 1
        if j < size and hS[j] <= lim:
            top += 1
            walk[top] = j
    if stale > 2 * k + 16:
        # stale entries pile up at a common entropy level: pop the whole
        # level once and push the valid entries back (each stale entry is
        # popped once, so walks stay proportional to the ties)
        while size > 0 and hS[0] <= lim:
            size = _heap_pop(hS, hC, hV, size)
        for i in range(k):
            c = tmp[i]
            size = _heap_push(hS, hC, hV, size, entropy[c], c, ver[c])
        counters[4] = size
    if k > 16:
        tmp[:k] = np.sort(tmp[:k])
    else:
        for i in range(1, k):
            x = tmp[i]
            j = i - 1
            while j >= 0 and tmp[j] > x:
                tmp[j + 1] = tmp[j]
                j -= 1
            tmp[j + 1] = x
    return tmp[min(int(u * k), k - 1)]


@njit(cache=True, nogil=True)
def run_steps(budget, wave, status, tiles, entropy, dirty, dlist, nbr, masks, weights,
              block_of, block_masks, remaining, initial, limited, randoms, stack, on_stack,
              events, counters, use_heap, ver, hS, hC, hV, tmp, walk):
    """Up to ``budget`` observations (each followed by propagation).

    ``counters`` = [observations, events, free cells, dirty-list length,
    heap size]. With ``use_heap`` (large grids, unlimited availability) the
    minimal-entropy cells come from the heap, otherwise from a scan of all
    cells (cheaper on small grids, and needed when every hint changes at
    every step). Both choose the same cell. Returns the number of observations made; stops early when no cell
    is free. Resumable: all state is in the arrays.
    """
    done = 0
    while done < budget and counters[2] > 0:
        step = counters[0]
        if use_heap:
            c = _pick_cell_heap(randoms[2 * step], status, entropy, dirty, dlist, ver, hS, hC,
                                hV, tmp, walk, counters, wave, weights, block_of, remaining,
                                initial, limited)
        else:
            counters[3] = 0
            c = _pick_cell(randoms[2 * step], status, entropy, dirty, wave, weights, block_of,
                           remaining, initial, limited)
        t = _pick_tile(c, randoms[2 * step + 1], wave, weights, block_of, remaining,
                       initial, limited)
        for w in range(wave.shape[1]):
            wave[c, w] = 0
        wave[c, t >> 6] = _ONE << np.uint64(t & 63)
        status[c] = ASSIGNED
        tiles[c] = t
        k = counters[1]
        events[k, 0] = c
        events[k, 1] = t
        counters[1] = k + 1
        counters[2] -= 1
        counters[0] = step + 1
        done += 1
        on_stack[c] = True
        stack[0] = c
        _propagate(1, stack, on_stack, wave, status, tiles, dirty, dlist, nbr, masks, events,
                   counters)
        if limited:
            b = block_of[t]
            if math.isfinite(initial[b]):
                remaining[b] -= 1.0
                if remaining[b] <= 0.0:
                    _ban_block(b, block_masks, stack, on_stack, wave, status, tiles, dirty,
                               dlist, nbr, masks, events, counters)
            for cc in range(status.shape[0]):
                dirty[cc] = True          # every hint changed: all entropies are stale
    return done
