"""A controller's blocks in TOML (qzs.iotools.config): ``[controller.compensation]``,
``[controller.dither]``, ``[controller.linear]``; written by ``config_text``, read by
``load_config`` / ``load_controller``; bad tables named with their key, value and fix."""
import numpy as np
import pytest

import qzs
from qzs.errors import ParameterError
from qzs.iotools.config import config_text, load_config, load_controller


def _full_controller():
    """Every block, the optional levels both unset (None) and set, a 2-input 2-state
    discrete linear controller."""
    linear = qzs.LinearController(a=[[0.5, 0.1], [0.0, 0.8]], b=[[1.0, 0.0], [0.2, 1.0]],
                                  c=[3.0, -1.5], d=[0.0, 40.0],
                                  inputs=("position_error", "measured_payload_velocity"),
                                  sample_time=1e-3, tracking_time=0.25, name="lead lag")
    return (qzs.PIDamping(pi_kp=80.0, damping_gain=5.0)
            + qzs.FrictionCompensation(fraction=1.2, stiction_force=8.0,
                                       viscous_damping=None, deadband=2e-3,
                                       observer_bandwidth=15.0)
            + qzs.Dither(amplitude=2.5, frequency=70.0) + linear)


def test_a_controller_with_every_block_round_trips_through_a_config_and_a_controller_file(
        tmp_path):
    controller = _full_controller()
    path = tmp_path / "run.toml"
    path.write_text(config_text(controller=controller, simulation={"dt": 1e-4}))
    loaded = load_config(path)
    assert loaded["controller"] == controller
    assert loaded["controller"].compensation.viscous_damping is None  # "none": the plant's
    assert loaded["controller"].compensation.coulomb_force is None
    text = path.read_text()
    assert "[controller.linear]\na = [[0.5, 0.1], [0.0, 0.8]]\n" in text
    only = tmp_path / "controller.toml"
    only.write_text(text[text.index("[controller]"):text.index("[simulation]")])
    assert load_controller(only) == controller


def test_a_transfer_function_table_is_that_transfer_function(tmp_path):
    """``num``/``den`` give the controller whose frequency response is num(s)/den(s)."""
    path = tmp_path / "c.toml"
    path.write_text('[controller]\npi_kp = 60\n[controller.linear]\nnum = [30.0, 300.0]\n'
                    'den = [1.0, 100.0]\ninputs = "measured_payload_velocity"\n')
    controller = load_controller(path)
    assert controller.pi_kp == 60.0 and controller.compensation is None
    system = controller.linear.to_system()
    for f in (0.3, 3.0, 30.0):
        s = 2j * np.pi * f
        assert np.isclose(complex(system(s)), (30 * s + 300) / (s + 100), rtol=1e-12)


