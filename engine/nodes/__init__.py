"""Node types.  Importing this package registers them all."""

from . import lines, solids, topology, transforms  # noqa: F401
