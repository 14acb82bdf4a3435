"""Node types' memory estimates, and the evaluator refusing before allocating."""

import math
import tracemalloc

import numpy as np
import pytest

from engine.geometry.voxel_inputs import SOLVER_BYTES_PER_DOF, memory_estimate_bytes
from engine.graph import Evaluator, node_type
from engine.growth import load_tileset
from engine.nodes.solids import OBJECT_BYTES_PER_POINT, ObjectNode
from tests.app.graphs import straight_beam_graph


def test_default_estimate_is_zero_and_never_refused(monkeypatch):
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "1")
    cls = node_type("Vertex")
    assert cls.memory_estimate(cls.default_params()) == 0
    assert cls.check_memory(cls.default_params()) == 0


def test_object_estimate_is_the_box_grid_times_a_constant():
    cls = node_type("Object")
    p = cls.validate_params({"resolution": 40, "cell": [1.0, 0.5, 1.0]})
    assert cls.grid_shape(p) == (40, 20, 40)
    assert cls.memory_estimate(p) == 40 * 20 * 40 * OBJECT_BYTES_PER_POINT


def test_object_estimate_bounds_the_traced_peak():
    doc = straight_beam_graph(resolution=48)
    Evaluator().evaluate(doc)                                  # compile the kernels first
    tracemalloc.start()
    report = Evaluator().evaluate(straight_beam_graph(resolution=48), targets=["obj1"])
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert report.ok
    assert peak <= ObjectNode.memory_estimate(ObjectNode.validate_params({"resolution": 48}))


def test_grow_estimate_grows_with_cells_and_tiles():
    cls = node_type("Grow")
    small, big = load_tileset("TL+-"), load_tileset("cubic-beams-mixed")
    p = cls.validate_params({"size": [10, 10]})
    assert cls.memory_estimate(p) == 100 * 128                 # before the tile set is known
    assert cls.memory_estimate(p, {"tileset": small}) < cls.memory_estimate(p, {"tileset": big})
    assert cls.memory_estimate(cls.validate_params({"size": [20, 10]}), {"tileset": small}) == \
        2 * cls.memory_estimate(p, {"tileset": small})


def test_material_matrix_uses_the_homogenization_model():
    cls = node_type("MaterialMatrix")
    assert cls.memory_estimate(cls.validate_params({"resolution": 50})) == \
        memory_estimate_bytes((50, 50, 50), per_dof_bytes=SOLVER_BYTES_PER_DOF)
    assert cls.memory_estimate(cls.validate_params({"resolution": 0})) == 0   # the grid comes with the input


def test_rd_and_topopt_estimates_follow_their_grids():
    grow, topopt = node_type("RDGrow"), node_type("TopOpt")
    assert grow.memory_estimate(grow.validate_params({"resolution": [200, 100]})) == 20000 * 400
    assert grow.memory_estimate(grow.validate_params({})) == 0                # the fields' grid, unknown yet
    p3 = topopt.validate_params({"preset": "mbb3d", "resolution": [20, 10, 4]})
    assert topopt.memory_estimate(p3) == 800 * 48_000
    assert topopt.memory_estimate(topopt.validate_params({})) == math.prod([64, 32]) * 8_000


def test_evaluator_refuses_before_the_node_runs(monkeypatch):
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "1M")

    def never(*_a, **_k):
        raise AssertionError("evaluate ran despite the memory estimate")
    monkeypatch.setattr(ObjectNode, "evaluate", never)
    report = Evaluator().evaluate(straight_beam_graph(resolution=64))
    r = report.results["obj1"]
    assert r.status == "failed" and r.where == "resolution"
    assert r.error.startswith("node 'obj1' (Object): resolution = 64 needs about 12.6 MB of memory")
    assert "lower resolution" in r.error
    assert report.results["l1"].status == "evaluated" and report.results["vox1"].status == "blocked"


@pytest.mark.parametrize("axis, expect", [("z", (81 * 41)), ("x", (41 * 11))])
def test_phasor_slice_estimate_counts_the_pixels_of_the_box(axis, expect):
    from engine.nodes.phasor import SLICE_BYTES_PER_PIXEL, slice_pixels

    assert slice_pixels(np.zeros(3), np.array([8.0, 4.0, 1.0]), axis, 0.1) == expect
    cls = node_type("PhasorSlice")
    assert cls.memory_estimate(cls.validate_params({"axis": axis})) == 0      # no infill yet

    class Fields:
        lo, hi = np.zeros(3), np.array([8.0, 4.0, 1.0])

    class Infill:
        fields = Fields()
    assert cls.memory_estimate(cls.validate_params({"axis": axis, "pixel": 0.1}), {"infill": Infill()}) == \
        expect * SLICE_BYTES_PER_PIXEL


def test_tiling_properties_estimate_is_the_homogenization_of_its_image():
    from engine.nodes.growth import tiling_properties_bytes

    assert tiling_properties_bytes((10, 10)) == memory_estimate_bytes((200, 200), per_dof_bytes=SOLVER_BYTES_PER_DOF)
    assert tiling_properties_bytes((4, 4, 4), 8) == memory_estimate_bytes((32, 32, 32),
                                                                          per_dof_bytes=SOLVER_BYTES_PER_DOF)
    cls = node_type("TilingProperties")
    assert cls.memory_estimate(cls.default_params()) == 0        # the tiling comes with the input
