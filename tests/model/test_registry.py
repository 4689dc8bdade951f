"""The parameter registry: every parameter and excitation option with its unit, doc and default."""
import dataclasses

import pytest

import qzs
from qzs.errors import ParameterError
from qzs.model.excitation import EXCITATION_KINDS, EXCITATION_OPTIONS, build_excitation
from qzs.model.registry import (PARAMETERS, SECTIONS, numeric_parameters, parameter_info,
                                parameter_table, unit_of, update_parameters)


def test_every_parameter_has_a_unit_a_doc_and_its_default():
    for name, info in PARAMETERS.items():
        assert info.unit and info.doc, name
        cls = SECTIONS[info.section]
        assert getattr(cls(), name) == info.default, name
    assert [row[1] for row in parameter_table()] == list(PARAMETERS)
    assert unit_of("pi_kp") == "N/m" and unit_of("stribeck_decay") == "s/m"
    assert "stop_center" not in numeric_parameters() and "stop_model" not in numeric_parameters()
    assert "stiction_force" in numeric_parameters()


def test_every_excitation_option_has_a_unit_and_builds_its_kind():
    for kind, options in EXCITATION_OPTIONS.items():
        for option in options:
            info = parameter_info(f"excitation.{option}", kind)
            assert info.unit or option == "record", (kind, option)
    assert unit_of("excitation.f0", "random") == "Hz"
    assert unit_of("excitation.phase") == "rad" and unit_of("excitation.amplitude") == "m"
    for field in dataclasses.fields(qzs.Chirp):
        assert field.metadata["unit"], field.name
    random = build_excitation("random", {"f0": 1.0, "f1": 5.0, "seed": 3.0, "duration": 8.0})
    assert (random.f_low, random.f_high, random.seed) == (1.0, 5.0, 3)
    assert isinstance(build_excitation("chirp"), EXCITATION_KINDS["chirp"])


@pytest.mark.parametrize("kind, options, message", [
    ("square", {}, "`kind` must be one of"),
    ("sine", {"f0": 1.0}, "takes no option(s) ['f0']"),
    ("file", {}, "needs `record`"),
    ("chirp", {"amplitude": -1.0}, "`amplitude` must be non-negative"),
])
def test_the_excitation_factory_names_what_is_wrong(kind, options, message):
    with pytest.raises(qzs.ExcitationError) as error:
        build_excitation(kind, options)
    assert message in str(error.value)


def test_update_parameters_places_each_name_in_its_section():
    isolator, controller = update_parameters(qzs.IsolatorParameters(),
                                             qzs.ControllerParameters(),
                                             {"mass": "7.5", "pi_kp": 12, "stop_center": "none"})
    assert isolator.mass == 7.5 and controller.pi_kp == 12.0 and isolator.stop_center is None
    with pytest.raises(ParameterError, match="unknown parameter 'masss'; valid names are: .*mass"):
        update_parameters(qzs.IsolatorParameters(), qzs.ControllerParameters(), {"masss": 1})
    with pytest.raises(ParameterError, match="unknown parameter 'excitation.f_low'"):
        parameter_info("excitation.f_low")
