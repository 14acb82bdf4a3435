"""Material Matrix in the window: stiffness panel in the inspector, material sphere in the viewport.

The cell is three orthogonal beams of diameter 0.3 through the cell centre
(a beam along x, copied by 120 and 240 degree turns about the body
diagonal).  One beam alone is a mechanism (C is singular: no compliance, no
sphere), and struts that stop short of the cell faces carry no load (the
node fails); the second test uses both.  Expected numbers come from numpy on
the reported C, not from the display code.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from PySide6 import QtCore, QtWidgets

from engine.graph import AddNode, Connect, Disconnect, SetParam

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

ICOSPHERE_POINTS = 10 * 4 ** 4 + 2  # subdivision 4
SOLVE_TIMEOUT_MS = 600_000           # the solve is seconds to minutes on a loaded CI machine


def build_cross_graph(undo, mm_resolution=8):
    """Vertex x2 -> EdgeChain -> Line (beam along x, diameter 0.3) -> Transform x2 (copies
    about the body diagonal) -> Object (24) -> Voxel -> MaterialMatrix; returns the ids."""
    ids = {}
    ids["v1"] = undo.push(AddNode("Vertex", {"position": [0.0, 0.5, 0.5]}, (0, 0))).node_id
    ids["v2"] = undo.push(AddNode("Vertex", {"position": [1.0, 0.5, 0.5]}, (0, 160))).node_id
    ids["e"] = undo.push(AddNode("EdgeChain", {}, (240, 80))).node_id
    undo.push(Connect(ids["v1"], "point", ids["e"], "vertices"))
    undo.push(Connect(ids["v2"], "point", ids["e"], "vertices"))
    ids["l"] = undo.push(AddNode("Line", {"thickness": [[0.0, 0.3], [1.0, 0.3]]}, (480, 80))).node_id
    undo.push(Connect(ids["e"], "chain", ids["l"], "chains"))
    ids["t1"] = undo.push(AddNode("Transform", {"rotation_angle": 120.0, "rotation_axis": [1, 1, 1]},
                                  (720, 80))).node_id
    ids["t2"] = undo.push(AddNode("Transform", {"rotation_angle": 240.0, "rotation_axis": [1, 1, 1]},
                                  (960, 80))).node_id
    undo.push(Connect(ids["l"], "skeleton", ids["t1"], "skeleton"))
    undo.push(Connect(ids["t1"], "skeleton", ids["t2"], "skeleton"))
    ids["obj"] = undo.push(AddNode("Object", {"resolution": 24}, (1200, 80))).node_id
    undo.push(Connect(ids["t2"], "skeleton", ids["obj"], "skeleton"))
    ids["vox"] = undo.push(AddNode("Voxel", {}, (1440, 80))).node_id
    undo.push(Connect(ids["obj"], "solid", ids["vox"], "solid"))
    ids["mm"] = undo.push(AddNode("MaterialMatrix", {"resolution": mm_resolution}, (1680, 80))).node_id
    undo.push(Connect(ids["vox"], "voxels", ids["mm"], "voxels"))
    return ids


def shown_within_precision(shown, exact: float, exponent: int = 0) -> bool:
    """`shown` (text such as "3.498", "0.01653", "2.5e-7") times 10**`exponent` is
    `exact` to the digits it shows (half a unit in its last place)."""
    mantissa, _, power = str(shown).partition("e")
    decimals = len(mantissa.partition(".")[2])
    value = float(shown) * 10.0 ** exponent
    half_ulp = 0.5 * 10.0 ** (int(power or 0) + exponent - decimals)
    return abs(value - exact) <= half_ulp * (1 + 1e-9)


def table_exponent(panel) -> int:
    """The power of ten the matrix title applies to the table ("C (×10⁻² Pa)")."""
    found = re.search(r"×10([⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)", panel.matrix_title.text())
    return int(found.group(1).translate(str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789"))) if found else 0


def table_shows(panel, row: int, column: int, exact: float) -> bool:
    """Entry (row, column) of the panel's table, as a user reads it, is `exact`."""
    return shown_within_precision(panel.cell_text(row, column), exact, table_exponent(panel))


