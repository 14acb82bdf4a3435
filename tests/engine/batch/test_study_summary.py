"""Grouping study rows for the plots, against hand-computed values; hint-group studies."""

import math

import numpy as np
import pytest

from engine.batch import read_study, sample_seed, sweep_hints
from engine.batch.rows import RowFile
from engine.batch.study_groups import study_hint_groups
from engine.batch.study_summary import (directional_modulus, group_directional_modulus,
                                        group_study, load_study, stiffness_of, study_blocks)
from engine.growth import dirichlet_hints

BLOCKS = ("T", "L", "-", "+")
NAN = math.nan
# orthotropic plane-stress C: S11 = 2/7, S22 = 4/7, S12 = -1/7, S66 = 1, so
# E(0) = 7/2, E(90) = 7/4 and 1/E(45) = (S11 + S22 + 2 S12 + S66) / 4 = 11/28
ORTHO = dict(C11=4.0, C12=1.0, C13=0.0, C22=2.0, C23=0.0, C33=1.0)


def _row(set_, index, status, hint, p, E=NAN, nu=NAN, C=None, E_s=1.0, hints="x"):
    r = {"set": set_, "index": index, "seed": 100 * set_ + index, "hints": hints}
    r.update({f"hint_{b}": w for b, w in zip(BLOCKS, hint)})
    r["status"] = status
    r.update({f"p_{b}": v for b, v in zip(BLOCKS, p)})
    r.update(C or dict.fromkeys(ORTHO, NAN))
    r.update({"E_avg": E * E_s, "nu_avg": nu, "E_avg/E_s": E, "E_s": E_s})
    return r


H0 = (0.25, 0.25, 0.25, 0.25)
H1 = (4 / 7, 1 / 7, 1 / 7, 1 / 7)


def _rows():
    return [
        _row(0, 0, "ok", H0, (0.4, 0.2, 0.2, 0.2), E=0.1, nu=0.2, C=ORTHO, hints="T=1,L=1,-=1,+=1"),
        _row(1, 0, "ok", H1, (0.7, 0.1, 0.1, 0.1), E=0.05, nu=-0.3, C=ORTHO),
        _row(0, 1, "ok", H0, (0.1, 0.3, 0.3, 0.3), E=0.3, nu=-0.1,
             C=dict(ORTHO, C11=8.0, C12=2.0, C22=4.0, C33=2.0)),     # twice ORTHO
        _row(0, 2, "singular", H0, (0.1, 0.1, 0.5, 0.3)),
        _row(0, 3, "error", H0, (NAN,) * 4),
        # set 0 again but other hints: rows of another study appended to the file
        _row(0, 0, "ok", H1, (0.5, 0.2, 0.2, 0.1), E=0.2, nu=0.0, C=ORTHO),
    ]


def test_groups_means_and_realised_probabilities_by_hand():
    groups = group_study(_rows())
    assert study_blocks(_rows()) == BLOCKS
    assert [(g.set, tuple(np.round(g.requested, 6))) for g in groups] == \
        [(0, tuple(np.round(H0, 6))), (0, tuple(np.round(H1, 6))), (1, tuple(np.round(H1, 6)))]
    g = groups[0]
    assert g.blocks == BLOCKS and g.hints_text == "T=1,L=1,-=1,+=1"
    assert [r["index"] for r in g.rows] == [0, 1, 2, 3] and g.n_samples == 4
    assert g.n_ok == 2 and g.count("singular") == 1 and g.count("error") == 1
    np.testing.assert_array_equal(g.E, [0.1, 0.3])
    np.testing.assert_array_equal(g.nu, [0.2, -0.1])
    assert g.E_mean == pytest.approx(0.2) and g.nu_mean == pytest.approx(0.05)
    # mean over the three rows that grew (ok and singular), the failed row left out
    np.testing.assert_allclose(g.realised, [0.6 / 3, 0.6 / 3, 1.0 / 3, 0.8 / 3], rtol=1e-12)
    assert g.realised.sum() == pytest.approx(1.0)
    np.testing.assert_allclose(groups[2].realised, [0.7, 0.1, 0.1, 0.1])
    assert groups[1].n_ok == 1 and groups[1].E_mean == 0.2


def test_groups_without_ok_rows_and_empty_input():
    rows = [_row(0, 0, "error", H0, (NAN,) * 4)]
    (g,) = group_study(rows)
    assert g.n_ok == 0 and math.isnan(g.E_mean) and np.all(np.isnan(g.realised))
    theta, e = group_directional_modulus(g, n=8)
    assert theta.shape == (8,) and np.all(np.isnan(e))
    assert group_study([]) == []
    with pytest.raises(ValueError, match="not from a study file"):
        group_study([{"a": 1, "p_T": 0.5}])


