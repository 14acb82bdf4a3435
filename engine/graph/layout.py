"""Layered ("Sugiyama") placement of a directed graph in readable columns.

A node's column is its longest-path depth from the sources, so every edge goes
left to right. Inside a column the rows are ordered to reduce edge crossings:
edges spanning several columns get virtual waypoints, then barycentre sweeps
(down and up) and adjacent swaps refine the order; the best order found is kept,
never one with more crossings than the input order. Pure and deterministic: the
same ids and edges in the same order give the same positions.

A long chain of columns is hard to read in a narrow editor: with
``max_columns`` the columns wrap into bands stacked top to bottom, read like
lines of text (the edges from a band's last columns run down to the next
band's first ones). `fit_columns` picks the band width at which a view of a
given size shows the whole graph largest.
"""

from __future__ import annotations

from itertools import combinations

__all__ = ["layered_positions", "layer_depths", "fit_columns"]

_SWEEPS = 12
_GEOMETRIC_CHECK_MAX_EDGES = 150  # above, the sweeps' own count decides (pairwise check is O(E^2))


def layered_positions(node_ids: list[str], edges: list[tuple[str, str]], *,
                      column_width: float = 240.0,
                      row_height: float = 110.0,
                      max_columns: int | None = None,
                      band_gap: float | None = None) -> dict[str, tuple[float, float]]:
    """``{node id: (x, y)}``: column ``depth * column_width``, row ``k * row_height``
    with each column centred on the tallest one. ``edges`` are ``(source, target)``;
    repeated edges and self-loops are ignored; in a cycle the edge closing it (in
    input order) is ignored for the depths. With ``max_columns`` (>= 1) column
    ``depth`` goes to band ``depth // max_columns`` at x ``(depth % max_columns) *
    column_width``; each band starts ``band_gap`` (default ``row_height``) below the
    one above it. Raises ValueError for a duplicate node id, an edge naming an
    unknown node, a non-positive spacing or ``max_columns`` < 1."""
    ids, pairs = _checked(node_ids, edges, column_width, row_height, max_columns, band_gap)
    depth = layer_depths(ids, pairs)
    forward = [(s, t) for s, t in pairs if depth[s] < depth[t]]
    layers = _initial_layers(ids, depth)
    sweeper = _Sweeper(layers, forward, depth)
    candidates = [layers, sweeper.best_layers()]
    if len(forward) <= _GEOMETRIC_CHECK_MAX_EDGES:
        scored = [(_straight_crossings(_place(c, column_width, row_height), forward), -k)
                  for k, c in enumerate(candidates)]
        chosen = candidates[-min(scored)[1]]
    else:
        chosen = candidates[1]
    return _place(chosen, column_width, row_height, max_columns, band_gap)


def fit_columns(node_ids: list[str], edges: list[tuple[str, str]], view: tuple[float, float], *,
                column_width: float = 240.0, row_height: float = 110.0,
                node_size: tuple[float, float] = (180.0, 80.0), band_gap: float | None = None) -> int:
    """The ``max_columns`` at which the whole layout, fitted into a ``view`` of
    (width, height) pixels and never shown larger than 1:1, is drawn largest (ties:
    the fewest bands, so a graph that fits at 1:1 stays one row).
    ``node_size`` is the (width, height) of the largest node."""
    ids, pairs = _checked(node_ids, edges, column_width, row_height, None, band_gap)
    depth = layer_depths(ids, pairs)
    counts = [0] * (max(depth.values(), default=-1) + 1)
    for d in depth.values():
        counts[d] += 1
    if not counts:
        return 1
    w, h = (float(v) for v in view)
    if not (w > 0 and h > 0):
        raise ValueError(f"view must be a positive (width, height), got {view!r}")
    gap = row_height if band_gap is None else band_gap
    best, best_scale = len(counts), -1.0
    for k in range(len(counts), 0, -1):
        bands = [counts[b:b + k] for b in range(0, len(counts), k)]
        width = (min(k, len(counts)) - 1) * column_width + node_size[0]
        height = sum((max(b) - 1) * row_height + node_size[1] for b in bands) + gap * (len(bands) - 1)
        scale = min(1.0, w / width, h / height)       # a view never zooms in past 1:1
        if scale > best_scale * (1.0 + 1e-9):
            best, best_scale = k, scale
    return best


