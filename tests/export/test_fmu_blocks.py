"""The FMU of a controller with blocks equals ``qzs simulate`` bit for bit (issue 40).

For compensation with an observer (continuous and sampled), a dither, a continuous 2-state
lead-lag and a discrete 2-state controller, the closed-loop FMU stepped by FMPy at whole
internal steps gives every recorded channel of :func:`qzs.simulate`, the blocks' own among
them, to the bit, in FMI 3.0 and 2.0. The blocks' parameters are FMU parameters with units,
their exported values as start, and the C model takes a changed one; the sources of an FMU
with every block compile with every warning an error. The FMU starts as qzs does on a base
moving or accelerating at t = 0: the PI's preload nets the blocks' output there, the linear
controller's initial state loaded first.
"""
import dataclasses

import numpy as np
import pytest
from export.fmu_support import starts
from export.test_fmu_matrix import rebuild
from helpers import EXPORT_BLOCK_CASES as CASES
from helpers import export_block_settings as settings

import qzs
from qzs.export import fmu as export

fmpy = pytest.importorskip("fmpy")
VERSIONS = (3, 2)
#: A controller with every block, a discrete linear one among them.
EVERY_BLOCK = dataclasses.replace(CASES["sampled compensation with observer"][2],
                                  dither=CASES["dither"][2].dither,
                                  linear=CASES["discrete controller"][2].linear)


@pytest.fixture(scope="module")
def fmu_of(tmp_path_factory):
    folder = tmp_path_factory.mktemp("block_fmus")
    made = {}

    def get(name, version, controller=None):
        key = (name, version, controller is not None)
        if key not in made:
            excitation, isolator, case_controller, _ = CASES[name]
            kwargs = settings(name)
            made[key] = export.export_fmu(
                folder / f"{len(made)}.fmu", excitation, isolator,
                controller or case_controller, fmi_version=version, dt=kwargs["dt"],
                duration=kwargs["duration"], communication_step=1.0 / kwargs["sample_rate"])
        return made[key]
    return get


def _run(path, name, **start_values):
    kwargs = settings(name)
    return fmpy.simulate_fmu(str(path), stop_time=kwargs["duration"],
                             output_interval=1.0 / kwargs["sample_rate"],
                             start_values=start_values)


def _assert_same(result, reference, name):
    assert set(reference.channels) - {"time"} <= set(result.dtype.names)
    for channel in set(reference.channels) - {"time"}:  # FMPy's own k*h, not the run's
        np.testing.assert_array_equal(np.asarray(result[channel], dtype=float),
                                      np.asarray(reference[channel], dtype=float),
                                      err_msg=f"{name}: {channel}")


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", list(CASES))
def test_the_fmu_with_blocks_is_qzs_simulate_to_the_bit(fmu_of, name, version):
    excitation, isolator, controller, _ = CASES[name]
    reference = qzs.simulate(excitation, isolator, controller, **settings(name))
    _assert_same(_run(fmu_of(name, version), name), reference, name)


def test_the_block_parameters_are_parameters_with_units(fmu_of):
    variables = starts(fmu_of("compensation with observer", 3))
    fraction = variables["controller.compensation.fraction"]
    assert fraction.causality == "parameter" and float(fraction.start) == 0.8
    assert variables["controller.compensation.observer_bandwidth"].unit == "Hz"
    assert variables["controller.compensation.stiction_force"].unit == "N"
    assert float(variables["controller.compensation.stiction_force"].start) == \
        qzs.IsolatorParameters().stiction_force  # the plant's, resolved at export
    assert variables["compensation_force"].causality == "output"
    assert variables["friction_estimate"].unit == "N"
    discrete = starts(fmu_of("discrete controller", 3))
    assert discrete["controller.linear.sample_time"].unit == "s"
    assert discrete["controller.linear.d_position_error"].unit == "N/m"
    assert float(discrete["controller.linear.a[1,2]"].start) == 0.05
    lead_lag = starts(fmu_of("continuous lead-lag", 3))
    assert lead_lag["controller.linear.a[1,1]"].unit == "1/s"
    plain = starts(fmu_of("dither", 3, qzs.PIDamping()))
    assert not [v for v in plain if v.startswith(("controller.dither", "controller.comp"))]