def test_directional_modulus_closed_forms():
    row = _row(0, 0, "ok", H0, H0, E=0.1, nu=0.0, C=ORTHO, E_s=2.0)
    theta, e = directional_modulus(row, n=8)                     # 45 degree steps
    np.testing.assert_allclose(theta, np.arange(8) * np.pi / 4)
    np.testing.assert_allclose(e[[0, 4]], 3.5 / 2, rtol=1e-12)             # E_x / E_s
    np.testing.assert_allclose(e[[2, 6]], 1.75 / 2, rtol=1e-12)            # E_y / E_s
    np.testing.assert_allclose(e[[1, 3, 5, 7]], 28 / 11 / 2, rtol=1e-12)   # S16 = S26 = 0
    # isotropic plane stress E = 3, nu = 0.25: E(theta) = 3 in every direction
    E, nu = 3.0, 0.25
    c = E / (1 - nu**2)
    iso = dict(C11=c, C12=c * nu, C13=0.0, C22=c, C23=0.0, C33=E / (2 * (1 + nu)))
    _, e = directional_modulus(_row(0, 0, "ok", H0, H0, C=iso), n=36)
    np.testing.assert_allclose(e, 3.0, rtol=1e-12)
    # a mechanism has no directional modulus
    _, e = directional_modulus(_row(0, 0, "singular", H0, H0, C=ORTHO), n=4)
    assert np.all(np.isnan(e))
    with pytest.raises(ValueError, match="n must be an integer >= 3"):
        directional_modulus(row, n=2)


def test_group_curve_is_the_mean_of_the_sample_curves():
    g = group_study(_rows())[0]            # ORTHO and twice ORTHO, both ok, E_s = 1
    theta, e = group_directional_modulus(g, n=4)
    np.testing.assert_allclose(e, [(3.5 + 7) / 2, (1.75 + 3.5) / 2] * 2, rtol=1e-12)


def test_stiffness_of_a_3d_row_is_symmetric():
    row = {f"C{i}{j}": float(10 * i + j) for i in range(1, 7) for j in range(i, 7)}
    C = stiffness_of(row)
    assert C.shape == (6, 6) and np.array_equal(C, C.T) and C[1, 4] == 25.0 and C[4, 1] == 25.0


def test_hint_groups_are_a_sweep_with_given_vectors(tmp_path):
    vectors = dirichlet_hints(4, 2, rng=5)
    groups = [dict(zip(BLOCKS, map(float, v))) for v in vectors]
    small = dict(shape=(5, 5), resolution=10, scheduler="synchronous", seed=5)
    a, b = tmp_path / "groups.csv", tmp_path / "sweep.csv"
    s = study_hint_groups("TL+-", groups, samples_per_group=2, out_path=a, **small)
    sweep_hints("TL+-", n_hint_sets=2, samples_per_set=2, out_path=b, **small)
    ra, rb = read_study(a), read_study(b)
    assert s["n_groups"] == 2 and s["n_done"] == 4 and len(s["sets"]) == 2
    assert [r["seed"] for r in ra] == [sample_seed(5, j, i) for j in (0, 1) for i in (0, 1)]
    for x, y in zip(ra, rb):                       # repr: NaN cells of mechanisms compare equal
        assert {k: repr(v) for k, v in x.items() if k != "seconds"} == \
            {k: repr(v) for k, v in y.items() if k != "seconds"}
    # one more group: the rows of the first two are kept, only the new group runs
    more = study_hint_groups("TL+-", [*groups, None], samples_per_group=2, out_path=a, **small)
    assert more["n_resumed"] == 4 and more["n_new"] == 2
    assert [g.set for g in group_study(load_study(a))] == [0, 1, 2]
    with pytest.raises(ValueError, match="hint group 1: .*'X'"):
        study_hint_groups("TL+-", [None, {"X": 1.0}], samples_per_group=1, **small)
    with pytest.raises(ValueError, match="hint_groups must be a non-empty list"):
        study_hint_groups("TL+-", [], samples_per_group=1, **small)


def test_load_study_refuses_what_is_not_a_study(tmp_path):
    with pytest.raises(ValueError, match="ends in .csv or .parquet"):
        load_study(tmp_path / "x.txt")
    with pytest.raises(ValueError, match="no such file"):
        load_study(tmp_path / "x.csv")
    with RowFile(tmp_path / "y.csv", ["a", "b"]) as f:
        f.append({"a": 1, "b": 2})
    with pytest.raises(ValueError, match="no 'set', 'index', 'status', 'hints' column"):
        load_study(tmp_path / "y.csv")
    # a Parquet study is read from its row journal
    with RowFile(tmp_path / "z.parquet.rows.csv", list(_rows()[0])) as f:
        for r in _rows():
            f.append(r)
    rows = load_study(tmp_path / "z.parquet")
    assert len(rows) == 6 and [(r["set"], r["index"]) for r in rows][:2] == [(0, 0), (0, 0)]
