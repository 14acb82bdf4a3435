"""PhasorInfillSession: the one way phasor infill runs (nodes, dock, command line).

Strokes applied through the session give the bytes the nodes give with the
same strokes in their parameters; a session is a value; its slices are the
engine's slices.
"""

import json

import numpy as np
import pytest
import trimesh

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack
from engine.graph.node import node_seed, node_type
from engine.nodes.phasor_session import PhasorInfillSession, diamonds_png
from engine.phasor.preview import slice_plane
from engine.phasor.strokes import Stroke

SPEC = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 60, "centre": [4.0, 4.0, 0.0]},
        "F": {"kind": "linear", "axis": "x", "from": 1.0, "to": 1.4}}
STROKE_F = {"field": "F", "axis": "z", "position": 1.0, "points": [[2.0, 2.0], [4.0, 3.0]],
            "radius": 1.2, "value": 1.6}
STROKE_D = {"field": "D", "axis": "z", "position": 1.0, "points": [[5.0, 6.0], [7.0, 6.5]],
            "radius": 1.0, "strength": 0.7}
FIELDS = {"lo": [0.0, 0.0, 0.0], "hi": [8.0, 8.0, 2.0], "resolution": 16, "spec": json.dumps(SPEC)}
NOISE = {"iterations": 4}


def _doc(strokes=(), *, mesh=None):
    doc = GraphDocument(seed=11)
    st = UndoStack(doc)
    st.push(AddNode("PhasorFields", {**FIELDS, "strokes": list(strokes)}, node_id="f"))
    st.push(AddNode("PhasorNoise", NOISE, node_id="n"))
    st.push(Connect("f", "fields", "n", "fields"))
    if mesh is not None:
        st.push(AddNode("MeshImport", {"path": str(mesh)}, node_id="m"))
        st.push(Connect("m", "mesh", "f", "domain"))
    return doc, st


def _params(type_name, params):
    return node_type(type_name).validate_params(params)


def _kernel_bytes(infill):
    k = infill.kernels
    return [np.asarray(a).tobytes() for a in (k.positions, k.frequency, k.direction_v, k.direction_w,
                                              k.phase_v, k.phase_w, k.spread_u)] + \
        [np.asarray(infill.attenuation).tobytes()]


def _field_bytes(fields):
    return [np.asarray(a).tobytes() for a in (fields.direction, fields.frequency, fields.spread)]


@pytest.fixture(scope="module")
def fresh():
    """The two nodes evaluated from scratch, and the session of the same parameters."""
    doc, _ = _doc()
    report = Evaluator().evaluate(doc)
    session = PhasorInfillSession.from_params(_params("PhasorFields", FIELDS), _params("PhasorNoise", NOISE),
                                              seed=node_seed(doc.seed, "n"))
    return report.output("n"), session


def test_from_params_is_a_fresh_evaluation_of_the_nodes(fresh):
    infill, session = fresh
    assert _field_bytes(session.fields) == _field_bytes(infill.fields)
    assert _kernel_bytes(session.infill) == _kernel_bytes(infill)
    assert session.infill.iterations == infill.iterations == NOISE["iterations"]


def test_strokes_through_the_session_equal_the_node_with_the_strokes_in_its_params(fresh):
    # the window: evaluate, paint one stroke (pushed as SetParam), evaluate again (the stateful path)
    doc, st = _doc()
    ev = Evaluator()
    ev.evaluate(doc)
    st.push(SetParam("f", "strokes", [STROKE_F]))
    node_infill = ev.evaluate(doc).output("n")
    st.push(SetParam("f", "strokes", [STROKE_F, STROKE_D]))
    node_infill_2 = ev.evaluate(doc).output("n")

    _, session = fresh
    after = session.apply_stroke(Stroke.from_dict(STROKE_F))
    assert after.touched and after.infill is session.infill      # the infill follows on update
    updated = after.update()
    assert _field_bytes(updated.fields) == _field_bytes(node_infill.fields)
    assert _kernel_bytes(updated.infill) == _kernel_bytes(node_infill)
    again = updated.apply_stroke(Stroke.from_dict(STROKE_D)).update()
    assert _kernel_bytes(again.infill) == _kernel_bytes(node_infill_2)
    # painted fields equal a fresh PhasorFields evaluation with both strokes in its params
    fresh_doc, _ = _doc([STROKE_F, STROKE_D])
    assert _field_bytes(again.fields) == _field_bytes(Evaluator().evaluate(fresh_doc).output("f").fields)