def test_dotted_keys_in_the_controller_table_are_the_block_tables(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text("[controller]\ncompensation.fraction = 0.4\ndither.amplitude = 3.0\n")
    assert load_controller(path) == (qzs.PIDamping() + qzs.FrictionCompensation(fraction=0.4)
                                     + qzs.Dither(amplitude=3.0))


LINEAR = "[controller.linear]\n"


@pytest.mark.parametrize("body, named, shown, fix", [
    (LINEAR + "num = [1.0, 2.0, 3.0]\nden = [1.0, 5.0]\n",
     "[controller.linear] num", "[1.0, 2.0, 3.0]", "add poles"),
    (LINEAR + 'a = [[-1.0]]\nb = [[1.0, 1.0]]\nc = [1.0]\nd = [0.0]\n',
     "[controller.linear] b", "[[1.0, 1.0]]", "one sensor per column of b"),
    (LINEAR + 'a = [[-1.0]]\nb = [[1.0]]\nc = [[1.0], [2.0]]\nd = [0.0]\n',
     "[controller.linear] c", "[[1.0], [2.0]]", "one row of c"),
    (LINEAR + 'num = [1.0]\nden = [1.0, 5.0]\ninputs = ["payload_jerk"]\n',
     "[controller.linear] inputs", "'payload_jerk'", "choose from position_error"),
    (LINEAR + 'a = [[-1.0]]\nb = [[nan]]\nc = [1.0]\nd = [0.0]\n',
     "[controller.linear] b", "[[nan]]", "must be a finite number"),
    (LINEAR + 'a = [[-1.0]]\nb = [[1.0]]\nc = [inf]\nd = [0.0]\n',
     "[controller.linear] c", "[[inf]]", "must be a finite number"),
    ("[controller.compensation]\nfraction = 1.6\n",
     "[controller.compensation] fraction", "1.6", "up to 1.5 over-compensates"),
    ("[controller.compensation]\nfractio = 1.0\n", "[controller.compensation]", "fractio",
     "allowed are"),
    (LINEAR + 'num = [1.0]\nden = [1.0, 5.0]\ninputs = ["position_error", '
     '"relative_velocity"]\n', "[controller.linear] inputs",
     "['position_error', 'relative_velocity']", "name one sensor"),
    (LINEAR + 'num = [1.0]\nden = [1.0, 5.0]\na = [[1.0]]\n', "[controller.linear]",
     "'a', 'den', 'num'", "either as matrices"),
])
def test_a_bad_controller_table_names_its_key_the_value_and_the_fix(tmp_path, body, named,
                                                                    shown, fix):
    path = tmp_path / "c.toml"
    path.write_text("[controller]\npi_kp = 50\n" + body)
    with pytest.raises(ParameterError) as error:
        load_controller(path)
    message = str(error.value)
    assert named in message and shown in message and fix in message, message
    assert str(path) in message


def test_a_controller_file_holds_the_controller_alone(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text("[isolator]\nmass = 7.0\n[controller]\npi_kp = 50\n")
    with pytest.raises(ParameterError, match=r"nothing else.*--config"):
        load_controller(path)
    assert load_config(path)["isolator"].mass == 7.0  # it is a config file


@pytest.mark.parametrize("table, match", [
    ({"dither": {"amplitude": -1.0}}, r"\[legs\.2\.controller\.dither\] amplitude in 'h\.toml'"),
    ({"linear": {"num": [1.0]}}, r"'h\.toml': \[legs\.2\.controller\.linear\] must give its "
                                 r"controller either as matrices"),
    ({"linear": {"d": [2.0], "sample_time": -1.0}},
     r"\[legs\.2\.controller\.linear\] sample_time in 'h\.toml'"),
    ({"dither": {"pitch": 1.0}}, r"unknown key\(s\) \['pitch'\] in \[legs\.2\.controller\.dither\]"),
    ({"pi_kp": "stiff"}, r"\[legs\.2\.controller\] pi_kp in 'h\.toml'"),
])
def test_a_controller_table_under_another_name_is_named_so_in_every_message(table, match):
    """The reader a hexapod file's ``[legs.N.controller]`` tables go through: the messages
    name the table as the file spells it."""
    from qzs.iotools.config import controller_from_table

    with pytest.raises(ParameterError, match=match):
        controller_from_table(table, "h.toml", name="legs.2.controller")


def test_a_controller_table_starts_from_the_controller_given():
    from qzs.iotools.config import controller_from_table

    every = qzs.PIDamping(pi_kp=80.0) + qzs.Dither(amplitude=2.0, frequency=30.0)
    own = controller_from_table({"dither": {"frequency": 45.0}}, controller=every)
    assert own == qzs.PIDamping(pi_kp=80.0) + qzs.Dither(amplitude=2.0, frequency=45.0)


def test_a_transfer_function_without_inputs_reads_what_the_api_reads_by_default(tmp_path):
    # the file and LinearController.from_transfer_function agree: the charge amplifier's
    # velocity when no sensor is named
    path = tmp_path / "c.toml"
    path.write_text("[controller.linear]\nnum = [-20.0]\nden = [1.0, 100.0]\n")
    expected = qzs.LinearController.from_transfer_function([-20.0], [1.0, 100.0])
    assert load_controller(path).linear.inputs == expected.inputs == (
        "measured_payload_velocity",)