def young_along(C: np.ndarray, d: np.ndarray) -> np.ndarray:
    """E(d) = 1 / (d d : S : d d) for unit rows of `d`, written out for Voigt order
    xx yy zz yz xz xy with engineering shear strains: 1/E = n.S.n, n = (x², y², z², yz, xz, xy)."""
    S = np.linalg.inv(C)
    x, y, z = d.T
    n = np.stack([x * x, y * y, z * z, y * z, x * z, x * y], axis=1)
    return 1.0 / np.einsum("ia,ab,ib->i", n, S, n)


def sphere_mesh(window):
    actor = window.viewport.plotter.actors.get("material_sphere")
    return None if actor is None else actor.mapper.dataset


def test_panel_and_material_sphere(window, qtbot, wait_eval):
    ids = build_cross_graph(window.undo, mm_resolution=8)
    report = wait_eval(window, 0, timeout=SOLVE_TIMEOUT_MS)   # also loads / compiles the kernels
    assert report.ok, report.errors

    # A finer solve: the GUI thread keeps running while the worker homogenizes.
    shown = []                                   # the progress text at each GUI heartbeat
    timer = QtCore.QTimer()
    timer.timeout.connect(lambda: shown.append(window.progress.format()))
    timer.start(20)
    n = window.eval_count
    window.undo.push(SetParam(ids["mm"], "resolution", 16))
    report = wait_eval(window, n, timeout=SOLVE_TIMEOUT_MS)
    timer.stop()
    assert report.ok, report.errors
    assert report.results[ids["mm"]].status == "evaluated"
    assert report.results[ids["obj"]].status == "cached"
    # Progress texts "mat1: 40% ..." are only shown while the node runs; a solve on
    # the GUI thread would let no heartbeat through until it ended.
    during = [fmt for fmt in shown if fmt.startswith(f"{ids['mm']}: ") and "%" in fmt]
    assert len(during) >= 1, sorted(set(shown))

    st = report.outputs[ids["mm"]]["stiffness"]
    C = np.asarray(st.C)
    assert st.resolution == 16

    # -- inspector panel ------------------------------------------------------------------
    inspector = window.inspector
    window.editor.select(ids["vox"])
    assert not inspector.stiffness_panel.isVisibleTo(inspector)
    window.editor.select(ids["mm"])
    panel = inspector.stiffness_panel
    assert panel.isVisibleTo(inspector)
    assert panel.table.horizontalHeaderItem(3).text() == "yz"
    assert panel.table.verticalHeaderItem(5).text() == "xy"
    assert "engineering" in panel.table.toolTip()
    assert table_shows(panel, 0, 0, C[0, 0])
    assert len(panel.cell_text(0, 0).lstrip("-0.").replace(".", "")) >= 4   # C11 is the largest entry
    assert table_shows(panel, 3, 3, C[3, 3])
    assert table_shows(panel, 0, 1, C[0, 1])
    assert st.symmetry and panel.value_text("symmetry") == st.symmetry
    assert panel.values["zener"].isVisibleTo(panel) == (st.symmetry == "cubic")
    if st.symmetry == "cubic":
        assert shown_within_precision(panel.value_text("zener"), 2 * C[3, 3] / (C[0, 0] - C[0, 1]))
    assert not panel.note.isVisibleTo(panel)              # C is positive definite
    S = np.linalg.inv(C)
    assert shown_within_precision(panel.value_text("E_x"), 1 / S[0, 0])
    assert shown_within_precision(panel.value_text("nu_xy"), -S[0, 1] / S[0, 0])
    assert shown_within_precision(panel.value_text("G_xy"), 1 / S[5, 5])
    assert panel.value_text("resolution").startswith("16")
    panel.compliance_toggle.click()                        # show S instead
    assert table_shows(panel, 0, 0, S[0, 0])
    assert panel.matrix_title.text().startswith("<b>S")
    panel.compliance_toggle.click()
    assert table_shows(panel, 0, 0, C[0, 0])
    panel.copy_button.click()
    copied = json.loads(QtWidgets.QApplication.clipboard().text())
    assert np.allclose(copied["C"], C, rtol=1e-12, atol=0)
    assert copied["symmetry"] == st.symmetry

    # -- material sphere ------------------------------------------------------------------
    assert window.shown_stiffness_id == ids["mm"]
    mesh = sphere_mesh(window)
    assert mesh is not None
    assert mesh.n_points == ICOSPHERE_POINTS == window.viewport.sphere_point_count()
    assert "E(d)" in window.viewport.plotter.scalar_bars
    centre = np.array([mesh.bounds[0] + mesh.bounds[1], mesh.bounds[2] + mesh.bounds[3],
                       mesh.bounds[4] + mesh.bounds[5]]) / 2
    assert mesh.bounds[0] > 1.0                           # right of the unit cell [0, 1]^3
    radial = np.asarray(mesh.points) - centre
    r = np.linalg.norm(radial, axis=1)
    assert r.max() == pytest.approx(0.5, rel=1e-6)        # half the block edge
    expected = young_along(C, radial / r[:, None])
    assert np.allclose(mesh["E"], expected, rtol=1e-6)
    assert np.allclose(r / r.max(), expected / expected.max(), rtol=1e-6)   # radius follows E(d)

    window.act_tiling.setChecked(True)                    # 3x3x3 block spans [-1, 2]
    mesh = sphere_mesh(window)
    assert mesh.bounds[0] > 2.0
    assert (mesh.bounds[1] - mesh.bounds[0]) / 2 <= 1.5 * (1 + 1e-9)
    window.act_tiling.setChecked(False)

    window.act_sphere.setChecked(False)
    assert sphere_mesh(window) is None and window.viewport.sphere_point_count() == 0
    assert "E(d)" not in window.viewport.plotter.scalar_bars
    assert window.viewport.mesh_point_count() > 0         # the structure stays
    window.act_sphere.setChecked(True)
    assert sphere_mesh(window).n_points == ICOSPHERE_POINTS

    # -- undo the node (resolution edit, connection, addition): the sphere goes at once ----
    for _ in range(3):
        window.undo_edit()
    assert ids["mm"] not in window.doc.nodes
    assert sphere_mesh(window) is None
    assert not panel.isVisibleTo(inspector)
    n = window.eval_count
    wait_eval(window, n)
    assert sphere_mesh(window) is None and window.shown_stiffness_id is None