@pytest.mark.parametrize("version", VERSIONS)
def test_a_changed_block_parameter_is_the_run_with_it(fmu_of, version):
    """Set before initialisation, the compensation's fraction and the dither's amplitude and
    frequency are those of the run: the FMU reproduces qzs.simulate with the new values."""
    excitation, isolator, _, _ = CASES["compensation with observer"]
    changed = qzs.PIDamping(compensation=qzs.FrictionCompensation(fraction=0.3,
                                                                  observer_bandwidth=5.0))
    reference = qzs.simulate(excitation, isolator, changed,
                             **settings("compensation with observer"))
    result = _run(fmu_of("compensation with observer", version), "compensation with observer",
                  **{"controller.compensation.fraction": 0.3})
    _assert_same(result, reference, "fraction 0.3")
    dither = qzs.PIDamping(dither=qzs.Dither(amplitude=1.5, frequency=25.0))
    reference = qzs.simulate(*CASES["dither"][:2], dither, **settings("dither"))
    result = _run(fmu_of("dither", version), "dither", **{"controller.dither.amplitude": 1.5,
                                                          "controller.dither.frequency": 25.0})
    _assert_same(result, reference, "dither 1.5 N at 25 Hz")


@pytest.mark.parametrize("version", VERSIONS)
def test_the_sources_with_every_block_rebuild_warning_free(fmu_of, tmp_path, version):
    path = fmu_of("discrete controller", version, EVERY_BLOCK)
    rebuilt = rebuild(path, tmp_path, version)
    runs = [_run(fmu, "discrete controller") for fmu in (path, rebuilt)]
    for name in runs[0].dtype.names:
        np.testing.assert_array_equal(runs[1][name], runs[0][name], err_msg=name)
    reference = qzs.simulate(*CASES["discrete controller"][:2], EVERY_BLOCK,
                             **settings("discrete controller"))
    _assert_same(runs[0], reference, "every block")


def test_the_bounds_of_the_block_parameters_are_those_of_qzs(fmu_of):
    """The FMU takes what qzs takes and refuses what it refuses: the largest compensation
    fraction (1.5, over-compensation) is the run with it; a discrete controller's period of
    0 steps is refused at initialisation, not run as a continuous controller."""
    name = "compensation with observer"
    excitation, isolator, _, _ = CASES[name]
    largest = qzs.PIDamping(compensation=qzs.FrictionCompensation(fraction=1.5,
                                                                  observer_bandwidth=5.0))
    reference = qzs.simulate(excitation, isolator, largest, **settings(name))
    _assert_same(_run(fmu_of(name, 3), name, **{"controller.compensation.fraction": 1.5}),
                 reference, "fraction 1.5")
    with pytest.raises(Exception, match="ExitInitializationMode failed"):
        _run(fmu_of("discrete controller", 3), "discrete controller",
             **{"controller.linear.sample_time": 0.0})


#: A base moving at t = 0 (y' = 2 pi f A = 0.19 m/s, y'' = 0) and one accelerating
#: (y'' = -(2 pi f)^2 A = -3.55 m/s^2, y' = 0): no fade-in.
MOVING = qzs.Sine(amplitude=0.01, frequency=3.0, fade_in=0.0)
ACCELERATING = qzs.Sine(amplitude=0.01, frequency=3.0, phase=np.pi / 2, fade_in=0.0)
#: A short run: what these tests look at is the start.
SHORT = dict(dt=1e-4, sample_rate=1000.0, duration=0.2)


def _short_fmu(folder, excitation, controller, version):
    return export.export_fmu(folder / "start.fmu", excitation, None, controller,
                             fmi_version=version, dt=SHORT["dt"], duration=SHORT["duration"],
                             communication_step=1.0 / SHORT["sample_rate"])


