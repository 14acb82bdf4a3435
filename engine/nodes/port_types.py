"""The value types node ports carry, declared to the graph core.

One line per family's values (the classes live in the families'
``values`` modules); a "Skeleton" port accepts lines, surfaces and their
transforms.  Imported first by engine/nodes/__init__.py, and by the graph
core on first use.
"""

from engine.graph.schema import register_port_types

register_port_types("Point", "EdgeChain", "Skeleton", "Solid", "Voxel", "Field", "Mesh",   # geometry
                    "SurfaceReport",                                                   # surfaces
                    "Stiffness", "Spectrum",                                           # physics
                    "TileSet", "Tiling",                                               # growth
                    "PhasorFields", "PhasorInfill", "Energy",                          # phasor
                    "Design",                                                          # topopt
                    "RDFields", "RDStructures", "Contour",                             # rd
                    "SDF")                                                             # implicit
