"""The family and one-line summary of every example in ``resources/examples``.

``tools/graph_builder.write_documents`` copies them into each example's meta
(``family``, ``summary``), where the example gallery reads them. A new example
needs an entry here, or writing it fails.
"""

from __future__ import annotations

LATTICE = "lattice"
SHELL = "shell & TPMS"
GROWTH = "virtual growth"
PHASOR = "phasor infill"
RD = "reaction diffusion"
PROPERTIES = "properties"
IMPLICIT = "implicit media"
FAMILIES = (LATTICE, SHELL, PROPERTIES, GROWTH, PHASOR, RD, IMPLICIT)

CATALOGUE: dict[str, tuple[str, str]] = {
    # unit-cell trusses and beam lattices (paper Table 4)
    "octet": (LATTICE, "FCC nodes joined to their 12 nearest neighbours: the stiff, stretch-dominated classic."),
    "bcc": (LATTICE, "The four body diagonals through the cell centre, thicker at the nodes."),
    "fcc_lattice": (LATTICE, "Heavy spheres on the FCC sites joined by slender rods: a phononic crystal."),
    "auxetic3d": (LATTICE, "Columns joined by re-entrant curved arms: stretching in z flattens the arms."),
    "anti_chiral": (LATTICE, "Rings with four tangent ligaments, neighbours mirror images (anti-tetrachiral)."),
    "assembled": (LATTICE, "Cuboctahedral voxel with S-shaped flexure struts: a compliant building block."),
    "assembled2": (LATTICE, "Cuboctahedral voxel whose face struts bow inwards: re-entrant, auxetic faces."),
    "assembled3": (LATTICE, "Each voxel face a pinwheel of curved arms around a turned square: chiral."),
    "twist_tilable": (LATTICE, "A chiral cube of rings and tangential arms that tiles: a twist metamaterial."),
    "six_hole_bcc": (LATTICE, "Spherical shells on the BCC sites with six holes each: a bucklicrystal by CSG."),
    "bandgap": (LATTICE, "Elastic frame, disc masses and thin braces: local resonators for a bandgap."),
    # shells and TPMS (paper Tables 2 and 3)
    "tpms_schwarz_p": (SHELL, "Schwarz P from one free-boundary patch by conjugate surface construction."),
    "tpms_schwarz_d": (SHELL, "Schwarz D: a Plateau patch over a Petrie hexagon of the cube."),
    "tpms_gyroid": (SHELL, "The gyroid: the D patch bent into its associate family at the Bonnet angle."),
    "tpms_neovius": (SHELL, "Neovius: a conjugate quadrilateral in the 1/48 mirror tetrahedron."),
    "tpms_schoen_iwp": (SHELL, "Schoen I-WP: a free-boundary hexagon with an edge-length period search."),
    "tpms_wei_genus4": (SHELL, "Wei's genus-4 surface from a free-boundary heptagon in the cube."),
    "tpms_steffmann": (SHELL, "Steffmann: the conjugate of I-WP, a Plateau hexagon of straight lines."),
    "tpms_schoen_s_s": (SHELL, "Schoen S'-S'' in its reflectional prism cell at c/a = 0.7."),
    "tpms_deformed_schoen_s_s": (SHELL, "Schoen S'-S'' deformed to c/a = 0.5, the same loop in a flatter cell."),
    "tpms_schoen_r2": (SHELL, "Schoen R2: a mixed minimal annulus between right isosceles triangles."),
    "tpms_schwarz_clp": (SHELL, "Schwarz CLP: a Plateau patch over a skew hexagon of straight lines."),
    "tpms_schwarz_h": (SHELL, "Schwarz H on the hexagonal lattice's orthorhombic cell."),
    "tpms_schwarz_p_neovius": (SHELL, "Schwarz P and Neovius shells in one cell (a hybrid)."),
    "tpms_schwarz_p_cubic_closed": (SHELL, "Schwarz P plus flat cubic walls that close every channel."),
    "tpms_schwarz_p_cubic_open": (SHELL, "Schwarz P plus cubic walls that leave each channel open."),
    "tpms_polyhedral_cell": (SHELL, "The straight-edged twin of Schwarz P: flat hexagons, a polyhedral shell."),
    "tpms_non_manifold_surface": (SHELL, "Three flat fins meeting on the body diagonal: a non-manifold shell."),
    "tpms_star_shaped": (SHELL, "Walls perforated by four-pointed star-shaped pores."),
    "tpms_our_composition": (SHELL, "A Schwarz P shell with a truss in each of its two labyrinths."),
    # effective properties (paper section 6.6)
    "octet_stiffness": (PROPERTIES, "The octet truss homogenized: its stiffness tensor and material sphere."),
    "schwarz_p_stiffness": (PROPERTIES, "A Schwarz P shell homogenized: the stiffness of a TPMS."),
    # virtual growth (Bastek et al.)
    "growth_tl_2d": (GROWTH, "TL+- tiles grown by wave-function collapse, with their 2D stiffness."),
    "growth_tl_hints": (GROWTH, "The same set steered by frequency hints towards + and - blocks: a stiffer mix."),
    "growth_cubic_3d": (GROWTH, "A 3D beam tiling of cubic blocks: beams, volume and stiffness."),
    # phasor infill and reaction diffusion
    "phasor_slab": (PHASOR, "A painted slab of phasor-noise diamond cells, sliced at mid height."),
    "rd_cantilever": (RD, "A SIMP cantilever filled with Gray-Scott stripes along its stress directions."),
    # implicit media (paper 004)
    "implicit_multiphase": (IMPLICIT, "Two particle clouds, spheres and turned rounded boxes, in one medium."),
    "implicit_ice_bubbles": (IMPLICIT, "A block of ice with air bubbles thinning out towards the top."),
    "implicit_multiscale_ice": (IMPLICIT, "Ice whose bubbles grow from small and dense to large and sparse, "
                                          "density painted in a Scalar Field."),
    "implicit_paper_fibres": (IMPLICIT, "A gyroid sheet pressed flat into interwoven paper-like fibres."),
    "implicit_rock_pile": (IMPLICIT, "Piled grains on a deformed lattice, convex at the bottom, dimpled on top."),
    "implicit_porous_lattice": (IMPLICIT, "Lattice spheres kept by a congruence rule: an open frame, homogenised."),
    "implicit_graded_gyroid": (IMPLICIT, "A gyroid network graded from 15 % to 50 % solid along its height."),
    "implicit_suspension_octet": (IMPLICIT, "The octet cell blended with a cloud of small spheres by a smooth union."),
}


def catalogue_meta(stem: str) -> dict[str, str]:
    """``{"family": ..., "summary": ...}`` of the example file ``<stem>.json``.

    Raises KeyError naming the example when it has no entry."""
    try:
        family, summary = CATALOGUE[stem]
    except KeyError:
        raise KeyError(f"example {stem!r} has no family / summary in tools/example_catalogue.py") from None
    return {"family": family, "summary": summary}