def _short_run(path, **start_values):
    return fmpy.simulate_fmu(str(path), stop_time=SHORT["duration"],
                             output_interval=1.0 / SHORT["sample_rate"],
                             start_values=start_values)


def _static_load(isolator=qzs.IsolatorParameters()):
    """m*g - a*tanh(-b*z_ref): the load the spring does not carry at the setpoint [N]."""
    return isolator.mass * isolator.gravity - isolator.spring_force * np.tanh(
        -isolator.spring_shape * qzs.PIDamping().position_setpoint)


@pytest.mark.parametrize("version", VERSIONS)
def test_a_feedthrough_on_the_measured_velocity_starts_the_fmu_at_the_static_load(tmp_path,
                                                                                 version):
    """A base already moving at t = 0 and a feedthrough D on the measured velocity, set as an
    FMU start value: at t = 0 the amplifier's high-pass has settled, D puts out 0, and the PI
    starts where it starts without D, the motor at the static load, as in qzs.simulate, every
    channel to the bit (docs/model.md §5.1, initial state). The FMU's preload used to count D
    times the velocity measured with the base at rest, -y'(0): the motor started at -5.6 N."""
    controller = CASES["continuous lead-lag"][2]
    d = -40.0  # [N*s/m]
    changed = dataclasses.replace(controller, linear=dataclasses.replace(controller.linear,
                                                                        d=[[d]]))
    reference = qzs.simulate(MOVING, None, changed, **SHORT)
    without = qzs.simulate(MOVING, None, controller, **SHORT)
    assert reference["pi_force"][0] == pytest.approx(without["pi_force"][0], rel=1e-12)
    assert reference["motor_force"][0] == pytest.approx(_static_load(), rel=1e-12)
    result = _short_run(_short_fmu(tmp_path, MOVING, controller, version),
                        **{"controller.linear.d_measured_payload_velocity": d})
    _assert_same(result, reference, "feedthrough on a moving base")


@pytest.mark.parametrize("version", VERSIONS)
def test_the_fmu_preload_nets_the_linear_output_of_its_initial_state_as_qzs(tmp_path, version):
    """The discrete controller reading the payload's acceleration, on a base accelerating at
    t = 0: its states start at equilibrium with that acceleration (the exported
    linear.initial_state), so its output at t = 0 is C x0 + D u0 = -2.3 N, and the PI's
    preload nets it: the motor starts at the static load, as in qzs.simulate, every channel
    to the bit. The FMU used to load linear.initial_state after the preload: the motor started
    C x0 off."""
    controller = CASES["discrete controller"][2]
    reference = qzs.simulate(ACCELERATING, None, controller, **SHORT)
    assert abs(reference["linear_force"][0]) > 2.0
    assert reference["motor_force"][0] == pytest.approx(_static_load(), rel=1e-12)
    _assert_same(_short_run(_short_fmu(tmp_path, ACCELERATING, controller, version)),
                 reference, "linear output at t = 0 from its states")


def test_a_linear_initial_state_set_in_the_fmu_is_netted_by_the_pi_preload(tmp_path):
    """linear.initial_state is loaded before the PI's preload (docs/fmu.md §3, docs/model.md
    §5.1): a state set as a start value puts out C x0 at t = 0 and the PI's integral nets it,
    so the motor starts at the static load whatever the state; the base at rest at t = 0."""
    controller = CASES["continuous lead-lag"][2]
    path = _short_fmu(tmp_path, CASES["continuous lead-lag"][0], controller, 3)
    default = _short_run(path)
    result = _short_run(path, **{"controller.linear.initial_state[1]": 4e-6})  # C x0 = -2 N
    assert default["linear_force"][0] == 0.0  # the exported state: at rest, 0
    assert abs(result["linear_force"][0]) > 1.0
    for run in (default, result):
        assert run["motor_force"][0] == pytest.approx(_static_load(), rel=1e-12)
        assert run["pi_force"][0] + run["linear_force"][0] == pytest.approx(_static_load(),
                                                                            rel=1e-12)
