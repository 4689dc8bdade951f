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
    assert [row[1] for row in parameter_table()][:len(PARAMETERS)] == list(PARAMETERS)
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
    ("sine", {"f0": 1.0}, "unknown option(s) ['f0'] in a sine excitation"),
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


def test_every_scalar_of_a_block_is_a_dotted_parameter_from_its_field():
    from qzs.model.controller import BLOCK_CLASSES
    from qzs.model.registry import ALL_PARAMETERS, BLOCK_PARAMETERS

    expected = {"compensation.fraction", "compensation.deadband",
                "compensation.observer_bandwidth", "compensation.stiction_force",
                "compensation.coulomb_force", "compensation.stribeck_decay",
                "compensation.viscous_damping", "dither.amplitude", "dither.frequency",
                "linear.tracking_time", "linear.sample_time"}
    assert set(BLOCK_PARAMETERS) == expected  # no matrices, inputs or name
    for name, info in BLOCK_PARAMETERS.items():
        block, field = name.split(".")
        declared = {f.name: f for f in dataclasses.fields(BLOCK_CLASSES[block])}[field]
        assert (info.unit, info.doc, info.default) == (
            declared.metadata["unit"], declared.metadata["doc"], declared.default), name
        assert info.section == "controller" and info.numeric, name
        assert ALL_PARAMETERS[name] is info and parameter_info(name) is info
    assert unit_of("compensation.observer_bandwidth") == "Hz"
    assert unit_of("linear.tracking_time") == "s" and unit_of("dither.amplitude") == "N"
    assert "compensation.fraction" not in PARAMETERS  # the C model's parameters stay as they are
    assert list(ALL_PARAMETERS)[:len(PARAMETERS)] == list(PARAMETERS)


def test_a_block_parameter_adds_its_block_with_its_defaults_or_changes_it():
    isolator = qzs.IsolatorParameters()
    _, controller = update_parameters(isolator, qzs.PIDamping(pi_kp=80.0),
                                      {"compensation.fraction": "0.8", "dither.frequency": 30})
    assert controller.compensation == qzs.FrictionCompensation(fraction=0.8)
    assert controller.dither == qzs.Dither(frequency=30.0)
    assert controller.pi_kp == 80.0 and controller.linear is None
    _, changed = update_parameters(isolator, controller, {"compensation.deadband": 1e-3,
                                                          "compensation.stiction_force": "none"})
    assert changed.compensation == qzs.FrictionCompensation(fraction=0.8, deadband=1e-3)
    linear = qzs.LinearController.from_transfer_function([2.0], [1.0, 5.0])
    _, changed = update_parameters(isolator, qzs.PIDamping() + linear,
                                   {"linear.tracking_time": 0.3})
    assert changed.linear.tracking_time == 0.3 and changed.linear.a == linear.a


@pytest.mark.parametrize("settings, names, message", [
    ({"compensation.fraction": 2.0}, ("compensation.fraction",), "must lie in [0, 1.5]"),
    ({"compensation.coulomb_force": 12.0, "compensation.stiction_force": 5.0},
     ("compensation.coulomb_force", "compensation.stiction_force"), "must not exceed"),
    ({"dither.frequency": 0.0}, ("dither.frequency",), "must be positive"),
    ({"linear.tracking_time": 0.2}, ("linear.tracking_time",), "[controller.linear]"),
    ({"compensation.fractio": 1.0}, (), "valid names are: "),
])
def test_a_bad_block_parameter_is_named_as_it_was_given(settings, names, message):
    with pytest.raises(ParameterError) as error:
        update_parameters(qzs.IsolatorParameters(), qzs.PIDamping(), settings)
    assert message in str(error.value)
    assert error.value.options == names
    for name in names:
        assert f"`{name}`" in str(error.value)


def test_the_table_shows_a_block_s_parameters_or_that_there_is_no_block():
    from qzs.model.registry import ALL_PARAMETERS, NO_BLOCK

    rows = {row[1]: row for row in parameter_table(
        controller=qzs.PIDamping() + qzs.Dither(amplitude=2.0))}
    assert list(rows) == [n for n in ALL_PARAMETERS if not n.startswith("spring.")]
    assert rows["dither.amplitude"][2:4] == (2.0, "N")
    assert rows["compensation.fraction"][2] == NO_BLOCK and rows["linear.sample_time"][2] == NO_BLOCK


def test_toml_dotted_keys_are_the_dotted_names():
    import tomllib

    from qzs.model.registry import dotted_names

    document = tomllib.loads('compensation.fraction = 0.8\n"dither.amplitude" = 2.0\n'
                             'excitation.f0 = [1, 2]\npi_kp = { start = 1, stop = 2, num = 2 }\n')
    assert dotted_names(document) == {"compensation.fraction": 0.8, "dither.amplitude": 2.0,
                                      "excitation.f0": [1, 2],
                                      "pi_kp": {"start": 1, "stop": 2, "num": 2}}
    assert dotted_names([1]) == [1]


# --- a spring law's parameters (spring.*): docs/model.md §3.1 -------------------------------

