"""The Particles node's density / offset Field inputs and correlation rules: fields read where the
kernel says (3-D as given, 2-D extruded), kept cells checked by hand, refusals located."""

import numpy as np
import pytest

from engine.geometry.values import Field
from engine.graph import (AddNode, Connect, EvalContext, Evaluator, GraphDocument, NodeInputError, ParamError,
                          SetParam, UndoStack)
from engine.implicit import cell_hash
from engine.implicit.field_sampling import GridField
from engine.implicit.particles import Suspension
from engine.nodes.implicit_media import ParticlesNode

BASE = {"cell": 0.5, "distribution": "fixed", "size_a": 0.2, "jitter": 0.5, "orient": False, "seed": 3}


def _evaluate(inputs=None, **params):
    p = ParticlesNode.validate_params({**BASE, **params})
    return ParticlesNode().evaluate(inputs or {}, p, EvalContext("p", 0))["sdf"]


def _cells(sus, lo=(-3.0, -3.0, -3.0), hi=(2.9, 2.9, 2.9)):
    return set(map(tuple, sus.particles_in_box(np.array(lo), np.array(hi)).cells.tolist()))


def _all_cells(lo=-6, hi=5):
    r = range(lo, hi + 1)
    return [(i, j, k) for i in r for j in r for k in r]


def _bilinear(values, lo, hi, u, v):
    """Cell-centred bilinear interpolation of values[v, u], clamped, one point at a time."""
    nv, nu = values.shape
    out = []
    for a, b in zip(u, v):
        idx = []
        for x, n, l0, l1 in ((a, nu, lo[0], hi[0]), (b, nv, lo[1], hi[1])):
            s = min(max((x - l0) / ((l1 - l0) / n) - 0.5, 0.0), n - 1.0)
            i = min(int(np.floor(s)), max(n - 2, 0))
            idx.append((i, s - i))
        (iu, tu), (iv, tv) = idx
        ju, jv = min(iu + 1, nu - 1), min(iv + 1, nv - 1)
        out.append((1 - tu) * (1 - tv) * values[iv, iu] + tu * (1 - tv) * values[iv, ju]
                   + (1 - tu) * tv * values[jv, iu] + tu * tv * values[jv, ju])
    return np.array(out)


def test_a_3d_density_field_thins_cells_like_the_kernel_and_an_offset_field_moves_surfaces():
    rng = np.random.default_rng(0)
    dens = Field(rng.random((3, 4, 5)), np.array([-3.0, -3.0, -3.0]), np.array([3.0, 3.0, 3.0]))
    off = Field(rng.uniform(-0.05, 0.1, (2, 3, 2)), np.array([-2.0, -2.0, -2.0]), np.array([2.0, 2.0, 2.0]))
    sus = _evaluate({"density": dens, "offset": off}, offset=0.02)
    assert isinstance(sus, Suspension)
    np.testing.assert_array_equal(sus.density_field.values, dens.values)
    ref = Suspension(cell=0.5, shape="sphere", size=sus.size, jitter=0.5, seed=3, offset=0.02)
    x = rng.uniform(-2.5, 2.5, (3000, 3))
    # every cell the field thins away is also absent in the unthinned cloud's list
    kept, every = _cells(sus), _cells(ref)
    assert kept < every and len(kept) > 0.2 * len(every)
    # the offset field enters the field where it is defined: f + o(x) is the cloud without it
    plain = _evaluate({"density": dens}, offset=0.02)
    np.testing.assert_allclose(sus.field(x) + sus.offset_field.sample(x), plain.field(x), atol=1e-12)
    direct = Suspension(cell=0.5, shape="sphere", size=sus.size, jitter=0.5, seed=3, offset=0.02,
                        density_field=GridField(dens.values, dens.lo, dens.hi))
    assert _cells(direct) == kept
    assert sus.lipschitz > 1.0 and plain.lipschitz == 1.0