def _checked(node_ids, edges, column_width, row_height, max_columns, band_gap):
    if not column_width > 0 or not row_height > 0:
        raise ValueError(f"column_width and row_height must be > 0 "
                         f"(got {column_width!r}, {row_height!r})")
    if max_columns is not None and (isinstance(max_columns, bool) or not isinstance(max_columns, int)
                                    or max_columns < 1):
        raise ValueError(f"max_columns must be an integer >= 1 or None (got {max_columns!r})")
    if band_gap is not None and not band_gap >= 0:
        raise ValueError(f"band_gap must be >= 0 (got {band_gap!r})")
    ids = list(node_ids)
    index = {nid: k for k, nid in enumerate(ids)}
    if len(index) != len(ids):
        dup = next(nid for k, nid in enumerate(ids) if index[nid] != k)
        raise ValueError(f"node id {dup!r} appears more than once")
    return ids, _clean_edges(index, edges)


def layer_depths(node_ids: list[str], edges: list[tuple[str, str]]) -> dict[str, int]:
    """Longest-path depth of every node from the sources (0 for a source). Edges
    that would close a cycle (found by a depth-first search in input order) are
    left out, so the result is always defined."""
    succ: dict[str, list[str]] = {nid: [] for nid in node_ids}
    for s, t in edges:
        succ[s].append(t)
    # Iterative DFS: post-order gives a reverse topological order of the acyclic part.
    state: dict[str, int] = {}  # 1 = on stack, 2 = done
    post: list[str] = []
    kept: list[tuple[str, str]] = []
    for root in node_ids:
        if root in state:
            continue
        state[root] = 1
        stack = [(root, iter(succ[root]))]
        while stack:
            nid, it = stack[-1]
            for t in it:
                if state.get(t) == 1:
                    continue  # back edge: closes a cycle, ignored
                kept.append((nid, t))
                if t not in state:
                    state[t] = 1
                    stack.append((t, iter(succ[t])))
                    break
            else:
                state[nid] = 2
                post.append(nid)
                stack.pop()
    preds: dict[str, list[str]] = {nid: [] for nid in node_ids}
    for s, t in kept:
        preds[t].append(s)
    depth: dict[str, int] = {}
    for nid in reversed(post):
        depth[nid] = max((depth[p] + 1 for p in preds[nid]), default=0)
    return depth


# ---------------------------------------------------------------- internals

def _clean_edges(index: dict[str, int], edges) -> list[tuple[str, str]]:
    seen: set[tuple[str, str]] = set()
    out: list[tuple[str, str]] = []
    for edge in edges:
        s, t = edge
        for end in (s, t):
            if end not in index:
                raise ValueError(f"edge {s!r} -> {t!r} names unknown node {end!r}")
        if s == t or (s, t) in seen:
            continue
        seen.add((s, t))
        out.append((s, t))
    return out


def _initial_layers(ids: list[str], depth: dict[str, int]) -> list[list[str]]:
    n = max(depth.values(), default=-1) + 1
    layers: list[list[str]] = [[] for _ in range(n)]
    for nid in ids:
        layers[depth[nid]].append(nid)
    return layers


