"""Each leg's own controller with blocks from a hexapod file (``[legs.N.controller]``) and
from ``--leg-controller N=FILE.toml`` pairs: the same run as the Python API's controllers,
bit for bit; bad legs named with the key, the value and the fix before any run."""
import numpy as np
import pytest

import qzs
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters, Dither, FrictionCompensation
from qzs.workflows.hexapod.setups import (centralised, hexapod_setup, load_hexapod,
                                          read_leg_controllers, simulate_setup)

#: A cube whose legs slip under a 3 Hz sine (a light leg friction), every leg dithered, leg 2
#: with its own gains and friction compensation, leg 5 with a stronger dither.
PLATFORM = """
[geometry]
kind = "cubic"
cube_edge = 0.15

[leg]
stiction_force = 1.0
coulomb_force = 0.8

[controller]
pi_kp = 2000.0
pi_ki = 800.0
[controller.dither]
amplitude = 0.5
frequency = 40.0

[legs.2.controller]
pi_kp = 2500.0
[legs.2.controller.compensation]
fraction = 0.8

[legs.5.controller.dither]
amplitude = 1.5

[excitation.z]
kind = "sine"
amplitude = 0.02
frequency = 3.0
"""
RUN = dict(duration=0.3, dt=1e-4)


def _write(tmp_path, text, name="platform.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _python_controllers():
    every = ControllerParameters(pi_kp=2000.0, pi_ki=800.0) + Dither(amplitude=0.5,
                                                                     frequency=40.0)
    legs = [every] * 6
    legs[1] = (ControllerParameters(pi_kp=2500.0, pi_ki=800.0)
               + FrictionCompensation(fraction=0.8) + Dither(amplitude=0.5, frequency=40.0))
    legs[4] = ControllerParameters(pi_kp=2000.0, pi_ki=800.0) + Dither(amplitude=1.5,
                                                                       frequency=40.0)
    return every, tuple(legs)


def test_per_leg_tables_start_from_every_legs_controller(tmp_path):
    setup = load_hexapod(_write(tmp_path, PLATFORM))
    every, legs = _python_controllers()
    assert setup.controller == every
    assert setup.leg_controllers == legs
    assert setup.controllers == legs


def test_a_file_with_per_leg_blocks_runs_as_the_python_controllers_bit_for_bit(tmp_path):
    setup = load_hexapod(_write(tmp_path, PLATFORM))
    from_file = simulate_setup(setup, **RUN)
    _, legs = _python_controllers()
    by_hand = qzs.simulate_hexapod(
        setup.geometry, setup.platform, setup.isolator, legs,
        excitation={"z": qzs.Sine(amplitude=0.02, frequency=3.0)}, **RUN)
    np.testing.assert_array_equal(from_file._data, by_hand._data)
    np.testing.assert_array_equal(from_file._flags, by_hand._flags)
    # the blocks acted, each on its own leg: leg 2 compensates, leg 5 dithers harder
    assert np.abs(from_file["compensation_force"][:, 1]).max() > 0
    assert not np.any(from_file["compensation_force"][:, [0, 2, 3, 4, 5]])
    peaks = np.abs(from_file["dither_force"]).max(axis=0)
    ratio = peaks / [0.5, 0.5, 0.5, 0.5, 1.5, 0.5]  # the same sampled sine on every leg
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)
    assert 0.99 < ratio[0] <= 1.0


def test_leg_controller_files_replace_what_the_file_gives_those_legs(tmp_path):
    leg = _write(tmp_path, "[controller]\npi_kp = 3000.0\n[controller.dither]\n"
                           "amplitude = 2.0\nfrequency = 25.0\n", "leg.toml")
    legs, names = read_leg_controllers([f"2={leg}", f"6={leg}"])
    assert set(legs) == {2, 6} and names == {"legs[2]": f"--leg-controller 2={leg}",
                                             "legs[6]": f"--leg-controller 6={leg}"}
    setup = load_hexapod(_write(tmp_path, PLATFORM), legs=legs, names=names)
    every, own = _python_controllers()
    expected = list(own)
    expected[1] = expected[5] = legs[2]
    assert setup.leg_controllers == tuple(expected)
    # --controller replaces every leg's, the file's [legs.N] tables too
    assert load_hexapod(_write(tmp_path, PLATFORM), controller=legs[2]).leg_controllers is None
    # --set applies to each leg's own controller after it
    setup = load_hexapod(_write(tmp_path, PLATFORM), {"dither.frequency": "30"})
    assert {c.dither.frequency for c in setup.controllers} == {30.0}
    assert setup.controllers[1].pi_kp == 2500.0