def test_every_float_field_of_a_law_but_the_tanh_s_is_a_spring_parameter_with_its_unit():
    from qzs.model.registry import SPRING_PARAMETERS, SPRING_POWERS
    from qzs.model.springs import SPRING_LAWS, TanhSpring

    fields = {f"spring.{f.name}": f.metadata["unit"] for cls in SPRING_LAWS.values()
              if cls is not TanhSpring for f in dataclasses.fields(cls) if f.type is float}
    powers = {f"spring.c{k}": "N" if k == 0 else "N/m" if k == 1 else f"N/m^{k}"
              for k in range(SPRING_POWERS + 1)}
    assert {n: i.unit for n, i in SPRING_PARAMETERS.items()} == {**fields, **powers}
    assert "spring.plateau" not in SPRING_PARAMETERS  # the tanh's are spring_force/_shape
    assert all(info.numeric and info.section == "isolator" and info.doc
               for info in SPRING_PARAMETERS.values())


def test_a_spring_parameter_changes_the_isolator_s_law_and_reads_back():
    from qzs.model.registry import parameter_value

    oblique = qzs.IsolatorParameters(spring=qzs.ObliqueSpringQZS.quasi_zero())
    isolator, _ = update_parameters(oblique, qzs.ControllerParameters(),
                                    {"spring.vertical_stiffness": "150", "spring.preload": 60.0})
    expected = {**oblique.spring.to_dict(), "vertical_stiffness": 150.0, "preload": 60.0}
    assert isolator.spring == qzs.SpringLaw.from_dict(expected)
    assert parameter_value(isolator, None, "spring.vertical_stiffness") == 150.0
    assert parameter_value(isolator, None, "spring.c0", "absent") == "absent"
    # a polynomial: c_k by index, a higher power pads with zeros, the force follows
    quadratic = qzs.IsolatorParameters(spring=qzs.PolynomialSpring(coefficients=(62.78, -100.0),
                                                                   center=-0.06))
    cubic, _ = update_parameters(quadratic, qzs.ControllerParameters(), {"spring.c3": -5e4})
    assert cubic.spring.coefficients.tolist() == [62.78, -100.0, 0.0, -5e4]
    assert cubic.spring.force(-0.04) == pytest.approx(62.78 - 100.0 * 0.02 - 5e4 * 0.02 ** 3,
                                                      rel=1e-14)
    assert parameter_value(cubic, None, "spring.c3") == -5e4
    rows = {row[1]: row for row in parameter_table(cubic)}
    assert [n for n in rows if n.startswith("spring.")] == [
        "spring.center", "spring.c0", "spring.c1", "spring.c2", "spring.c3"]
    assert rows["spring.c3"][2:4] == (-5e4, "N/m^3")


@pytest.mark.parametrize("isolator, settings, names, message", [
    (qzs.IsolatorParameters(), {"spring.preload": 60.0}, ("spring.preload",),
     "MagSpring's tanh"),
    (qzs.IsolatorParameters(spring=qzs.ObliqueSpringQZS()), {"spring.c3": 1.0},
     ("spring.c3",), "no parameter of this 'oblique' spring law"),
    (qzs.IsolatorParameters(spring=qzs.ObliqueSpringQZS()), {"spring.free_length": -1.0},
     ("spring.free_length",), "`spring.free_length` must be positive"),
    (qzs.IsolatorParameters(spring=qzs.PolynomialSpring(coefficients=(60.0,))),
     {"spring.c2": float("nan")}, ("spring.c2",), "`spring.c2`"),
])
def test_a_bad_spring_parameter_is_named_with_its_fix(isolator, settings, names, message):
    with pytest.raises(ParameterError, match=message) as caught:
        update_parameters(isolator, qzs.ControllerParameters(), settings)
    assert caught.value.options == names


def test_a_polynomial_takes_its_next_power_and_any_up_to_the_highest():
    """``spring.c<k>`` for k at and above the polynomial's length pads with zeros (docs/model.md
    §3.1): a linear law (c0, c1) takes c2, the very next power, and c7, the highest; c8 is
    no parameter."""
    from qzs.model.registry import SPRING_POWERS, check_law_parameters

    linear = qzs.IsolatorParameters(spring=qzs.PolynomialSpring(coefficients=(60.0, -100.0)))
    quadratic, _ = update_parameters(linear, qzs.ControllerParameters(), {"spring.c2": 3e3})
    assert quadratic.spring.coefficients.tolist() == [60.0, -100.0, 3e3]
    # the force is the polynomial's: c0 + c1 z + c2 z^2 about the centre 0
    assert quadratic.spring.force(0.01) == pytest.approx(60.0 - 1.0 + 0.3, rel=1e-14)
    check_law_parameters(linear.spring, [f"spring.c{k}" for k in range(SPRING_POWERS + 1)])
    with pytest.raises(ParameterError) as caught:
        check_law_parameters(linear.spring, [f"spring.c{SPRING_POWERS + 1}"])
    assert caught.value.options == (f"spring.c{SPRING_POWERS + 1}",)


def test_a_spring_parameter_on_an_explicit_tanh_law_names_the_fix():
    """An isolator whose law is a TanhSpring given explicitly (not None) has no ``spring.*``
    parameter either; the refusal names its own parameters and the fix, as for None."""
    tanh = qzs.IsolatorParameters(spring=qzs.TanhSpring())
    with pytest.raises(ParameterError, match="MagSpring's tanh.*`spring_force`") as caught:
        update_parameters(tanh, qzs.ControllerParameters(), {"spring.preload": 60.0})
    assert caught.value.options == ("spring.preload",)
