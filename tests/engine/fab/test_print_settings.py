import math

import pytest

from engine.fab import PrintSettings


def test_defaults_and_filament_per_mm_closed_form():
    s = PrintSettings()
    assert (s.nozzle_diameter, s.layer_height, s.filament_diameter) == (0.4, 0.2, 1.75)
    assert s.filament_per_mm == pytest.approx(0.4 * 0.2 / (math.pi * 0.875 ** 2))
    assert s.replace(extrusion_multiplier=1.1).filament_per_mm == pytest.approx(
        1.1 * s.filament_per_mm)


@pytest.mark.parametrize("changes, words", [
    ({"layer_height": 0.5}, ["layer_height", "0.5", "nozzle"]),
    ({"layer_height": 0.0}, ["layer_height"]),
    ({"nozzle_diameter": -0.4}, ["nozzle_diameter", "-0.4"]),
    ({"filament_diameter": float("nan")}, ["filament_diameter"]),
    ({"print_speed": 0}, ["print_speed", "(0.0, 1000.0]"]),
    ({"nozzle_temperature": 900}, ["nozzle_temperature", "900"]),
    ({"retraction_length": -1}, ["retraction_length"]),
    ({"perimeters": 1.5}, ["perimeters", "whole"]),
    ({"perimeters": "two"}, ["perimeters"]),
    ({"bed_temperature": "hot"}, ["bed_temperature", "number"]),
    ({"offset": (1.0,)}, ["offset"]),
])
def test_bad_values_are_refused_by_name(changes, words):
    with pytest.raises(ValueError) as err:
        PrintSettings(**changes)
    for w in words:
        assert w in str(err.value)


def test_dict_round_trip_and_unknown_keys():
    s = PrintSettings(perimeters=2, offset=(10, 20), relative_extrusion=True)
    assert PrintSettings.from_dict(s.to_dict()) == s
    assert s.offset == (10.0, 20.0)
    with pytest.raises(ValueError, match="nozzle_size"):
        PrintSettings.from_dict({"nozzle_size": 0.4})