@pytest.mark.parametrize("table, match", [
    ("[legs.7.controller]\npi_kp = 1.0\n", r"\[legs\.7\].*'7' is not a leg.*1 to 6"),
    ("[legs.0.controller]\npi_kp = 1.0\n", r"'0' is not a leg"),
    ("[legs.first.controller]\npi_kp = 1.0\n", r"'first' is not a leg"),
    ("[legs.3.controller]\npi_kp = 1.0\n[legs.03.controller]\npi_kp = 2.0\n",
     r"leg 3 is given twice \(\[legs\.3\] and \[legs\.03\]\); give each leg one table"),
    ("[legs.3]\npi_kp = 1.0\n", r"\[legs\.3\] takes one table, \[legs\.3\.controller\]"),
    ("[legs.3.controller]\nstiction_force = 1.0\n",
     r"\[legs\.3\.controller\] `stiction_force` is not a controller parameter"),
    ("[legs.3.controller.dither]\nloudness = 1.0\n",
     r"unknown key\(s\) \['loudness'\] in \[legs\.3\.controller\.dither\]"),
    ("[legs.3.controller.compensation]\nfraction = 2.0\n",
     r"\[legs\.3\.controller\.compensation\] fraction in '.*platform\.toml'.*2\.0"),
    ("[legs.4.controller.linear]\nnum = [1.0]\nden = [1.0, 2.0]\nsample_time = 3.3e-5\n",
     None),
])
def test_bad_leg_tables_name_the_key_the_value_and_the_fix(tmp_path, table, match):
    path = _write(tmp_path, PLATFORM.split("[legs.2")[0] + table)
    if match is None:  # a good table: a leg's linear controller through the single reader
        setup = load_hexapod(path)
        assert setup.leg_controllers[3].linear.sample_time == 3.3e-5
        return
    with pytest.raises(ParameterError, match=match):
        load_hexapod(path)


def test_blocks_with_centralised_control_are_refused_naming_where_they_come_from(tmp_path):
    base = PLATFORM.split("[controller.dither]")[0]
    with_cartesian = "\n[cartesian]\npoint = 'origin'\n"
    plain = load_hexapod(_write(tmp_path, base + with_cartesian))  # no blocks: accepted
    assert plain.cartesian is not None
    own = base + "[legs.4.controller.dither]\namplitude = 1.0\nfrequency = 20.0\n"
    with pytest.raises(ParameterError, match=r"centralised control \(\[cartesian\] in '.*'\) "
                       r"models PI \+ damping alone; `\[legs\.4\.controller\] in .*` has "
                       r"blocks.*dither \(1 N at 20 Hz\).*leave out \[cartesian\]"):
        load_hexapod(_write(tmp_path, own + with_cartesian))
    with pytest.raises(ParameterError, match=r"`\[controller\] in .*` has blocks"):
        load_hexapod(_write(tmp_path, PLATFORM.split("[legs.2")[0] + with_cartesian))
    with pytest.raises(ParameterError, match=r"`--controller c\.toml` has blocks"):
        load_hexapod(_write(tmp_path, base + with_cartesian),
                     controller=ControllerParameters() + Dither(amplitude=1.0, frequency=9.0),
                     names={"controller": "--controller c.toml"})
    with pytest.raises(ParameterError, match=r"\(--centralised\).*`leg 4's controller` has"):
        centralised(load_hexapod(_write(tmp_path, own)))
    with pytest.raises(ParameterError, match=r"\(`cartesian`\).*`legs\[4\]` has blocks"):
        hexapod_setup(legs={4: ControllerParameters() + Dither(amplitude=1.0, frequency=9.0)},
                      cartesian="legs")


@pytest.mark.parametrize("pairs, match", [
    (["7=leg.toml"], r"--leg-controller '7=leg\.toml': '7' is not a leg.*1 to 6"),
    (["x=leg.toml"], r"'x' is not a leg"),
    (["3"], r"--leg-controller '3' names no file; give --leg-controller 3=FILE\.toml"),
    (["3=missing.toml", "3=missing-too.toml"],
     r"leg 3 is given twice \('3=missing\.toml' and '3=missing-too\.toml'\)"),
])
def test_bad_leg_controller_pairs_are_refused_before_any_file_is_read(pairs, match):
    with pytest.raises(ParameterError, match=match):
        read_leg_controllers(pairs)


@pytest.mark.parametrize("legs, match", [
    ({7: ControllerParameters()}, r"`legs` has the key 7.*numbered 1 to 6"),
    ({True: ControllerParameters()}, r"`legs` has the key True"),
    ({2: "pi"}, r"`legs\[2\]` must be a ControllerParameters"),
    ([ControllerParameters()], r"`legs` must map leg numbers"),
])
def test_bad_python_legs_are_named(legs, match):
    with pytest.raises(ParameterError, match=match):
        hexapod_setup(legs=legs)
