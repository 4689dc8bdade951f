"""One periodic response by harmonic balance (qzs.analysis.harmonic_balance.solution) against
the linear closed loop (closed form and python-control) and the smooth model integrated in
time by scipy."""
import numpy as np
import pytest

from qzs import ParameterError
from qzs.analysis.harmonic_balance import SmoothModel, periodic_response


@pytest.mark.parametrize("frequency", [0.2, 1.0, 3.0, 10.0])
def test_the_linear_limit_is_the_closed_form_transmissibility(frequency, linear_model,
                                                               linear_transmissibility):
    model = linear_model()
    solution = periodic_response(frequency, model, harmonics=3)
    exact = complex(linear_transmissibility(frequency, model))
    assert solution.converged and solution.residual < 1e-10
    assert solution.transmissibility == pytest.approx(abs(exact), rel=1e-9)
    assert solution.phase == pytest.approx(np.angle(exact), abs=1e-9)
    assert solution.relative_amplitude == pytest.approx(abs(exact - 1) * model.amplitude,
                                                        rel=1e-9)
    np.testing.assert_allclose(solution.harmonic_ratios(5)[:2], 0.0, atol=1e-10)
    assert np.isnan(solution.harmonic_ratios(5)[2:]).all()  # beyond the 3 harmonics kept
    # the mean: the integral carries the weight the spring does not
    k = model.spring_force * model.spring_shape
    assert solution.integral_mean * model.pi_ki == pytest.approx(
        model.mass * model.gravity + k * model.position_setpoint, rel=1e-9)


def test_the_time_series_is_the_response_over_one_period(linear_model, linear_transmissibility):
    model = linear_model()
    frequency = 2.0
    solution = periodic_response(frequency, model, harmonics=3)
    series = solution.time_series(points=128)
    omega = 2 * np.pi * frequency
    time = series["time"]
    assert time.size == 128 and time[-1] < 1 / frequency
    exact = complex(linear_transmissibility(frequency, model))
    payload = (exact * model.amplitude * np.exp(1j * omega * time)).real
    np.testing.assert_allclose(series["relative_position"],
                               model.position_setpoint + payload - model.amplitude
                               * np.cos(omega * time), atol=1e-12)
    np.testing.assert_allclose(series["payload_acceleration"], -omega ** 2 * payload,
                               atol=1e-9 * omega ** 2 * model.amplitude)
    np.testing.assert_allclose(series["relative_velocity"],
                               np.gradient(series["relative_position"], time, edge_order=2),
                               rtol=0, atol=1e-3 * omega * model.amplitude)
    motor = model.motor_force(series["relative_position"], series["pi_integral"],
                              -omega * (exact * model.amplitude
                                        * np.exp(1j * omega * time)).imag,
                              series["highpass_state"])
    np.testing.assert_allclose(series["motor_force"], motor, atol=1e-9)
    start = solution.state_at_start()
    assert start == pytest.approx([series[name][0] for name in (
        "relative_position", "relative_velocity", "highpass_state", "pi_integral")], abs=1e-15)


def test_frictionless_small_motion_is_the_linear_closed_loop(frictionless_small_motion,
                                                             validation):
    solutions, linear = frictionless_small_motion
    for frequency, solution in solutions.items():
        assert solution.converged
        assert solution.transmissibility == pytest.approx(
            float(linear.transmissibility(frequency)), rel=1e-7)
        validation(f"Harmonic balance, frictionless small motion at {frequency} Hz: T",
                   "the linearised closed loop (python-control)",
                   abs(solution.transmissibility / float(linear.transmissibility(frequency))
                       - 1), 1e-7)


def test_a_solution_is_a_periodic_orbit_of_the_smooth_ode(monodromy):
    """The paper's default case with Stribeck friction and the PI loop, friction regularised
    over 20 mm/s so that 25 harmonics resolve it: integrated over one period from the
    solution's start, the smooth ODE comes back to it (to the truncation of the harmonics:
    the Stribeck term's |v| leaves a jump in the second derivative at reversal)."""
    model = SmoothModel.from_parameters(amplitude=0.010, friction_velocity=0.02)
    omega = 2 * np.pi * 5.0
    solution = periodic_response(5.0, model)
    assert solution.converged and solution.residual < 1e-9
    start, end, _ = monodromy(solution)
    scale = np.array([model.amplitude, model.amplitude * omega, 1.0, model.amplitude / omega])
    error = np.abs(end - start) / scale
    assert error[0] < 1e-4 and error[1] < 1e-4
    assert error[3] < 1e-3  # the integral sums the small offset of z over the period
    # the integral's mean carries the weight the spring does not: m g - a tanh(b z_ref)
    deficit = model.mass * model.gravity - model.spring(model.position_setpoint)[0]
    assert solution.integral_mean * model.pi_ki == pytest.approx(deficit, rel=1e-2)


def test_steep_friction_needs_more_harmonics_and_gets_better_with_them(monodromy):
    """At the default 1 mm/s the friction's reversal is steep: the orbit's error falls as
    the harmonics grow, and the fundamental moves less than the orbit does."""
    model = SmoothModel.from_parameters(amplitude=0.010)
    errors, ratios = [], []
    for harmonics in (25, 50):
        solution = periodic_response(5.0, model, harmonics=harmonics)
        start, end, _ = monodromy(solution)
        errors.append(abs(end[1] - start[1]) / (model.amplitude * 2 * np.pi * 5.0))
        ratios.append(solution.transmissibility)
    assert errors[1] < 0.5 * errors[0]
    assert abs(ratios[1] / ratios[0] - 1) < 1e-3


def test_a_solution_restarts_newton_where_it_left_off():
    model = SmoothModel.from_parameters(amplitude=0.010, friction_velocity=0.02)
    first = periodic_response(5.0, model, harmonics=15)
    again = periodic_response(5.0, model, harmonics=15, initial_guess=first)
    assert again.converged and again.iterations <= 2
    assert again.transmissibility == pytest.approx(first.transmissibility, rel=1e-10)
    with pytest.raises(ParameterError, match="initial_guess"):
        periodic_response(5.0, model, harmonics=10, initial_guess=first)


@pytest.mark.parametrize("call, name", [
    (lambda m: periodic_response(0.0, m), "frequency"),
    (lambda m: periodic_response(1.0, m, harmonics=0), "harmonics"),
    (lambda m: periodic_response(1.0, m, harmonics=10, time_points=20), "time_points"),
    (lambda m: periodic_response(1.0, "model"), "model"),
])
def test_bad_input_is_refused(call, name):
    model = SmoothModel.from_parameters(amplitude=0.01)
    with pytest.raises(ParameterError, match=name):
        call(model)


def test_one_period_as_text_dataset_and_figure(softening_curve, tmp_path):
    """The protocol of a solution: its summary names its fundamental, its dataset is one
    period of its time series with units, its figure draws that period."""
    import matplotlib.pyplot as plt

    solution = softening_curve.solution(3)
    text = solution.summary()
    assert f"{solution.transmissibility:.6g}" in text and f"{solution.frequency:.6g} Hz" in text
    data = solution.to_xarray()
    series = solution.time_series()
    assert np.array_equal(data["time"].values, series["time"])
    assert np.array_equal(data["motor_force"].values, series["motor_force"])
    assert data["time"].values[-1] < 1.0 / solution.frequency  # one period, its end left out
    assert data["pi_integral"].attrs["units"] == "m*s"
    figure = solution.plot(tmp_path / "period.png")
    try:
        (line,) = figure.axes[0].lines
        assert np.allclose(line.get_ydata(), series["relative_position"] * 1e3)
    finally:
        plt.close(figure)
