"""The Studies dock's number fields (#14): a typed value outside its range is refused at the
field with the range ``mesoforge study`` gives for the same flag, never clamped; the seed
takes the CLI's whole 64-bit range; the sample selector's range follows the data."""

from __future__ import annotations

import pytest

from app import cli
from engine.batch import read_study, sweep_hints
from engine.batch.study_params import resolution_param
from keyboard_entry import type_into
from ui.study_panel import StudyPanel


@pytest.fixture
def panel(qtbot, tmp_path):
    p = StudyPanel()
    qtbot.addWidget(p)
    p.show()
    qtbot.waitExposed(p)
    p.out_edit.setText(str(tmp_path / "s.csv"))
    yield p
    p.shutdown()
    assert not p.is_running


# (field, CLI flag, typed value); the mode the flag needs
CASES = [
    ("samples_spin", "--n", "0"),
    ("seed_spin", "--seed", "-1"),
    ("seed_spin", "--seed", str(2**64)),
    ("workers_spin", "--workers", "0"),
    ("resolution_spin", "--resolution", "600"),
    ("resolution_spin", "--resolution", "1"),
    ("sweep_spin", "--sweep", "0"),
    ("distance_spin", "--min-distance", "-0.5"),
]


@pytest.mark.parametrize("name, flag, typed", CASES)
def test_the_dock_and_the_cli_refuse_the_same_value_with_the_same_range(qtbot, capsys, panel,
                                                                        name, flag, typed):
    box = getattr(panel, name)
    if name in ("sweep_spin", "distance_spin"):
        panel.sweep_radio.setChecked(True)
    kept, seen = box.value(), []
    box.valueChanged.connect(seen.append)
    type_into(qtbot, box, typed)
    text = box.message.text()
    assert box.refused and f"= {typed} refused" in text and f"kept {kept:g}" in text
    assert box.value() == kept and seen == []                    # not clamped, not truncated
    allowed = box.param.allowed()
    assert allowed in box.toolTip() and "default:" in box.toolTip()
    if name == "resolution_spin" and typed == "1":
        assert "0 or >= 2" in box.toolTip() and ">= 2" in text
    # the command line refuses the same value, quoting the same range
    mode = ["--sweep", "2"] if flag not in ("--sweep",) and name in ("distance_spin",) else \
        ([] if flag == "--sweep" else ["--group", "T=1"])
    code = cli.main(["study", "TL+-", "--size", "4x4", "--scheduler", "synchronous", *mode, flag, typed])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith(f"mesoforge study: {flag} {typed}") and allowed in err, err
    # Run refuses to start while a field shows a refusal (it would run the kept value)
    assert not panel.run() and not panel.is_running and "refused" in panel.status.text()
    type_into(qtbot, box, f"{kept:g}")
    assert not box.refused


def test_the_seed_takes_64_bit_values_exactly(qtbot, panel):
    for seed in (2**40, 2**64 - 1):
        type_into(qtbot, panel.seed_spin, str(seed))
        assert panel.seed_spin.value() == seed and not panel.seed_spin.refused
        argv = panel.study_arguments(resume=True)
        assert argv[argv.index("--seed") + 1] == str(seed)
        assert cli.build_parser().parse_args(argv).seed == seed


def test_values_past_the_old_spin_box_limits_are_kept_as_typed(qtbot, panel):
    panel.sweep_radio.setChecked(True)
    type_into(qtbot, panel.samples_spin, "2000000")        # a QSpinBox capped this at 1000000
    type_into(qtbot, panel.distance_spin, "0.12345")        # and rounded this to 3 decimals
    assert panel.samples_spin.value() == 2_000_000 and panel.distance_spin.value() == 0.12345
    assert panel.resolution_spin.lineEdit().text() == "default"
    assert panel.resolution_spin.param is not None and panel.resolution_spin.param == resolution_param()


def test_resolution_steps_over_the_value_the_node_refuses(qtbot, panel):
    box = panel.resolution_spin
    assert box.value() == 0
    box.box.stepBy(1)                                        # 1 is refused: the step lands on 2
    assert box.value() == 2 and not box.refused
    box.box.stepBy(-1)
    assert box.value() == 0


def test_the_sample_selector_refuses_an_index_past_the_group(qtbot, panel, tmp_path):
    out = tmp_path / "db.csv"
    sweep_hints("TL+-", n_hint_sets=2, samples_per_set=2, seed=2, out_path=out,
                scheduler="synchronous", shape=(4, 4), resolution=10)
    assert len(read_study(out)) == 4
    assert panel.load_database(out)
    spin = panel.plots.sample_spin
    assert spin.value() == -1 and spin.lineEdit().text() == "group mean"
    type_into(qtbot, spin, "5")                              # the group has samples 0 and 1
    assert spin.refused and "[-1, 1]" in spin.message.text() and spin.value() == -1
    type_into(qtbot, spin, "1")
    assert spin.value() == 1 and not spin.refused
