"""ToolNumber (#14): a dock's number field over an engine Param that never clamps,
rounds or truncates what was typed."""

from __future__ import annotations

import pytest

from engine.graph import Param
from keyboard_entry import type_into
from ui.tool_number import ToolNumber

RADIUS = Param("radius", "float", 2.0, 0.0, 512.0, unit="mm", doc="brush radius")
COUNT = Param("count", "int", 3, 0, None, doc="how many")


def _positive(v):
    if not v > 0:
        raise ValueError("expected > 0")


@pytest.fixture
def field(qtbot):
    w = ToolNumber(RADIUS, check=_positive, rule="> 0")
    qtbot.addWidget(w)
    w.show()
    qtbot.waitExposed(w)
    return w


@pytest.mark.parametrize("typed, words", [("600", "radius = 600 refused: expected a finite number in [0, 512] mm"),
                                          ("-1", "[0, 512] mm"), ("0", "radius = 0 refused: expected > 0"),
                                          ("wide", "radius = 'wide' refused")])
def test_a_typed_bad_value_is_refused_at_the_field_and_kept_unchanged(qtbot, field, typed, words):
    seen = []
    field.valueChanged.connect(seen.append)
    type_into(qtbot, field, typed)
    assert field.refused and field.message.isVisible()
    assert words in field.message.text() and field.message.text().endswith("kept 2")
    assert field.value() == 2.0 and seen == [] and field.box.property("refused") is True
    assert field.lineEdit().text() == "2 mm"                      # the field shows the kept value
    type_into(qtbot, field, "2")                                  # the kept value typed again clears it
    assert not field.refused and field.box.property("refused") is False and seen == []


def test_accepted_values_are_exact_and_emitted_once(qtbot, field):
    seen = []
    field.valueChanged.connect(seen.append)
    type_into(qtbot, field, "3.14159265")
    assert field.value() == 3.14159265 and seen == [3.14159265]
    assert not field.setValue(1000.0) and field.value() == 3.14159265 and field.refused
    assert field.setValue(4.0) and not field.refused and seen == [3.14159265, 4.0]
    field.show_value(5.0)                                         # the document's value: no signal
    assert field.value() == 5.0 and seen == [3.14159265, 4.0]


def test_the_tooltip_gives_doc_range_rule_unit_and_default(field):
    tip = field.toolTip()
    assert tip.splitlines() == ["brush radius", "allowed: a finite number in [0, 512] mm, > 0", "unit: mm",
                                "default: 2"]


def test_integers_of_any_size_and_a_special_value(qtbot):
    w = ToolNumber(COUNT, special=(0, "none"))
    qtbot.addWidget(w)
    w.show()
    type_into(qtbot, w, str(2**70))                               # no 32-bit limit, no cap
    assert w.value() == 2**70
    type_into(qtbot, w, "2.5")
    assert w.refused and "an integer" in w.message.text() and w.value() == 2**70
    type_into(qtbot, w, "none")
    assert w.value() == 0 and w.lineEdit().text() == "none" and "0: none" in w.toolTip()


def test_steps_skip_values_the_check_refuses_and_ranges_follow_the_data(qtbot):
    def not_one(v):
        if v == 1:
            raise ValueError("0 or >= 2")
    w = ToolNumber(Param("n", "int", 0, 0, 9), check=not_one, special=(0, "default"))
    qtbot.addWidget(w)
    w.box.stepBy(1)
    assert w.value() == 2 and not w.refused
    w.setRange(0, 1)                      # 2 is outside: back to the default
    assert w.value() == 0 and w.maximum() == 1
    w.box.stepBy(1)                       # 1 is refused and the range ends: no step
    assert w.value() == 0 and not w.refused


def test_set_param_switches_the_setting_the_field_edits(qtbot, field):
    gamma = Param("Gamma", "float", 30.0, 0.0, 90.0, unit="°")
    field.set_param(gamma, value=45.0)
    assert field.value() == 45.0 and "[0, 90] °" in field.toolTip() and "> 0" not in field.toolTip()
    type_into(qtbot, field, "100")
    assert field.refused and "Gamma = 100 refused" in field.message.text() and field.value() == 45.0