@pytest.mark.parametrize("axis, plane", [("x", (1, 2)), ("y", (0, 2)), ("z", (0, 1))])
def test_a_2d_field_is_extruded_along_field_axis(axis, plane):
    rng = np.random.default_rng(len(axis))
    img = Field(rng.random((4, 6)), np.array([-2.0, -1.0]), np.array([2.0, 3.0]))
    sus = _evaluate({"density": img}, field_axis=axis)
    p = rng.uniform(-4, 4, (300, 3))
    want = _bilinear(img.values, img.lo, img.hi, p[:, plane[0]], p[:, plane[1]])
    np.testing.assert_allclose(sus.density_field.sample(p), want, atol=1e-12)


def test_clusters_keep_the_cells_the_modular_rule_keeps():
    sus = _evaluate(correlation="clusters", cluster_period=3, cluster_size=2, cell=1.0)
    want = {c for c in _all_cells() if all(v % 3 < 2 for v in c)}
    assert _cells(sus, (-6, -6, -6), (5.9, 5.9, 5.9)) == want
    none = _evaluate(correlation="none", cluster_period=3, cluster_size=2, cell=1.0)
    assert len(_cells(none, (-6, -6, -6), (5.9, 5.9, 5.9))) == 12 ** 3


def test_a_json_rule_keeps_the_cells_it_names():
    rule = {"polynomials": [[[1, [1, 0, 0]], [2, [0, 0, 1]]]], "moduli": [5], "classes": [[[0, 1], [3, 1]]]}
    sus = _evaluate(correlation="rule", correlation_rule=rule, cell=1.0)
    want = {c for c in _all_cells() if (c[0] + 2 * c[2]) % 5 in (0, 3)}
    assert _cells(sus, (-6, -6, -6), (5.9, 5.9, 5.9)) == want
    # without a rule, "rule" rejects nothing
    assert len(_cells(_evaluate(correlation="rule", cell=1.0), (-6, -6, -6), (5.9, 5.9, 5.9))) == 12 ** 3


@pytest.mark.parametrize("inputs, params, where, match", [
    ({}, dict(correlation="clusters", cluster_period=4, cluster_size=4), "cluster_size", "cluster size"),
    ({"density": Field(np.full((2, 2, 2), 1.5), np.zeros(3), np.ones(3))}, {}, "density", r"\[0, 1\]"),
    ({"offset": Field(np.full((2, 2, 2), 0.2), np.zeros(3), np.ones(3))}, dict(offset=0.1), "offset",
     "w / 2"),
    ({"density": Field(np.zeros((2, 2, 2, 3)), np.zeros(3), np.ones(3), kind="vector")}, {}, "density",
     "scalar Field"),
    ({"offset": Field(np.zeros(4), np.zeros(1), np.ones(1))}, {}, "offset", "2-D .* or 3-D"),
])
def test_bad_fields_and_rules_are_refused_at_their_port_or_parameter(inputs, params, where, match):
    with pytest.raises(NodeInputError, match=match) as info:
        _evaluate(inputs, **params)
    assert info.value.where == where


def test_a_bad_json_rule_is_refused_when_set():
    doc = GraphDocument()
    st = UndoStack(doc)
    st.push(AddNode("Particles", {}, node_id="p"))
    with pytest.raises(ParamError, match="correlation_rule"):
        st.push(SetParam("p", "correlation_rule", {"polynomials": [[[1, [1, 0, 0]]]], "moduli": [0],
                                                   "classes": [[[0, 1]]]}))


