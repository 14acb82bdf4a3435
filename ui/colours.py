"""Colours the window draws with: node families, port value types, evaluation statuses.

The engine knows no colours; a family without an entry here is drawn grey.
"""

from __future__ import annotations

# Node header colour by node family (RGB).
FAMILY_COLOURS = {
    "topology": (232, 176, 60),
    "skeleton": (70, 150, 220),
    "transform": (150, 110, 200),
    "solid": (90, 180, 110),
    "property": (60, 165, 175),     # teal: apart from the red of a failed node's outline
    "implicit": (200, 120, 70),     # implicit media (SDF values)
}

# Port dot colours by value type, so compatible ends are recognisable at a glance.
PORT_COLOURS = {
    "Point": (240, 200, 90),
    "EdgeChain": (245, 150, 60),
    "Skeleton": (90, 170, 240),
    "Solid": (110, 210, 130),
    "Voxel": (60, 160, 90),
    "Stiffness": (230, 100, 100),
    "Spectrum": (230, 120, 200),
    "Field": (200, 200, 200),
    "Mesh": (160, 220, 220),
    "TileSet": (180, 140, 240),
    "Tiling": (140, 120, 220),
    "SDF": (230, 140, 80),
}

# Text colour of a node's evaluation status (inspector, docks).
STATUS_COLOURS = {"evaluated": "#5cb85c", "cached": "#5bc0de", "failed": "#e04040",
                  "blocked": "#e0a030", "cancelled": "#999999"}


def family_colour(family: str, default=(120, 120, 120)) -> tuple[int, int, int]:
    """The RGB colour of a node family, ``default`` for a family without one."""
    return FAMILY_COLOURS.get(family, default)


def family_shade(family: str, factor: float) -> tuple[int, int, int]:
    """The family colour scaled by ``factor`` (node bodies are a darker shade)."""
    r, g, b = family_colour(family)
    return (int(r * factor), int(g * factor), int(b * factor))
