"""The viewport's scene, kept by actor, and its camera framing.

`SceneActors` holds one named actor per shown thing (solid, skeleton lines,
control points, cell box, material sphere, toolpaths, captions) with the key
of the value it draws; `put` replaces an actor only when its key changed, so
showing the same thing again touches nothing.  It counts what it did
(``replaced[name]``, ``full_rebuilds``) so tests can count instead of timing.

`Framing` decides when the camera is homed: on the first real content once
the widget has its size, and again when the content's bounds grow or shrink
by more than `REFRAME_FACTOR` or move away from the framed region.
"""

from __future__ import annotations

from collections import Counter
from typing import Any, Callable

import numpy as np

REFRAME_FACTOR = 2.0     # re-home when the content's diagonal changes by more than this factor
MIN_FRAMED_PIXELS = 64   # the widget is "sized" once both sides reach this


class SceneActors:
    """Named actors of a pyvista plotter, each with the key of what it draws.

    A key is compared with ``==``; put the value objects themselves in it (not
    their ``id``), so an identical-looking new value is told apart and the
    old one is not collected while its actor shows it."""

    def __init__(self, plotter):
        self.plotter = plotter
        self.keys: dict[str, Any] = {}
        self.replaced: Counter = Counter()   # name -> number of times its actor was (re)built
        self.full_rebuilds = 0               # clear-everything calls (none in normal use)

    def has(self, name: str) -> bool:
        return name in self.keys

    def same(self, name: str, key: Any) -> bool:
        return name in self.keys and _same_key(self.keys[name], key)

    def put(self, name: str, key: Any, build: Callable[[], Any]) -> bool:
        """Run ``build()`` (which adds the actor called `name`) unless the actor shows
        `key` already; True if it was (re)built."""
        if self.same(name, key):
            return False
        build()
        self.keys[name] = key
        self.replaced[name] += 1
        return True

    def drop(self, name: str) -> bool:
        """Remove the actor called `name`; True if there was one."""
        if name not in self.keys:
            return False
        del self.keys[name]
        self.plotter.remove_actor(name, reset_camera=False, render=False)
        return True

    def clear(self) -> None:
        """Remove every actor this scene added (counted in `full_rebuilds`)."""
        self.full_rebuilds += 1
        for name in list(self.keys):
            self.drop(name)

    def actor(self, name: str):
        return self.plotter.actors.get(name)


def _same_key(a, b) -> bool:
    """Keys are equal: tuples element by element, arrays by value, other objects by identity
    (value objects like Solid define no cheap ``==``)."""
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same_key(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and np.array_equal(a, b)
    if isinstance(a, (int, float, str, bytes, bool, type(None))):
        return type(a) is type(b) and a == b
    return a is b


class Framing:
    """When to home the camera on the content (bounds are VTK's (x0, x1, y0, y1, z0, z1))."""

    def __init__(self):
        self.framed: np.ndarray | None = None   # (lo, hi) the camera was last homed on, with real content
        self.homes = 0

    def reset(self) -> None:
        self.framed = None

    def wants_home(self, bounds, *, has_content: bool, sized: bool) -> bool:
        """True if the camera should be homed on `bounds` now."""
        if not sized:
            return False
        if not has_content:
            return self.homes == 0           # an empty view is framed once, on its box
        box = _box(bounds)
        if box is None:
            return False
        if self.framed is None:
            return True
        old = self.framed
        d_old = float(np.linalg.norm(old[1] - old[0])) or 1e-12
        d_new = float(np.linalg.norm(box[1] - box[0])) or 1e-12
        if max(d_new / d_old, d_old / d_new) > REFRAME_FACTOR:
            return True
        shift = float(np.linalg.norm(0.5 * (box[0] + box[1]) - 0.5 * (old[0] + old[1])))
        return shift > 0.5 * d_old

    def homed(self, bounds, *, has_content: bool) -> None:
        self.homes += 1
        self.framed = _box(bounds) if has_content else None


def _box(bounds):
    b = np.asarray(bounds, dtype=float).reshape(3, 2)
    if not np.all(np.isfinite(b)) or np.any(b[:, 1] < b[:, 0]):
        return None
    return np.stack([b[:, 0], b[:, 1]])
