"""Reference lattice skeletons used by benchmarks and tests."""

from __future__ import annotations

import numpy as np


def octet_segments() -> list[np.ndarray]:
    """The octet truss of the unit cell as 18 straight segments, each (2, 3).

    Two diagonals on each of the three face orientations (their periodic
    copies cover the opposite faces) and the 12 octahedron edges joining the
    face centres.
    """
    segs = []
    for axis in range(3):
        u, v = [i for i in range(3) if i != axis]
        a, b, c, d = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
        b[u] = b[v] = 1.0
        c[u] = d[v] = 1.0
        segs += [(a, b), (c, d)]
    centres = []
    for axis in range(3):
        for val in (0.0, 1.0):
            p = np.full(3, 0.5)
            p[axis] = val
            centres.append(p)
    for i in range(6):
        for j in range(i + 1, 6):
            if np.isclose(np.linalg.norm(centres[i] - centres[j]), np.sqrt(0.5)):
                segs.append((centres[i], centres[j]))
    return [np.array(s) for s in segs]
