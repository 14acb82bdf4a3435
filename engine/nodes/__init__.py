"""Node types.  Importing this package registers them all."""

from . import growth, lines, phasor, properties, solids, topology, transforms  # noqa: F401
from . import phasor_preview  # noqa: F401
from . import rd  # noqa: F401
from . import rd_topopt  # noqa: F401
from . import surfaces  # noqa: F401
