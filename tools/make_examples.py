"""Build the example graphs in ``resources/examples/`` (paper Tables 3 and 4).

Every example is built the way a user builds it in the node editor, with the
undoable commands of :mod:`engine.graph` (``AddNode`` / ``Connect`` on an
``UndoStack``), following the paper's four-step design process (Makatura et
al. 2023, section 3):

1. a fundamental skeleton from a few Vertex and Edge Chain nodes,
2. Line nodes with a thickness profile (diameter samples over t in [0, 1]),
3. Mirror / Transform / Group nodes that fill the unit cell using the
   structure's symmetry,
4. one or more Object nodes (optionally combined by a CSG Boolean) and exactly
   one Voxel node carrying the base material of the paper's section 8.2.

All structures are periodic unit cells on [0, 1]^3: the Object node wraps
geometry across the cell faces, so members that leave through one face
re-enter through the opposite one.  Node ids are stable and readable, and
node positions are laid out in readable columns (engine.graph.layout: a
node's column is its depth, rows ordered to reduce crossings).

Beside the unit cells: property examples (a cell followed by a Material
Matrix node), virtual growth examples (Tile Set -> Grow -> Tiling Image /
Beams + Tiling Properties), a phasor infill and a reaction-diffusion example.
Each example's family and one-line summary (the gallery shows them) come
from ``tools/example_catalogue.py``.

Usage::

    python tools/make_examples.py                  # all examples
    python tools/make_examples.py --only octet bcc # a subset (phasor_slab: the phasor infill example,
                                                   # rd_cantilever: the reaction-diffusion one)
    python tools/make_examples.py --out /tmp/ex    # somewhere else

The test ``tests/resources/test_examples.py`` regenerates the files and
checks that they equal the committed ones, so edit the graphs here, never
the JSON by hand.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from engine.graph import AddNode, Connect, GraphDocument, UndoStack  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from graph_builder import (COLUMN_WIDTH, EDITOR_VIEW, ROW_HEIGHT, GraphBuilder as _Builder,  # noqa: E402
                           r6, vec6, write_documents)

from engine.graph.layout import fit_columns, layered_positions  # noqa: E402

EXAMPLES_DIR = ROOT / "resources" / "examples"

CENTRE = [0.5, 0.5, 0.5]
BODY_DIAGONAL = [1.0, 1.0, 1.0]
SPHERE_SEED = 0.0               # a zero-length line: spherically thickened, a sphere (paper 3.1)


def _r(x: float) -> float:
    return r6(x)


def _vec(p) -> list[float]:
    return vec6(p)


def _add(p, q, s: float = 1.0) -> list[float]:
    return [a + s * b for a, b in zip(p, q)]


def _unit(v) -> list[float]:
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def _polar(centre, radius: float, degrees: float) -> list[float]:
    """A point in the plane z = centre[2] at `degrees` around `centre`."""
    a = math.radians(degrees)
    return [centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a), centre[2]]


class GraphBuilder(_Builder):
    """A unit-cell example: mirrors and rotations act about the cell centre."""

    origin = tuple(CENTRE)
    sep = "_"

    def __init__(self, name: str, *, title: str, source: str, paper_nodes: int | None,
                 description: str):
        super().__init__(name, {"example": name, "title": title, "source": source,
                                "paper_node_count": paper_nodes, "description": description})


# =============================================================== the examples

def octet() -> GraphBuilder:
    b = GraphBuilder(
        "octet", title="Octet truss", source="Deshpande, Fleck & Ashby 2001", paper_nodes=12,
        description="FCC nodes joined to their 12 nearest neighbours: face diagonals plus the "
                    "octahedron between face centres. One bent strut (corner -> face centre -> "
                    "neighbouring face centre) is mirrored in x, y, z and copied about the body "
                    "diagonal.")
    corner = b.vertex("v_corner", [0, 0, 0])
    face_z = b.vertex("v_face_z", [0.5, 0.5, 0])
    face_y = b.vertex("v_face_y", [0.5, 0, 0.5])
    chain = b.chain("e_strut", [corner, face_z, face_y])
    line = b.line("l_strut", [chain], [[0, 0.08], [1, 0.08]])
    m = b.mirror("mirror_x", line, [1, 0, 0])
    m = b.mirror("mirror_y", m, [0, 1, 0])
    m = b.mirror("mirror_z", m, [0, 0, 1])
    r = b.transform("rot_111_120", m, angle=120.0, axis=BODY_DIAGONAL)
    r = b.transform("rot_111_240", r, angle=240.0, axis=BODY_DIAGONAL)
    b.voxel("voxel", b.object("object", r))
    return b


def bcc() -> GraphBuilder:
    b = GraphBuilder(
        "bcc", title="BCC truss", source="body-centred cubic strut lattice (textbook)", paper_nodes=None,
        description="The four body diagonals through the cell centre. One half diagonal "
                    "(corner -> centre), thicker at both nodes, mirrored in x, y and z.")
    corner = b.vertex("v_corner", [0, 0, 0])
    centre = b.vertex("v_centre", CENTRE)
    chain = b.chain("e_half_diagonal", [corner, centre])
    line = b.line("l_half_diagonal", [chain], [[0, 0.11], [0.5, 0.08], [1, 0.11]])
    m = b.mirror("mirror_x", line, [1, 0, 0])
    m = b.mirror("mirror_y", m, [0, 1, 0])
    m = b.mirror("mirror_z", m, [0, 0, 1])
    b.voxel("voxel", b.object("object", m))
    return b


def fcc_lattice() -> GraphBuilder:
    b = GraphBuilder(
        "fcc_lattice", title="3D FCC lattice", source="Lu, Yang, Guest & Srivastava 2017", paper_nodes=19,
        description="Heavy spheres on the FCC sites joined by slender cylindrical rods to their 12 "
                    "nearest neighbours (a ball-and-stick phononic crystal). The rods are the octet "
                    "strut mirrored and turned about the body diagonal; the spheres are one sphere "
                    "copied by the FCC translations (1/2, 1/2, 0) and (1/2, 0, 1/2). Rods and spheres "
                    "are separate Objects (normal vs spherical extrusion) joined by a CSG union.")
    corner = b.vertex("v_corner", [0, 0, 0])
    face_z = b.vertex("v_face_z", [0.5, 0.5, 0])
    face_y = b.vertex("v_face_y", [0.5, 0, 0.5])
    seed = b.vertex("v_sphere_seed", [SPHERE_SEED, 0, 0])
    rod = b.chain("e_rod", [corner, face_z, face_y])
    ball = b.chain("e_sphere", [corner, seed])
    rods = b.line("l_rod", [rod], [[0, 0.06], [1, 0.06]])
    balls = b.line("l_sphere", [ball], [[0, 0.36], [1, 0.36]])
    m = b.mirror("rod_mirror_x", rods, [1, 0, 0])
    m = b.mirror("rod_mirror_y", m, [0, 1, 0])
    m = b.mirror("rod_mirror_z", m, [0, 0, 1])
    m = b.transform("rod_rot_111_120", m, angle=120.0, axis=BODY_DIAGONAL)
    m = b.transform("rod_rot_111_240", m, angle=240.0, axis=BODY_DIAGONAL)
    s = b.transform("sphere_fcc_xy", balls, translation=[0.5, 0.5, 0])
    s = b.transform("sphere_fcc_xz", s, translation=[0.5, 0, 0.5])
    o_rods = b.object("object_rods", m, extrusion="normal")
    o_balls = b.object("object_spheres", s)
    b.voxel("voxel", b.csg("union", [o_balls, o_rods], "union"))
    return b


def auxetic3d() -> GraphBuilder:
    b = GraphBuilder(
        "auxetic3d", title="3D re-entrant auxetic", source="after Hsueh et al. 2019 (Handbook of Mechanics "
        "of Materials), 3D re-entrant lattice", paper_nodes=17,
        description="Vertical columns on the cell edges and through the cell centre, offset by half "
                    "a cell in z, joined by curved arms that run downhill from the top of one column "
                    "to the bottom of the next (re-entrant, so stretching in z flattens the arms and "
                    "widens the cell). Column + arm, mirrored in x and y, then copied by the "
                    "body-centring translation (1/2, 1/2, 1/2).")
    bottom = b.vertex("v_column_bottom", [0, 0, 0.1])
    top = b.vertex("v_column_top", [0, 0, 0.9])
    sag = b.vertex("v_arm_sag", [0.25, 0.25, 0.71])
    foot = b.vertex("v_centre_column_bottom", [0.5, 0.5, 0.6])
    column = b.chain("e_column", [bottom, top])
    arm = b.chain("e_arm", [top, sag, foot], smooth=True)
    l_column = b.line("l_column", [column], [[0, 0.09], [1, 0.09]])
    l_arm = b.line("l_arm", [arm], [[0, 0.085], [0.5, 0.065], [1, 0.085]])
    g = b.group("column_and_arm", [l_column, l_arm])
    m = b.mirror("mirror_x", g, [1, 0, 0])
    m = b.mirror("mirror_y", m, [0, 1, 0])
    t = b.transform("body_centring", m, translation=[0.5, 0.5, 0.5])
    b.voxel("voxel", b.object("object", t))
    return b


def anti_chiral() -> GraphBuilder:
    radius, half = 0.12, 0.25
    c = [half, half, 0.5]
    b = GraphBuilder(
        "anti_chiral", title="3D anti-tetrachiral", source="after Wu et al. 2019 (chiral metamaterials "
        "review), anti-tetrachiral lattice", paper_nodes=13,
        description="Rings with four tangent ligaments; neighbouring rings are mirror images "
                    "(anti-chiral). A ligament plus a quarter ring is rotated about the ring centre "
                    "(4 ligaments, full ring), mirrored in x and y (a 2x2 anti-tetrachiral sheet in "
                    "z = 1/2), and the sheet is turned into the planes y = 1/2 and x = 1/2; the "
                    "sheets cross at their ligament midpoints.")
    end = b.vertex("v_ligament_end", [0.5, half + radius, 0.5])
    tangent = b.vertex("v_ring_top", _polar(c, radius, 90))
    arc_mid = b.vertex("v_ring_arc", _polar(c, radius, 135))
    arc_end = b.vertex("v_ring_left", _polar(c, radius, 180))
    ligament = b.chain("e_ligament", [end, tangent])
    arc = b.chain("e_quarter_ring", [tangent, arc_mid, arc_end], smooth=True)
    line = b.line("l_ligament_ring", [ligament, arc], [[0, 0.06], [1, 0.06]])
    r = b.transform("ring_rot90", line, angle=90.0, origin=c)
    r = b.transform("ring_rot180", r, angle=180.0, origin=c)
    m = b.mirror("mirror_x", r, [1, 0, 0])
    sheet = b.mirror("mirror_y", m, [0, 1, 0])
    xy = b.transform("sheet_to_y", sheet, angle=90.0, axis=[1, 0, 0])
    x = b.transform("sheet_to_x", sheet, angle=90.0, axis=[0, 1, 0], copy=False)
    g = b.group("three_sheets", [xy, x])
    b.voxel("voxel", b.object("object", g))
    return b


def _face_strut_frame():
    """Geometry of one cuboct face strut on the face z = 0: from the edge
    midpoint (0.5, 0, 0) towards (0, 0.5, 0).  Returns start, direction along
    the strut, in-plane normal towards the face centre, and the strut length."""
    start = [0.5, 0.0, 0.0]
    u = _unit([-1.0, 1.0, 0.0])
    n = _unit([1.0, 1.0, 0.0])
    return start, u, n, math.sqrt(0.5)


def assembled() -> GraphBuilder:
    start, u, n, length = _face_strut_frame()
    stub, amp = 0.07, 0.055
    b = GraphBuilder(
        "assembled", title="Assembled voxel: compliant", source="after Jenett et al. 2020, discretely "
        "assembled cuboct voxel with flexure struts", paper_nodes=20,
        description="Cuboctahedral voxel whose face-diamond struts are S-shaped flexures with short "
                    "straight, thicker stubs at the nodes (edge midpoints). Half a strut (stub + half "
                    "S) is turned 180 degrees about the strut midpoint, 4-fold about the face normal, "
                    "and copied to the x and y faces about the body diagonal.")
    half = length / 2.0 - stub
    stub_end = _add(start, u, stub)
    p1 = _add(_add(stub_end, u, half / 3.0), n, amp * math.sin(math.pi / 3.0))
    p2 = _add(_add(stub_end, u, 2.0 * half / 3.0), n, amp * math.sin(2.0 * math.pi / 3.0))
    mid = _add(start, u, length / 2.0)
    v0 = b.vertex("v_node", start)
    v1 = b.vertex("v_stub_end", stub_end)
    v2 = b.vertex("v_flexure_a", p1)
    v3 = b.vertex("v_flexure_b", p2)
    v4 = b.vertex("v_strut_middle", mid)
    e_stub = b.chain("e_stub", [v0, v1])
    e_flex = b.chain("e_flexure", [v1, v2, v3, v4], smooth=True)
    line = b.line("l_half_strut", [e_stub, e_flex], [[0, 0.1], [0.16, 0.1], [0.3, 0.062], [1, 0.062]])
    t = b.transform("strut_rot180", line, angle=180.0, origin=mid)
    t = b.transform("face_rot90", t, angle=90.0, origin=[0.5, 0.5, 0])
    t = b.transform("face_rot180", t, angle=180.0, origin=[0.5, 0.5, 0])
    faces = b.threefold("faces", t)
    b.voxel("voxel", b.object("object", faces))
    return b


def assembled2() -> GraphBuilder:
    start, u, n, length = _face_strut_frame()
    stub, depth = 0.06, 0.11
    b = GraphBuilder(
        "assembled2", title="Assembled voxel: re-entrant", source="after Jenett et al. 2020, discretely "
        "assembled cuboct voxel with auxetic (re-entrant) struts", paper_nodes=15,
        description="Cuboctahedral voxel whose face-diamond struts bow in towards the face centre "
                    "(re-entrant, auxetic faces): straight node stubs and a curved beam. Half a strut "
                    "is mirrored across the strut's bisecting plane, turned 4-fold about the face "
                    "normal and copied to the other faces about the body diagonal.")
    half = length / 2.0 - stub
    stub_end = _add(start, u, stub)

    def bow(f):  # cosine bow: flat where it meets the stub and at the strut middle
        return depth * (1.0 - math.cos(math.pi * f)) / 2.0

    p1 = _add(_add(stub_end, u, half / 3.0), n, bow(1.0 / 3.0))
    p2 = _add(_add(stub_end, u, 2.0 * half / 3.0), n, bow(2.0 / 3.0))
    mid = _add(_add(start, u, length / 2.0), n, depth)
    v0 = b.vertex("v_node", start)
    v1 = b.vertex("v_stub_end", stub_end)
    v2 = b.vertex("v_bow_a", p1)
    v3 = b.vertex("v_bow_b", p2)
    v4 = b.vertex("v_strut_middle", mid)
    e_stub = b.chain("e_stub", [v0, v1])
    e_bow = b.chain("e_bow", [v1, v2, v3, v4], smooth=True)
    line = b.line("l_half_strut", [e_stub, e_bow], [[0, 0.1], [0.15, 0.1], [0.3, 0.065], [1, 0.065]])
    m = b.mirror("strut_mirror", line, [1, -1, 0], origin=[0.5, 0.5, 0])
    t = b.transform("face_rot90", m, angle=90.0, origin=[0.5, 0.5, 0])
    t = b.transform("face_rot180", t, angle=180.0, origin=[0.5, 0.5, 0])
    faces = b.threefold("faces", t)
    b.voxel("voxel", b.object("object", faces))
    return b


def assembled3() -> GraphBuilder:
    c = [0.5, 0.5, 0.0]
    rho, twist = 0.17, 55.0
    b = GraphBuilder(
        "assembled3", title="Assembled voxel: chiral", source="after Jenett et al. 2020, discretely "
        "assembled voxel with chiral faces", paper_nodes=15,
        description="Each voxel face is a pinwheel: a straight-edged inner square, turned against "
                    "the face, held by four curved arms from the nodes (edge midpoints). One arm plus "
                    "one inner edge is turned 4-fold about the face normal and copied to the other "
                    "faces about the body diagonal (proper rotations, so every face has the same "
                    "handedness).")
    p0 = _polar(c, rho, -90.0 + twist)
    p1 = _polar(c, rho, twist)
    node = [0.5, 0.0, 0.0]
    # The arm leaves the node heading into the face and swings round onto the
    # inner square corner, roughly along the inner edge's direction.
    a1 = [0.5 + 0.035, 0.13, 0.0]
    a2 = [p0[0] + 0.02, p0[1] - 0.14, 0.0]
    v0 = b.vertex("v_node", node)
    v1 = b.vertex("v_arm_a", a1)
    v2 = b.vertex("v_arm_b", a2)
    v3 = b.vertex("v_square_a", p0)
    v4 = b.vertex("v_square_b", p1)
    arm = b.chain("e_arm", [v0, v1, v2, v3], smooth=True)
    edge = b.chain("e_square_edge", [v3, v4])
    line = b.line("l_arm_edge", [arm, edge], [[0, 0.09], [0.15, 0.065], [0.7, 0.065], [1, 0.075]])
    t = b.transform("face_rot90", line, angle=90.0, origin=c)
    t = b.transform("face_rot180", t, angle=180.0, origin=c)
    faces = b.threefold("faces", t)
    b.voxel("voxel", b.object("object", faces))
    return b


def twist_tilable() -> GraphBuilder:
    inset, radius = 0.1, 0.17
    face_c = [0.5, 0.5, inset]
    corner = [inset, inset, inset]
    # Tangent point on the ring seen from the face corner (at 225 degrees):
    # the arm touches the ring there, all four arms turning the same way.
    dist = math.hypot(corner[0] - face_c[0], corner[1] - face_c[1])
    alpha = math.degrees(math.acos(radius / dist))
    first = 225.0 + alpha
    b = GraphBuilder(
        "twist_tilable", title="Chiral twist metamaterial (tileable)", source="after Frenzel, Kadic & "
        "Wegener 2017, 'Three-dimensional mechanical metamaterials with a twist'", paper_nodes=33,
        description="A chiral cube: each face carries a ring held by four arms that run from the "
                    "face corners tangentially onto the ring, all with the same handedness (the "
                    "cube has the 24 proper rotations of the octahedral group and no mirror). To "
                    "tile by translation the cube is inset from the cell faces and its corners are "
                    "linked to the cell corner, where 8 neighbouring cubes meet; neighbouring faces "
                    "stay separate walls instead of having to be each other's mirror image.")
    node = b.vertex("v_cell_corner", [0, 0, 0])
    v_corner = b.vertex("v_cube_corner", corner)
    ring = [b.vertex(f"v_ring_{k}", _polar(face_c, radius, first + 90.0 * k)) for k in range(4)]
    e_link = b.chain("e_link", [node, v_corner])
    e_arm = b.chain("e_arm", [v_corner, ring[0]])
    e_ring = b.chain("e_ring", ring, smooth=True, order=[0, 1, 2, 3, 0])
    l_link = b.line("l_link", [e_link], [[0, 0.11], [1, 0.08]])
    l_arm = b.line("l_arm", [e_arm], [[0, 0.065], [0.5, 0.055], [1, 0.06]])
    l_ring = b.line("l_ring", [e_ring], [[0, 0.06], [1, 0.06]])
    axis_z = dict(axis=[0, 0, 1], origin=CENTRE)
    arms = b.transform("arm_rot90", l_arm, angle=90.0, **axis_z)
    arms = b.transform("arm_rot180", arms, angle=180.0, **axis_z)
    face = b.group("bottom_face", [l_ring, arms])
    faces = b.transform("flip_x180", face, angle=180.0, axis=[1, 0, 0])
    cube = b.threefold("cube", faces)
    links = b.mirror("link_mirror_x", l_link, [1, 0, 0])
    links = b.mirror("link_mirror_y", links, [0, 1, 0])
    links = b.mirror("link_mirror_z", links, [0, 0, 1])
    cell = b.group("cube_and_links", [cube, links])
    b.voxel("voxel", b.object("object", cell))
    return b


def six_hole_bcc() -> GraphBuilder:
    outer, inner, hole, neck = 0.80, 0.68, 0.24, 0.14
    b = GraphBuilder(
        "six_hole_bcc", title="6-hole BCC bucklicrystal", source="after Babaee et al. 2013, '3D soft "
        "metamaterials with negative Poisson's ratio' (6-hole building block, BCC)", paper_nodes=27,
        description="Spherical shells on the BCC sites, each pierced by six holes along the axes and "
                    "joined to its eight neighbours by short necks along the body diagonals. Built "
                    "by CSG: (balls + necks) minus inner balls gives the joined shells, minus the "
                    "axis cylinders gives the holes.")
    corner = b.vertex("v_corner", [0, 0, 0])
    seed = b.vertex("v_sphere_seed", [SPHERE_SEED, 0, 0])
    centre = b.vertex("v_centre", CENTRE)
    axis_end = b.vertex("v_axis_end", [1, 0, 0])
    e_ball = b.chain("e_sphere", [corner, seed])
    e_neck = b.chain("e_neck", [corner, centre])
    e_axis = b.chain("e_axis_x", [corner, axis_end])
    l_outer = b.line("l_outer_sphere", [e_ball], [[0, outer], [1, outer]])
    l_inner = b.line("l_inner_sphere", [e_ball], [[0, inner], [1, inner]])
    l_neck = b.line("l_neck", [e_neck], [[0, neck], [1, neck]])
    l_hole = b.line("l_hole", [e_axis], [[0, hole], [1, hole]])
    bc = dict(translation=[0.5, 0.5, 0.5])
    outers = b.transform("outer_body_centring", l_outer, **bc)
    inners = b.transform("inner_body_centring", l_inner, **bc)
    necks = b.mirror("neck_mirror_x", l_neck, [1, 0, 0])
    necks = b.mirror("neck_mirror_y", necks, [0, 1, 0])
    necks = b.mirror("neck_mirror_z", necks, [0, 0, 1])
    balls = b.group("balls_and_necks", [outers, necks])
    axes = b.threefold("holes", l_hole)
    holes = b.transform("holes_body_centring", axes, **bc)
    o_outer = b.object("object_outer", balls)
    o_inner = b.object("object_inner", inners)
    o_holes = b.object("object_holes", holes, extrusion="normal")
    shells = b.csg("shells", [o_outer, o_inner], "difference")
    b.voxel("voxel", b.csg("pierced_shells", [shells, o_holes], "difference"))
    return b


def bandgap() -> GraphBuilder:
    mass_d, mass_h = 0.34, 0.16
    b = GraphBuilder(
        "bandgap", title="Phononic metastructure (local resonators)", source="after Muhammad & Lim "
        "2021, 'Phononic metastructures with ultrawide low frequency three-dimensional bandgaps'",
        paper_nodes=30,
        description="An elastic frame with rigid cylindrical masses: thick struts along the cell "
                    "edges, a disc-shaped mass at every face centre, and thin tapered braces from "
                    "the face corners to the mass (the springs of a mass-spring chain). Frame, "
                    "springs and masses are three Objects (the masses with flat, normal-extruded "
                    "ends) joined by a CSG union.")
    corner = b.vertex("v_corner", [0, 0, 0])
    edge_end = b.vertex("v_edge_end", [1, 0, 0])
    face = b.vertex("v_face_centre", [0.5, 0.5, 0])
    m_lo = b.vertex("v_mass_bottom", [0.5, 0.5, -mass_h / 2.0])
    m_hi = b.vertex("v_mass_top", [0.5, 0.5, mass_h / 2.0])
    e_edge = b.chain("e_edge", [corner, edge_end])
    e_brace = b.chain("e_brace", [corner, face])
    e_mass = b.chain("e_mass_axis", [m_lo, m_hi])
    l_edge = b.line("l_frame_edge", [e_edge], [[0, 0.09], [1, 0.09]])
    l_brace = b.line("l_brace", [e_brace], [[0, 0.06], [0.5, 0.045], [1, 0.06]])
    l_mass = b.line("l_mass", [e_mass], [[0, mass_d], [1, mass_d]])
    frame = b.threefold("frame", l_edge)
    face_axis = dict(axis=[0, 0, 1], origin=[0.5, 0.5, 0])
    braces = b.transform("brace_rot90", l_brace, angle=90.0, **face_axis)
    braces = b.transform("brace_rot180", braces, angle=180.0, **face_axis)
    springs = b.threefold("springs", braces)
    masses = b.threefold("masses", l_mass)
    o_frame = b.object("object_frame", frame)
    o_springs = b.object("object_springs", springs)
    o_masses = b.object("object_masses", masses, extrusion="normal")
    b.voxel("voxel", b.csg("union", [o_frame, o_springs, o_masses], "union"))
    return b


EXAMPLES: dict[str, Callable[[], GraphBuilder]] = {
    "octet": octet,
    "bcc": bcc,
    "fcc_lattice": fcc_lattice,
    "auxetic3d": auxetic3d,
    "anti_chiral": anti_chiral,
    "assembled": assembled,
    "assembled2": assembled2,
    "assembled3": assembled3,
    "twist_tilable": twist_tilable,
    "six_hole_bcc": six_hole_bcc,
    "bandgap": bandgap,
}


# =============================================================== property examples
#
# A unit cell followed by a Material Matrix node (paper section 6.6): the
# window's material sphere and Material Matrix dock show its stiffness as soon
# as the example is open.

STIFFNESS_RESOLUTION = 48       # voxels per cell edge of the homogenization solve


def octet_stiffness() -> GraphBuilder:
    b = octet()
    b.name = "octet_stiffness"
    b.meta.update(example="octet_stiffness", title="Octet truss: stiffness", paper_node_count=None,
                  description="The octet truss of the lattice examples followed by a Material Matrix "
                              "node: periodic homogenization of the voxelized cell gives its "
                              "effective stiffness tensor C (cubic symmetry), the engineering "
                              "constants and the directional Young's modulus drawn as the material "
                              "sphere.")
    b.material_matrix("stiffness", "voxel", resolution=STIFFNESS_RESOLUTION)
    return b


def schwarz_p_stiffness():
    from surface_examples import schwarz_p

    b = schwarz_p()
    b.name = "schwarz_p_stiffness"
    b.meta.update(example="schwarz_p_stiffness", title="Schwarz P shell: stiffness", paper_node_count=None,
                  description="The Schwarz P shell of the TPMS examples followed by a Material Matrix "
                              "node: the stiffness tensor of a thin minimal-surface shell, cubic like "
                              "the octet but far more isotropic (compare their material spheres).")
    b.material_matrix("stiffness", "voxel", resolution=STIFFNESS_RESOLUTION)
    return b


PROPERTY_EXAMPLES: dict[str, Callable] = {
    "octet_stiffness": octet_stiffness,
    "schwarz_p_stiffness": schwarz_p_stiffness,
}


def write_property_examples(out_dir: str | Path = EXAMPLES_DIR, names=None) -> dict[Path, GraphDocument]:
    """Build the property examples (all, or `names`) as ``<out_dir>/<name>.json``."""
    return write_documents({n: (lambda n=n: PROPERTY_EXAMPLES[n]().document()) for n in PROPERTY_EXAMPLES},
                           out_dir, names)


# =============================================================== virtual growth examples
#
# Tile sets grown by wave-function collapse (Liu, Sun & Daraio 2022, virtual growth),
# each Grow node followed by Tiling Properties, so the Virtual Growth dock
# shows the tiling, its block mix and its stiffness when the example opens.

def _arranged(ids: list[str], edges: list[tuple[str, str]]) -> dict[str, tuple[float, float]]:
    """Positions in readable columns, wrapped into bands that fit the default node editor."""
    bands = fit_columns(ids, edges, EDITOR_VIEW, column_width=COLUMN_WIDTH, row_height=ROW_HEIGHT)
    return layered_positions(ids, edges, column_width=COLUMN_WIDTH, row_height=ROW_HEIGHT, max_columns=bands)


def _growth_document(name: str, meta: dict, tileset: str, grow: dict, *, three_d: bool) -> GraphDocument:
    doc = GraphDocument(seed=0)
    doc.meta = {"example": name, "source": "Liu, Sun & Daraio 2022 (virtual growth)",
                "paper_node_count": None, **meta}
    show = ("beams", "TilingBeams", "skeleton") if three_d else ("image", "TilingImage", "image")
    nodes = [("tileset", "TileSet", {"name": tileset}), ("grow", "Grow", grow),
             (show[0], show[1], {}), ("properties", "TilingProperties", {})]
    edges = [("tileset", "tileset", "grow", "tileset"), ("grow", "tiling", show[0], "tiling"),
             ("grow", "tiling", "properties", "tiling")]
    pos = _arranged([n[0] for n in nodes], [(e[0], e[2]) for e in edges])
    stack = UndoStack(doc)
    for node_id, type_name, params in nodes:
        stack.push(AddNode(type_name, params, pos[node_id], node_id=node_id))
    for edge in edges:
        stack.push(Connect(*edge))
    return doc


def growth_tl_2d() -> GraphDocument:
    return _growth_document("growth_tl_2d", {
        "title": "Virtual growth: TL+- tiling",
        "description": "A periodic 16 x 16 tiling of the TL+- blocks (T, L, straight and cross "
                       "beams) grown by minimal-entropy wave-function collapse under the set's "
                       "adjacency rules and weights. Tiling Image draws it; Tiling Properties "
                       "homogenizes the pixel image in plane stress. Change the seed or the hints "
                       "in the Virtual Growth dock and watch the stiffness follow; the Study dock "
                       "runs the same grid as a property study."},
        "TL+-", {"size": [16, 16]}, three_d=False)


def growth_tl_hints() -> GraphDocument:
    return _growth_document("growth_tl_hints", {
        "title": "Virtual growth: hinted towards + and -",
        "description": "The TL+- set on the same 16 x 16 grid, with frequency hints "
                       "T=1,L=1,+=3,-=2 that favour the cross and straight blocks. More "
                       "continuous load paths: compare its stiffness with the unhinted example."},
        "TL+-", {"size": [16, 16], "hints": "T=1,L=1,+=3,-=2"}, three_d=False)


def growth_cubic_3d() -> GraphDocument:
    return _growth_document("growth_cubic_3d", {
        "title": "Virtual growth: 3D cubic beams",
        "description": "A periodic 4 x 4 x 4 tiling of the cubic-beams set (3D cross, planar cross, "
                       "T, Y, L and straight junctions). Tiling Beams turns it into a beam "
                       "skeleton; Tiling Properties voxelizes the beams and homogenizes them in 3D."},
        "cubic-beams", {"size": [4, 4, 4]}, three_d=True)


GROWTH_EXAMPLES: dict[str, Callable[[], GraphDocument]] = {
    "growth_tl_2d": growth_tl_2d,
    "growth_tl_hints": growth_tl_hints,
    "growth_cubic_3d": growth_cubic_3d,
}


def write_growth_examples(out_dir: str | Path = EXAMPLES_DIR, names=None) -> dict[Path, GraphDocument]:
    """Build the virtual growth examples (all, or `names`) as ``<out_dir>/<name>.json``."""
    return write_documents(GROWTH_EXAMPLES, out_dir, names)


# =============================================================== phasor infill examples
#
# Not unit cells: a part's box filled with phasor-noise diamond cells (Tricard
# et al. 2020), seeded from a field spec and painted with brush strokes, each
# stroke one SetParam of the whole stroke list as the window's paint canvas does.

def phasor_slab() -> GraphDocument:
    import json
    import math

    from engine.graph import SetParam
    from engine.phasor.strokes import Stroke

    doc = GraphDocument(seed=0)
    doc.meta = {"example": "phasor_slab", "title": "Phasor infill: painted slab",
                "source": "Tricard et al. 2020 (phasor infill)", "paper_node_count": None,
                "description": "A 30 x 30 x 6 mm slab of diamond cells. D starts vertical (cells "
                               "lined up with x and y in every layer) and F falls from 1 cell/mm at "
                               "the centre to 0.7 at 15 mm. Brush strokes then tilt D along a curved "
                               "drag (the cells turn to follow it), tilt it diagonally in a corner, "
                               "raise F along the bottom edge and add angular spread on the right. "
                               "The slice shows the layer at mid height."}
    spec = {"D": [0.0, 0.0, 1.0],
            "F": {"kind": "radial", "axis": "z", "centre": [0.0, 0.0, 0.0], "from": 1.0, "to": 0.7,
                  "radius": 15.0},
            "Gamma": 0.0}
    stack = UndoStack(doc)
    pos = _arranged(["fields", "noise", "slice"], [("fields", "noise"), ("noise", "slice")])
    stack.push(AddNode("PhasorFields", {"lo": [-15.0, -15.0, 0.0], "hi": [15.0, 15.0, 6.0],
                                        "resolution": 64, "spec": json.dumps(spec)},
                       pos["fields"], node_id="fields"))
    stack.push(AddNode("PhasorNoise", {}, pos["noise"], node_id="noise"))
    stack.push(AddNode("PhasorSlice", {"position": 3.0, "pixel": 0.1}, pos["slice"], node_id="slice"))
    stack.push(Connect("fields", "fields", "noise", "fields"))
    stack.push(Connect("noise", "infill", "slice", "infill"))
    arc = [[_r(8.0 * math.cos(math.radians(a))), _r(8.0 * math.sin(math.radians(a)))]
           for a in range(200, 341, 20)]
    tilt = 1.1  # radians out of the slice plane: D leans 27 degrees from vertical
    strokes = [
        Stroke("D", "z", 3.0, arc, 4.0, tilt=tilt, depth=4.0),
        Stroke("D", "z", 3.0, [[-9.0, 9.0], [-6.0, 6.0]], 5.0, heading=[1.0, 1.0], tilt=tilt, depth=4.0),
        Stroke("F", "z", 3.0, [[-12.0, -13.0], [12.0, -13.0]], 2.5, value=1.2, depth=4.0),
        Stroke("Gamma", "z", 3.0, [[11.0, 2.0], [11.0, 10.0]], 3.0, value=0.3, falloff="linear", depth=4.0),
    ]
    for stroke in strokes:  # one SetParam per stroke, as the paint canvas pushes them
        painted = doc.node("fields").params["strokes"]
        stack.push(SetParam("fields", "strokes", painted + [stroke.to_dict()]))
    return doc


PHASOR_EXAMPLES: dict[str, Callable[[], GraphDocument]] = {
    "phasor_slab": phasor_slab,
}


def write_phasor_examples(out_dir: str | Path = EXAMPLES_DIR, names=None) -> dict[Path, GraphDocument]:
    """Build the phasor infill examples (all, or `names`) as ``<out_dir>/<name>.json``."""
    return write_documents(PHASOR_EXAMPLES, out_dir, names)


# =============================================================== reaction-diffusion examples
#
# Not unit cells: a topology-optimised part filled with lattices grown by
# anisotropic Gray-Scott reaction-diffusion along its principal stress
# directions (Garnier, Schmidt & Rohmer 2022).  A painted solid region is one
# SetParam of the whole stamp list, as the RD dock pushes it.

def rd_cantilever() -> GraphDocument:
    from engine.graph import SetParam

    doc = GraphDocument(seed=0)
    doc.meta = {"example": "rd_cantilever", "title": "Reaction-diffusion: stress-aligned cantilever",
                "source": "Garnier, Schmidt & Rohmer 2022 (reaction-diffusion growth)", "paper_node_count": None,
                "description": "A 2:1 cantilever clamped on the left and loaded at the middle of its right "
                               "edge, optimised by SIMP on 64 x 32 elements (volume fraction 0.4). Its "
                               "principal stress directions, regularised, orient one Gray-Scott growth per "
                               "direction on a 640 x 320 grid from a seed at the middle of the part; a "
                               "painted solid region keeps the load point full. The compiled lattice is "
                               "the union of the two stripe families at iso 0.7 (paper Fig. 11)."}
    stack = UndoStack(doc)
    pos = _arranged(["topopt", "fields", "grow", "compile"],
                    [("topopt", "fields"), ("fields", "grow"), ("grow", "compile")])
    stack.push(AddNode("TopOpt", {"preset": "cantilever", "resolution": [64, 32], "max_iter": 60},
                       pos["topopt"], node_id="topopt"))
    stack.push(AddNode("RDFields", {"regularise": True, "coherence": True}, pos["fields"], node_id="fields"))
    stack.push(AddNode("RDGrow", {"resolution": [640, 320], "max_steps": 20000}, pos["grow"], node_id="grow"))
    stack.push(AddNode("RDCompile", {"iso": 0.7}, pos["compile"], node_id="compile"))
    stack.push(Connect("topopt", "design", "fields", "design"))
    stack.push(Connect("fields", "rdfields", "grow", "rdfields"))
    stack.push(Connect("grow", "structures", "compile", "structures"))
    # the load point, painted solid in cells of the 64 x 32 design grid
    stroke = [{"centre": [62.0, y], "radius": 2.5, "value": 1.0} for y in (14.5, 16.0, 17.5)]
    stack.push(SetParam("fields", "gamma_c", doc.node("fields").params["gamma_c"] + [stroke]))
    return doc


RD_EXAMPLES: dict[str, Callable[[], GraphDocument]] = {
    "rd_cantilever": rd_cantilever,
}


def write_rd_examples(out_dir: str | Path = EXAMPLES_DIR, names=None) -> dict[Path, GraphDocument]:
    """Build the reaction-diffusion examples (all, or `names`) as ``<out_dir>/<name>.json``."""
    return write_documents(RD_EXAMPLES, out_dir, names)


def build(name: str) -> GraphDocument:
    """The example `name` as a fresh GraphDocument."""
    return EXAMPLES[name]().document()


def write_examples(out_dir: str | Path = EXAMPLES_DIR, names=None) -> dict[Path, GraphDocument]:
    """Build the examples (all, or `names`) and save each as ``<out_dir>/<name>.json``."""
    return write_documents({name: (lambda n=name: build(n)) for name in EXAMPLES}, out_dir, names)


def _surface_examples():
    """The Table 2/3 surface examples live in tools/surface_examples.py."""
    from surface_examples import EXAMPLES as surface_examples, write_surface_examples
    return surface_examples, write_surface_examples


SURFACE_EXAMPLES, write_surface_examples = _surface_examples()


def _implicit_examples():
    """The implicit media examples live in tools/implicit_examples.py."""
    from implicit_examples import IMPLICIT_EXAMPLES, write_implicit_examples
    return IMPLICIT_EXAMPLES, write_implicit_examples


IMPLICIT_EXAMPLES, write_implicit_examples = _implicit_examples()


def all_writers() -> dict[str, tuple[dict, Callable]]:
    """Every example generator: ``{kind: (its builders by name, its writer)}``."""
    return {"cells": (EXAMPLES, write_examples), "properties": (PROPERTY_EXAMPLES, write_property_examples),
            "growth": (GROWTH_EXAMPLES, write_growth_examples), "phasor": (PHASOR_EXAMPLES, write_phasor_examples),
            "rd": (RD_EXAMPLES, write_rd_examples), "surfaces": (SURFACE_EXAMPLES, write_surface_examples),
            "implicit": (IMPLICIT_EXAMPLES, write_implicit_examples)}


def write_all(out_dir: str | Path = EXAMPLES_DIR, names=None) -> dict[Path, GraphDocument]:
    """Build every example (or those in `names`) into `out_dir`."""
    written: dict[Path, GraphDocument] = {}
    for builders, writer in all_writers().values():
        picked = [n for n in names or builders if n in builders]
        if picked:
            written.update(writer(out_dir, picked))
    return written


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(EXAMPLES_DIR), help="output folder (default: resources/examples)")
    parser.add_argument("--only", nargs="+",
                        choices=sorted(n for builders, _ in all_writers().values() for n in builders),
                        help="build only these examples")
    args = parser.parse_args(argv)
    for path, doc in write_all(args.out, args.only).items():
        paper = doc.meta.get("paper_node_count")
        print(f"{path}  ({len(doc.nodes)} nodes; paper: {paper if paper is not None else '-'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