def test_sphere_follows_reevaluation_and_failure(window, wait_eval):
    ids = build_cross_graph(window.undo, mm_resolution=8)
    report = wait_eval(window, 0, timeout=SOLVE_TIMEOUT_MS)
    assert report.ok, report.errors
    window.editor.select(ids["mm"])
    panel = window.inspector.stiffness_panel
    first = np.array(sphere_mesh(window)["E"])
    c00 = report.outputs[ids["mm"]]["stiffness"].C[0, 0]

    n = window.eval_count                                 # thicker beams: stiffer cell
    window.undo.push(SetParam(ids["l"], "thickness", [[0.0, 0.4], [1.0, 0.4]]))
    report = wait_eval(window, n, timeout=SOLVE_TIMEOUT_MS)
    assert report.ok, report.errors
    C = np.asarray(report.outputs[ids["mm"]]["stiffness"].C)
    assert C[0, 0] > c00
    mesh = sphere_mesh(window)
    second = np.array(mesh["E"])
    assert second.max() > first.max()
    radial = np.asarray(mesh.points) - np.asarray(mesh.center)
    assert np.allclose(second, young_along(C, radial / np.linalg.norm(radial, axis=1)[:, None]), rtol=1e-6)
    assert table_shows(panel, 0, 0, C[0, 0])

    # One beam alone is a mechanism: singular C, so no sphere (whether the node
    # reports the singular C or refuses it).
    n = window.eval_count
    window.undo.push(Disconnect(ids["t2"], "skeleton", ids["obj"], "skeleton"))
    window.undo.push(Connect(ids["l"], "skeleton", ids["obj"], "skeleton"))
    report = wait_eval(window, n, timeout=SOLVE_TIMEOUT_MS)
    assert sphere_mesh(window) is None and window.viewport.sphere_point_count() == 0
    assert window.viewport.mesh_point_count() > 0         # the beam itself is still drawn
    if report.results[ids["mm"]].status == "evaluated":
        C = np.asarray(report.outputs[ids["mm"]]["stiffness"].C)
        assert np.linalg.eigvalsh(C)[0] <= 1e-6 * np.linalg.eigvalsh(C)[-1]
        assert panel.isVisibleTo(window.inspector)
        assert panel.note.isVisibleTo(panel)
        assert not panel.compliance_toggle.isEnabled()
        assert table_shows(panel, 0, 0, C[0, 0])
    else:
        assert not panel.isVisibleTo(window.inspector)
    window.undo_edit()
    window.undo_edit()

    # Struts that stop short of the cell faces carry no load: the node fails.
    n = window.eval_count
    window.undo.push(SetParam(ids["v1"], "position", [0.3, 0.5, 0.5]))
    window.undo.push(SetParam(ids["v2"], "position", [0.7, 0.5, 0.5]))
    report = wait_eval(window, n, timeout=SOLVE_TIMEOUT_MS)
    assert report.results[ids["mm"]].status == "failed"
    assert ids["mm"] in report.errors
    assert sphere_mesh(window) is None and window.shown_stiffness_id is None
    assert not panel.isVisibleTo(window.inspector)
    assert "failed" in window.inspector.status_text()

    n = window.eval_count                                 # undo: the sphere and the panel come back
    window.undo_edit()
    window.undo_edit()
    report = wait_eval(window, n, timeout=SOLVE_TIMEOUT_MS)
    assert report.ok, report.errors
    assert sphere_mesh(window).n_points == ICOSPHERE_POINTS
    assert panel.isVisibleTo(window.inspector)
    assert not panel.note.isVisibleTo(panel)


