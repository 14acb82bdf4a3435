"""Node types.  Importing this package registers them all."""

from . import port_types  # noqa: F401  (first: the value types ports carry)
from . import growth, lines, phasor, properties, solids, topology, transforms  # noqa: F401
from . import phasor_preview  # noqa: F401
from . import rd  # noqa: F401
from . import rd_topopt  # noqa: F401
from . import surfaces  # noqa: F401
from . import voxel_import  # noqa: F401
from . import implicit_lattices, implicit_media, implicit_ops, implicit_solid  # noqa: F401
from . import scalar_field  # noqa: F401
from . import codecs  # noqa: F401  (how stateful nodes' values are kept in project files)
