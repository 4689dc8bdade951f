"""Tests of qzs.simulate's interface: argument checking, divergence, decimation, interrupts.

The physics of the runs is in test_kernels.py, the solvers' stability limits in
test_stability.py, the result object in test_results.py.
"""
import numpy as np
import pytest
import scipy.linalg
from helpers import SHORT_CHIRP, linear_controller, linear_isolator

from qzs.engine import kernels as kernels
from qzs.engine import lanes as _lanes
from qzs import (
    SOLVERS,
    ControllerParameters,
    InitialState,
    IsolatorParameters,
    ParameterError,
    Sine,
    SimulationError,
    StabilityError,
    largest_stable_step,
    simulate,
)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("kwargs, error, match", [
    (dict(solver="rk45"), ParameterError, r"`solver` must be one of 'euler', 'ode3', 'rk4', got 'rk45'"),
    (dict(solver=3), ParameterError, r"`solver` must be one of .*, got 3"),
    (dict(dt=0.0), ParameterError, r"`dt` must be positive, got 0.0"),
    (dict(dt=-1e-4), ParameterError, r"`dt` must be positive, got -0.0001"),
    (dict(dt=float("nan")), ParameterError, r"`dt` must be finite, got nan"),
    (dict(dt=True), ParameterError, r"`dt` must be a number, got the boolean True"),
    (dict(dt="1e-4s"), ParameterError, r"`dt` must be a number, got '1e-4s'"),
    (dict(sample_rate=0.0), ParameterError, r"`sample_rate` must be positive, got 0.0"),
    (dict(sample_rate=3000.0), ParameterError,
     r"`sample_rate` \(3000.0 Hz\) must divide the integration rate 1/dt = 10000 Hz"),
    (dict(sample_rate=20000.0), ParameterError, r"`sample_rate` \(20000.0 Hz\) must divide"),
    (dict(controller=ControllerParameters(controller_rate=3000.0)), ParameterError,
     r"`controller_rate` \(3000.0 Hz\) must divide the integration rate"),
    (dict(duration=30.0), ParameterError, r"`duration` \(30.0 s\) exceeds the excitation's length \(20.0 s\)"),
    (dict(duration=-1.0), ParameterError, r"`duration` must be positive, got -1.0"),
    (dict(duration=1e-5), ParameterError, r"`dt` \(0.0001 s\) must not exceed `duration` \(1e-05 s\)"),
    (dict(excitation=Sine()), ParameterError, r"`duration` is required for a sine excitation"),
    (dict(initial_state=InitialState(relative_position=0.05)), ParameterError,
     r"initial `relative_position` \(0.05 m\) must lie between the stops \[-0.14, 0.02\] m"),
    (dict(isolator=IsolatorParameters(stop_center=0.2)), ParameterError,
     r"initial `relative_position` \(-0.06 m\) must lie between the stops \[0.12, 0.28\] m"),
    (dict(excitation="chirp"), ParameterError,
     r"`excitation` must be a Chirp or Sine or RandomExcitation or DisplacementRecord, got str"),
    (dict(isolator=ControllerParameters()), ParameterError,
     r"`isolator` must be a IsolatorParameters, got ControllerParameters"),
    (dict(controller={"pi_kp": 50.0}), ParameterError, r"`controller` must be a ControllerParameters, got dict"),
    (dict(initial_state=(0.0, 0.0)), ParameterError, r"`initial_state` must be a InitialState, got tuple"),
    (dict(time_step=1e-4), TypeError, r"time_step"),
])
def test_bad_arguments_raise_a_clear_error(kwargs, error, match):
    arguments = dict(excitation=SHORT_CHIRP)
    arguments.update(kwargs)
    with pytest.raises(error, match=match):
        simulate(**arguments)


def test_options_are_keyword_only():
    with pytest.raises(TypeError):
        simulate(SHORT_CHIRP, None, None, 1.0)


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_too_large_step_raises_stability_error_with_the_limit(solver):
    limit = largest_stable_step(solver=solver)
    dt = 1.0 / 100  # 10 ms: above every solver's limit for the default 1e6 N/m stop
    assert dt > limit
    with pytest.raises(StabilityError, match="largest stable step") as info:
        simulate(SHORT_CHIRP, dt=dt, sample_rate=100.0, solver=solver)
    message = str(info.value)
    assert f"{limit:.3g}" in message and "`dt` (0.01 s)" in message and solver in message
    assert isinstance(info.value, ParameterError)


# ------------------------------------------------------------------ divergence
def _discrete_loop_radius(plant, kp, rate):
    """Spectral radius of a P loop sampled with zero-order hold around m*zdd = -c*zd - k*z + u."""
    m, c = plant.mass, plant.viscous_damping
    k = plant.spring_force * plant.spring_shape
    a = np.array([[0.0, 1.0], [-k / m, -c / m]])
    b = np.array([[0.0], [1.0 / m]])
    block = np.zeros((3, 3))
    block[:2, :2], block[:2, 2:] = a, b
    exponential = scipy.linalg.expm(block / rate)
    ad, bd = exponential[:2, :2], exponential[:2, 2:]
    return max(abs(np.linalg.eigvals(ad - bd @ np.array([[kp, 0.0]]))))


