"""The one module of defaults: every layer that needs one of them reads it there."""
import ast
from pathlib import Path

import pytest

from qzs import defaults
from qzs.analysis.hexapod_linear import entry_unit
from qzs.defaults import AXES, AXIS_RATE_UNITS, AXIS_UNITS, EXCITATION, HEXAPOD
from qzs.model.excitation import Chirp, Sine
from qzs.workflows.hexapod.setups import hexapod_setup

SOURCE = Path(__file__).resolve().parents[1] / "src" / "qzs"


def test_the_axes_are_three_translations_then_three_rotations_about_them():
    assert AXES[:3] == ("x", "y", "z")
    assert AXES[3:] == tuple(f"r{axis}" for axis in AXES[:3])
    assert AXIS_UNITS == ("m",) * 3 + ("rad",) * 3
    assert AXIS_RATE_UNITS == tuple(f"{unit}/s" for unit in AXIS_UNITS)


def test_every_mapping_of_defaults_is_read_only():
    for name in defaults.__all__:
        value = getattr(defaults, name)
        if hasattr(value, "keys"):
            with pytest.raises(TypeError):
                value["new"] = 1.0


def test_the_excitations_default_to_the_papers_10_mm():
    assert EXCITATION["amplitude"] == pytest.approx(10e-3)
    assert Chirp().amplitude == Sine().amplitude == EXCITATION["amplitude"]


def test_the_default_platform_is_the_cube_of_the_shipped_edge():
    geometry = hexapod_setup().geometry
    # a cube's adjacent lower vertices are one edge apart; the legs of a cubic
    # configuration run along its edges, so the home length is the edge too
    assert geometry.home_lengths == pytest.approx([HEXAPOD["cube_edge"]] * 6)


@pytest.mark.parametrize("output, input, unit", [(0, 1, "1"), (3, 5, "1"), (2, 4, "m/rad"),
                                                 (5, 0, "rad/m")])
def test_an_entry_of_the_6x6_matrix_has_the_unit_of_its_row_per_its_column(output, input, unit):
    assert entry_unit(output, input) == unit
    assert entry_unit(output, input, dimensionless="-") == ("-" if unit == "1" else unit)


def test_the_axis_names_are_spelled_nowhere_else_in_the_package():
    spelled = []
    for path in SOURCE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Tuple) and [getattr(e, "value", None)
                                                for e in node.elts] == list(AXES):
                spelled.append(str(path.relative_to(SOURCE)))
    assert spelled == ["defaults.py"], spelled
