"""Problem validation, JSON round trip and the presets."""

import numpy as np
import pytest

from engine.topopt import PRESETS, Problem, preset
from engine.topopt.problem import node_shape


def _arrays(shape):
    ns = node_shape(shape)
    return np.zeros(ns + (len(shape),), bool), np.zeros((1,) + ns + (len(shape),))


def _clamped(shape=(4, 6)):
    fixed, loads = _arrays(shape)
    fixed[:, 0] = True
    loads[0, 2, -1, 1] = -1.0
    return fixed, loads


def test_valid_problem_freezes_its_arrays_and_leaves_inputs_alone():
    fixed, loads = _clamped()
    p = Problem(shape=(4, 6), fixed=fixed, loads=loads, volfrac=0.5)
    fixed[:] = False
    assert p.fixed[:, 0].all() and not p.fixed.flags.writeable and not p.loads.flags.writeable
    assert p.n_dofs == 2 * 5 * 7 and p.n_cases == 1 and p.n_domain == 24


@pytest.mark.parametrize("change, field", [
    (dict(volfrac=0.0), "volfrac"), (dict(volfrac=1.0), "volfrac"), (dict(volfrac=1.2), "volfrac"),
    (dict(penal=0.5), "penal"), (dict(rmin=0.0), "rmin"), (dict(young_min=0.0), "young_min"),
    (dict(poisson=0.5, shape=(2, 4, 6)), "poisson"), (dict(objective="mass"), "objective"),
    (dict(shape=(4, 7)), "fixed"), (dict(passive=np.full((4, 6), 2)), "passive"),
])
def test_bad_fields_are_named(change, field):
    fixed, loads = _clamped()
    if "shape" in change and len(change["shape"]) == 3:
        fixed, loads = _arrays(change["shape"])
        fixed[:, :, 0] = True
        loads[0, 1, 2, -1, 1] = -1.0
    kw = dict(shape=(4, 6), fixed=fixed, loads=loads, volfrac=0.5) | change
    with pytest.raises(ValueError, match=field):
        Problem(**kw)


def test_unsupported_or_underconstrained_structure_is_refused():
    fixed, loads = _clamped()
    with pytest.raises(ValueError, match="fixed: no supported dof"):
        Problem(shape=(4, 6), fixed=np.zeros_like(fixed), loads=loads, volfrac=0.5)
    rollers = np.zeros_like(fixed)
    rollers[:, 0, 0] = True                                 # x held on the left edge only: slides in y
    with pytest.raises(ValueError, match="fixed: .* rigid-body"):
        Problem(shape=(4, 6), fixed=rollers, loads=loads, volfrac=0.5)


def test_load_on_supported_dof_and_empty_case_are_refused():
    fixed, loads = _clamped()
    bad = loads.copy()
    bad[0, 1, 0, 1] = 1.0
    with pytest.raises(ValueError, match=r"loads: case 0 .* supported dof y of node \[0, 1\]"):
        Problem(shape=(4, 6), fixed=fixed, loads=bad, volfrac=0.5)
    two = np.concatenate([loads, np.zeros_like(loads)])
    with pytest.raises(ValueError, match="loads: case 1 applies no force"):
        Problem(shape=(4, 6), fixed=fixed, loads=two, volfrac=0.5)


def test_passive_solid_must_leave_room():
    fixed, loads = _clamped()
    passive = np.zeros((4, 6), np.int8)
    passive[:, :4] = 1
    with pytest.raises(ValueError, match="volfrac"):
        Problem(shape=(4, 6), fixed=fixed, loads=loads, volfrac=0.5, passive=passive)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_round_trip_through_json(name):
    p = preset(name, 6 if "3d" not in name else 4)
    q = Problem.from_json(p.to_json())
    for f in ("fixed", "loads", "passive"):
        np.testing.assert_array_equal(getattr(q, f), getattr(p, f))
    for f in ("shape", "volfrac", "rmin", "penal", "objective", "name", "h"):
        assert getattr(q, f) == getattr(p, f)


def test_from_dict_names_the_bad_entry():
    d = preset("cantilever_2d", 4).to_dict()
    d["supports"][0]["node"] = [99, 0]
    with pytest.raises(ValueError, match=r"supports\[0\]\.node"):
        Problem.from_dict(d)
    d = preset("cantilever_2d", 4).to_dict()
    d["load_cases"][0][0]["force"] = [1.0]
    with pytest.raises(ValueError, match=r"load_cases\[0\]\[0\]\.force"):
        Problem.from_dict(d)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_scale_with_resolution(name):
    lo, hi = (4, 8) if "3d" in name else (10, 20)
    a, b = preset(name, lo), preset(name, hi)
    assert all(2 * m == n for m, n in zip(a.shape, b.shape))
    np.testing.assert_allclose(a.loads.sum(axis=tuple(range(1, a.loads.ndim - 1))),
                               b.loads.sum(axis=tuple(range(1, b.loads.ndim - 1))))
    assert a.volfrac == b.volfrac and b.rmin >= a.rmin


def test_editing_supports_and_loads():
    p = preset("cantilever_2d", 10)
    from engine.topopt import nodes_in_box
    q = p.with_load(nodes_in_box(p.shape, (1.0, 1.0), (1.0, 1.0)), (0.0, -2.0), case=1)
    assert q.n_cases == 2 and q.loads[1, -1, -1, 1] == -2.0 and p.n_cases == 1
    r = q.with_support(nodes_in_box(p.shape, (0.5, 0.0), (0.5, 0.0)), axes="y")
    assert r.fixed[0, 10, 1] and not r.fixed[0, 10, 0]
    freed = r.with_support(nodes_in_box(p.shape, (0.5, 0.0), (0.5, 0.0)), axes="y", held=False)
    assert not freed.fixed[0, 10].any()
    with pytest.raises(ValueError, match="loads: case 1 applies no force"):
        q.with_load(nodes_in_box(p.shape, (1.0, 1.0), (1.0, 1.0)), (0.0, 0.0), case=1, add=False)