def test_unstable_sampled_loop_raises_simulation_error_with_the_time():
    plant = linear_isolator(stiffness=1e-9, damping=100.0, stroke_half=1.0,
                            motor_force_max=1e12)
    controller = linear_controller(pi_kp=1e6, controller_rate=100.0)
    assert _discrete_loop_radius(plant, 1e6, 100.0) > 2  # the discrete loop is violently unstable
    with pytest.raises(SimulationError, match=r"diverged at t = [0-9.e+-]+ s") as info:
        simulate(Sine(amplitude=0.01, frequency=1.0), plant, controller, duration=5.0)
    message = str(info.value)
    assert "relative position z =" in message and "relative velocity v =" in message
    assert isinstance(info.value, RuntimeError)
    time = float(message.split("t = ")[1].split(" s")[0])
    assert 0 < time < 5.0


def test_same_gain_sampled_fast_enough_stays_stable():
    plant = linear_isolator(stiffness=1e-9, damping=100.0, stroke_half=1.0, motor_force_max=1e12)
    assert _discrete_loop_radius(plant, 1e6, 1e4) < 1
    r = simulate(Sine(amplitude=0.01, frequency=1.0), plant, linear_controller(pi_kp=1e6, controller_rate=1e4),
                 duration=2.0, sample_rate=100.0)
    assert np.abs(r.relative_position).max() < 1e-3


# ------------------------------------------------------------------ decimation, progress, interrupts
@pytest.fixture(scope="module")
def short_run():
    return simulate(SHORT_CHIRP, duration=3.0, dt=1e-4, sample_rate=500.0)


def test_decimation_does_not_change_the_integration(short_run):
    every_step = simulate(SHORT_CHIRP, duration=3.0, dt=1e-4, sample_rate=1e4)
    for name in ("relative_position", "payload_acceleration", "friction_force", "base_work"):
        np.testing.assert_array_equal(every_step[name][::20], short_run[name])


def test_progress_bar_does_not_change_the_run(short_run):
    r = simulate(SHORT_CHIRP, duration=3.0, dt=1e-4, sample_rate=500.0, progress=True)
    np.testing.assert_array_equal(r.payload_acceleration, short_run.payload_acceleration)


def test_interrupt_returns_a_partial_result_only_when_interruptible(monkeypatch):
    def interrupted(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(_lanes, "run_single", interrupted)
    r = simulate(SHORT_CHIRP, duration=1.0, interruptible=True)
    assert not r.completed and len(r) == 1 and r.run["steps"] == 0
    with pytest.raises(KeyboardInterrupt):
        simulate(SHORT_CHIRP, duration=1.0)


# ------------------------------------------------------------------ kernels as plain Python
_PURE_PYTHON_RUNS = """
import sys
import numpy as np
from qzs import InitialState, IsolatorParameters, ControllerParameters, Sine, simulate

def runs():
    passive = ControllerParameters(pi_kp=0.0, pi_ki=0.0)
    yield simulate(Sine(amplitude=0.01, frequency=2.5, fade_in=0.0), duration=0.6, dt=1e-4, sample_rate=1e4)
    yield simulate(Sine(amplitude=0.01, frequency=4.0, fade_in=0.0), IsolatorParameters(stop_model="plastic"), passive,
                   duration=0.3, dt=1e-4, sample_rate=1e4,
                   initial_state=InitialState(relative_position=-0.139, relative_velocity=-0.3))
    yield simulate(Sine(amplitude=0.01, frequency=4.0, fade_in=0.0), IsolatorParameters(), passive, duration=0.3,
                   dt=1e-4, sample_rate=1e4, initial_state=InitialState(relative_position=-0.139,
                                                                        relative_velocity=-0.3))

arrays = {}
for i, r in enumerate(runs()):
    arrays[f"data{i}"] = r._data
    arrays[f"flags{i}"] = r._flags
    arrays[f"counts{i}"] = np.array([r.run["stick_events"], r.run["stop_contacts"]])
np.savez(sys.argv[1], **arrays)
"""


def test_kernels_run_as_plain_python_and_agree_with_the_compiled_ones(tmp_path):
    """NUMBA_DISABLE_JIT=1 runs the kernels' Python bodies (coverage, and no numba-only behaviour)."""
    import os
    import subprocess
    import sys

    script = tmp_path / "pure.py"
    script.write_text(_PURE_PYTHON_RUNS)
    environment = dict(os.environ, NUMBA_DISABLE_JIT="1")
    for output, env in ((tmp_path / "python.npz", environment), (tmp_path / "jit.npz", dict(os.environ))):
        subprocess.run([sys.executable, str(script), str(output)], env=env, check=True, timeout=300)
    python, jit = np.load(tmp_path / "python.npz"), np.load(tmp_path / "jit.npz")
    for i in range(3):
        np.testing.assert_array_equal(python[f"flags{i}"], jit[f"flags{i}"])
        np.testing.assert_array_equal(python[f"counts{i}"], jit[f"counts{i}"])
        scale = np.abs(jit[f"data{i}"]).max(axis=0) + 1e-300
        np.testing.assert_allclose(python[f"data{i}"] / scale, jit[f"data{i}"] / scale, rtol=0, atol=1e-9)
    assert jit["counts0"][0] > 0 and jit["counts1"][1] > 0 and jit["counts2"][1] > 0