def test_2d_tiling_stiffness_draws_its_polar_curve(window, qtbot, wait_eval):
    # The 2D counterpart of the material sphere: E(theta) of a plane-stress C as a
    # closed curve beside the cell, coloured by E; radii follow 1 / (n.S.n).
    from engine.graph import AddNode, Connect
    u = window.undo
    u.push(AddNode("TileSet", node_id="ts"))
    u.push(AddNode("Grow", {"size": [4, 4]}, node_id="grow"))
    u.push(AddNode("TilingProperties", node_id="props"))
    u.push(Connect("ts", "tileset", "grow", "tileset"))
    u.push(Connect("grow", "tiling", "props", "tiling"))
    report = wait_eval(window, 0, timeout=SOLVE_TIMEOUT_MS)
    assert report.ok, report.errors
    C = np.asarray(report.outputs["props"]["stiffness"].C)
    assert C.shape == (3, 3)
    curve = sphere_mesh(window)
    assert curve is not None and curve.n_lines > 0 and curve.n_points == 361
    S = np.linalg.inv(C)
    t = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    n = np.stack([np.cos(t) ** 2, np.sin(t) ** 2, np.cos(t) * np.sin(t)], axis=1)
    expect = 1.0 / np.einsum("ia,ab,ib->i", n, S, n)
    np.testing.assert_allclose(np.asarray(curve["E"])[:360], expect, rtol=1e-9)
    # the inspector shows the 3x3 plane-stress C as a table too
    window.editor.select("props")
    panel = window.inspector.stiffness_panel
    assert panel.isVisibleTo(window.inspector)
    assert panel.table.rowCount() == 3 and panel.table.horizontalHeaderItem(2).text() == "xy"
    assert table_shows(panel, 0, 0, C[0, 0]) and table_shows(panel, 2, 2, C[2, 2])