def test_a_tiling_image_graph_drives_the_density():
    doc = GraphDocument(seed=1)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", {"name": "TL+-"}, node_id="ts"))
    st.push(AddNode("Grow", {"size": [5, 3]}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    st.push(AddNode("TilingImage", {"resolution": 10, "line_width": 2.0}, node_id="img"))
    st.push(Connect("g", "tiling", "img", "tiling"))
    st.push(AddNode("Particles", {**BASE, "cell": 0.1, "size_a": 0.04}, node_id="p"))
    st.push(Connect("img", "image", "p", "density"))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    img, sus = res.output("img"), res.output("p")
    assert set(np.unique(img.values)) == {0.0, 1.0}
    parts = sus.particles_in_box(np.array([0.0, 0.0, 0.0]), np.array([4.99, 2.99, 0.29]))
    cells = [(i, j, k) for i in range(50) for j in range(30) for k in range(3)]   # one per pixel
    centres = (np.array(cells) + 0.5) * 0.1
    d = _bilinear(img.values, img.lo, img.hi, centres[:, 0], centres[:, 1])
    c = np.array(cells)
    u0 = cell_hash.cell_uniform(cell_hash.cell_stream(c[:, 0], c[:, 1], c[:, 2], cell_hash.seed_word(3)), 0)
    kept = set(map(tuple, parts.cells.tolist()))
    assert kept == {cell for cell, u, v in zip(cells, u0, d) if u < v}     # roulette on the image
    assert np.sum(d < 1e-9) > 500 and np.sum(d > 1 - 1e-9) > 500 and 0 < len(kept) < len(cells)
    # an unconnected density port leaves every cell kept
    st.push(AddNode("Particles", {**BASE, "cell": 0.1, "size_a": 0.04}, node_id="q"))
    plain = Evaluator().evaluate(doc).output("q")
    assert plain.density_field is None and len(plain.particles_in_box(
        np.zeros(3), np.array([4.99, 2.99, 0.29])).cells) == len(cells)


def test_a_cell_width_field_makes_a_union_of_scaled_clouds():
    from engine.implicit.combine import Union
    from engine.implicit.multiscale import layer_weights, layer_widths
    img = Field(np.array([[0.25, 0.5, 1.0], [0.25, 0.5, 1.0]]), np.array([0.0, 0.0]), np.array([6.0, 4.0]))
    sus = _evaluate({"cell_width": img}, field_axis="y", scales=3)      # (u, v) -> (x, z)
    assert isinstance(sus, Union) and len(sus.parts) == 3
    assert [p.cell for p in sus.parts] == pytest.approx([0.25, 0.5, 1.0])
    assert [p.seed for p in sus.parts] == [3, 4, 5]
    # sizes relative to cell = 0.5: fixed 0.2 mm becomes 0.1, 0.2 and 0.4 mm
    assert [p.size.a for p in sus.parts] == pytest.approx([0.1, 0.2, 0.4])
    # each cloud's weight is the hat of the width extruded along y (samples along x)
    p = np.array([[1.0, 7.0, 1.0], [3.0, -2.0, 3.0], [5.0, 0.0, 2.0], [2.0, 1.0, 0.5]])
    want = layer_weights(_bilinear(img.values, img.lo, img.hi, p[:, 0], p[:, 2]), layer_widths(0.25, 1.0, 3))
    got = np.array([c.density_field.sample(p) for c in sus.parts])
    np.testing.assert_allclose(got[:, :3], want[:, :3], atol=1e-12)         # at the samples: exact
    np.testing.assert_allclose(got.sum(axis=0), 1.0, atol=1e-12)
    # unconnected: today's single cloud
    assert isinstance(_evaluate(scales=3), Suspension)


@pytest.mark.parametrize("inputs, params, where, match", [
    ({"cell_width": Field(np.array([[0.5, 0.0]]), np.zeros(2), np.ones(2))}, {}, "cell_width", "> 0"),
    ({"cell_width": Field(np.array([[0.3, 2.0]]), np.zeros(2), np.ones(2))}, dict(offset=0.2), "offset",
     r"layer 0 of 3 \(width 0.3 mm\)"),
    ({"cell_width": Field(np.array([[0.3, 2.0]]), np.zeros(2), np.ones(2))},
     dict(warp_octaves=3, warp_amplitude=0.1, warp_frequency=1.0), "warp_octaves", "warp_octaves must be 1"),
])
def test_bad_cell_width_inputs_are_refused_where_they_are(inputs, params, where, match):
    with pytest.raises(NodeInputError, match=match) as info:
        _evaluate(inputs, **params)
    assert info.value.where == where


def test_scales_is_refused_outside_its_schema_range():
    with pytest.raises(ParamError, match="scales"):
        ParticlesNode.validate_params({**BASE, "scales": 7})