class _Sweeper:
    """Crossing reduction on integer items: real nodes first, then one waypoint per
    intermediate column of every long edge; segments join adjacent columns."""

    def __init__(self, layers: list[list[str]], forward, depth: dict[str, int]):
        self.names: list[str] = [nid for layer in layers for nid in layer]
        item = {nid: k for k, nid in enumerate(self.names)}
        self.n_real = len(self.names)
        self.layers: list[list[int]] = [[item[nid] for nid in layer] for layer in layers]
        self.up: list[list[int]] = [[] for _ in range(self.n_real)]
        self.down: list[list[int]] = [[] for _ in range(self.n_real)]
        self.col: list[int] = [depth[nid] for nid in self.names]
        for s, t in forward:
            prev = item[s]
            for c in range(depth[s] + 1, depth[t]):
                way = len(self.up)
                self.up.append([])
                self.down.append([])
                self.col.append(c)
                self.layers[c].append(way)
                self._link(prev, way)
                prev = way
            self._link(prev, item[t])
        self.pos: list[int] = [0] * len(self.up)

    def _link(self, a: int, b: int) -> None:
        self.down[a].append(b)
        self.up[b].append(a)

    def _index(self, order: list[list[int]]) -> None:
        for layer in order:
            for k, it in enumerate(layer):
                self.pos[it] = k

    def total(self, order: list[list[int]]) -> int:
        self._index(order)
        return sum(self._between(order[c]) for c in range(len(order) - 1))

    def _between(self, upper: list[int]) -> int:
        """Crossings of the segments leaving ``upper`` (inversions, Fenwick tree)."""
        pos = self.pos
        seq = [pos[b] for a in upper for b in sorted(self.down[a], key=pos.__getitem__)]
        if not seq:
            return 0
        size = max(seq) + 2
        tree = [0] * size
        n = seen = 0
        for v in seq:
            # count earlier entries greater than v
            i, le = v + 1, 0
            while i > 0:
                le += tree[i]
                i -= i & -i
            n += seen - le
            i = v + 1
            while i < size:
                tree[i] += 1
                i += i & -i
            seen += 1
        return n

    def best_layers(self) -> list[list[str]]:
        current = [list(layer) for layer in self.layers]
        best, best_score = [list(layer) for layer in current], self.total(current)
        items = len(self.up)
        sweeps = _SWEEPS if items <= 2000 else 4
        for sweep in range(sweeps):
            if best_score == 0:
                break
            going_down = sweep % 2 == 0
            cols = range(1, len(current)) if going_down else range(len(current) - 2, -1, -1)
            nbrs = self.up if going_down else self.down
            self._index(current)
            for c in cols:
                current[c] = self._by_barycentre(current[c], nbrs)
                for k, it in enumerate(current[c]):
                    self.pos[it] = k
            self._transpose(current)
            score = self.total(current)
            if score < best_score:
                best, best_score = [list(layer) for layer in current], score
        return [[self.names[it] for it in layer if it < self.n_real] for layer in best]

    def _by_barycentre(self, layer: list[int], nbrs: list[list[int]]) -> list[int]:
        pos = self.pos
        scored = []
        for k, it in enumerate(layer):
            ps = nbrs[it]
            bary = sum(pos[p] for p in ps) / len(ps) if ps else float(k)
            scored.append((bary, k, it))
        scored.sort()
        return [it for _, _, it in scored]

    def _pair_cost(self, u: int, v: int) -> int:
        """Crossings among the segments of u and v when u sits directly above v."""
        pos, n = self.pos, 0
        for side in (self.up, self.down):
            pv = [pos[b] for b in side[v]]
            for a in side[u]:
                pa = pos[a]
                n += sum(1 for b in pv if b < pa)
        return n

    def _transpose(self, order: list[list[int]]) -> None:
        """Swap neighbours in a column while that lowers the crossings."""
        self._index(order)
        pos = self.pos
        for _ in range(4):
            improved = False
            for layer in order:
                for k in range(len(layer) - 1):
                    u, v = layer[k], layer[k + 1]
                    if self._pair_cost(v, u) < self._pair_cost(u, v):
                        layer[k], layer[k + 1] = v, u
                        pos[u], pos[v] = k + 1, k
                        improved = True
            if not improved:
                break


def _place(layers: list[list[str]], column_width: float, row_height: float,
           max_columns: int | None = None, band_gap: float | None = None) -> dict[str, tuple[float, float]]:
    per = max_columns or max(len(layers), 1)
    gap = row_height if band_gap is None else band_gap
    out: dict[str, tuple[float, float]] = {}
    y0 = 0.0
    for b in range(0, len(layers), per):
        band = layers[b:b + per]
        tallest = max(len(layer) for layer in band)
        for c, layer in enumerate(band):
            top = y0 + (tallest - len(layer)) * row_height / 2.0
            for r, nid in enumerate(layer):
                out[nid] = (c * column_width, top + r * row_height)
        y0 += tallest * row_height + gap
    return out


def _straight_crossings(pos: dict[str, tuple[float, float]], edges) -> int:
    """Proper crossings of the straight segments between node positions."""
    segs = [(pos[s], pos[t]) for s, t in edges]
    n = 0
    for (p1, p2), (q1, q2) in combinations(segs, 2):
        if {p1, p2} & {q1, q2}:
            continue
        if _segments_cross(p1, p2, q1, q2):
            n += 1
    return n


def _segments_cross(p1, p2, q1, q2) -> bool:
    def orient(a, b, c) -> float:
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    d1, d2 = orient(q1, q2, p1), orient(q1, q2, p2)
    d3, d4 = orient(p1, p2, q1), orient(p1, p2, q2)
    return d1 * d2 < 0 and d3 * d4 < 0