def test_a_session_is_a_value(fresh):
    _, session = fresh
    before = _field_bytes(session.fields)
    painted = session.apply_stroke(Stroke.from_dict(STROKE_F))
    assert _field_bytes(session.fields) == before and not session.touched
    lo, hi = painted.painted_region()
    # the stroke's disc (radius 1.2 mm around its points) lies in the region
    assert lo[0] <= 2.0 - 1.2 and hi[0] >= 4.0 + 1.2 and lo[1] <= 2.0 - 1.2 and hi[1] >= 3.0 + 1.2
    nowhere = painted.apply_stroke(Stroke.from_dict({**STROKE_F, "points": [[50.0, 50.0]]}))
    assert not nowhere.touched


def test_update_refuses_another_grid_and_a_moved_kernel_radius(fresh):
    _, session = fresh
    other = PhasorInfillSession.from_params(_params("PhasorFields", {**FIELDS, "resolution": 12}))
    moved = PhasorInfillSession(other.fields, session.infill)
    assert not moved.can_update()
    with pytest.raises(ValueError, match="another grid"):
        moved.update()
    lower = session.apply_stroke(Stroke.from_dict({**STROKE_F, "value": 0.5}))   # F_min 1.0 -> 0.5
    assert not lower.can_update()
    assert session.apply_stroke(Stroke.from_dict(STROKE_F)).can_update()


def test_a_rectangle_of_a_slice_is_that_part_of_the_whole(fresh):
    _, session = fresh
    fields = session.fields
    plane = slice_plane(fields.lo, fields.hi, "z", 1.0, max_pixels=96)
    whole, used = session.slice(plane, "diamonds", engine="numpy")
    part, _ = session.slice(plane, "diamonds", (10, 40, 5, 30), engine="numpy")
    assert used == "numpy" and part.shape == (30, 25)
    assert np.array_equal(part, whole[10:40, 5:30])


def test_slice_energy_and_part_mask_are_the_slice_nodes(tmp_path):
    cube = trimesh.creation.box(extents=(6.0, 5.0, 1.6))
    cube.apply_translation((4.0, 4.0, 1.0))
    path = tmp_path / "part.stl"
    cube.export(path)
    doc, st = _doc(mesh=path)
    st.push(AddNode("PhasorSlice", {"position": 1.0, "pixel": 0.1, "engine": "numpy"}, node_id="s"))
    st.push(Connect("n", "infill", "s", "infill"))
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    session = PhasorInfillSession.of_infill(report.output("n"))
    result = session.slice_at("z", 1.0, 0.1, engine="numpy")
    assert session.energy(result) == report.output("s", "energy")
    assert np.array_equal(result.diamonds, report.output("s", "image").values > 0)
    inside = session.part_mask("z", 1.0, 0.1)
    assert np.array_equal(inside, result.inside) and 0 < inside.mean() < 1
    with pytest.raises(ValueError, match="position"):
        session.check_slice("z", 9.0, 0.1)
    with pytest.raises(ValueError, match="pixel"):
        session.check_pixel(0.5)


def test_diamonds_png_is_black_cells_on_white_with_v_up():
    from io import BytesIO

    from PIL import Image

    image = np.zeros((3, 4))
    image[0, 1] = 1.0                 # row 0 runs along v = lowest: the picture's bottom row
    img = np.asarray(Image.open(BytesIO(diamonds_png(image))))
    assert img.shape == (3, 4) and img[2, 1] == 0 and (img == 255).sum() == 11


def test_print_paths_come_from_the_export_pixel(fresh):
    from engine.fab import PrintSettings

    _, session = fresh
    assert session.export_pixel() == pytest.approx(min(0.1, 1 / (4 * session.fields.max_frequency())))
    settings = PrintSettings(layer_height=0.4)
    assert session.layer_count(0.4) == 5
    layers = session.toolpaths(settings, pixel=0.1, engine="numpy")
    assert len(layers) == 5 and all(layer.paths for layer in layers)
