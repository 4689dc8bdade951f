"""Transmissibility fit: round trip through the simulator with a small free set, bad input."""
import numpy as np
import pytest

import qzs
from qzs.errors import DataError, ParameterError
from qzs.errors import FitError
from qzs.identify import fit_transmissibility
from qzs.analysis.spectral import transmissibility

CHIRP = qzs.Chirp(amplitude=0.010, f0=0.0, f1=20.0, duration=60.0)
RATE = 100.0


def measured_curve(isolator, seed=0, noise=0.03):
    """The model's curve under the fit's own settings, with 3 % multiplicative noise."""
    run = qzs.simulate(CHIRP, isolator, dt=5e-4, sample_rate=RATE)
    estimate = transmissibility(run.base_acceleration, run.payload_acceleration, RATE,
                                fft_length=1024)
    rng = np.random.default_rng(seed)
    return estimate.frequency, estimate.magnitude * np.exp(rng.normal(0.0, noise,
                                                                      estimate.frequency.size))


@pytest.fixture(scope="module")
def curve():
    return measured_curve(qzs.IsolatorParameters(viscous_damping=60.0, stiction_force=6.0))


@pytest.mark.parametrize("seed", [0, 1])
def test_round_trip_viscous_damping_within_interval(seed, validation):
    truth = qzs.IsolatorParameters(viscous_damping=60.0, stiction_force=6.0)
    frequency, magnitude = measured_curve(truth, seed)
    fit = fit_transmissibility(frequency, magnitude, ("viscous_damping",),
                               isolator=qzs.IsolatorParameters(stiction_force=6.0),
                               excitation=CHIRP)
    low, high = fit.intervals["viscous_damping"]
    assert low <= 60.0 <= high and high - low < 3.0, (fit.parameters, (low, high))
    assert fit.isolator.viscous_damping == fit.parameters["viscous_damping"]
    assert fit.residual_rms == pytest.approx(0.03, rel=0.3)
    assert fit.n_simulations < 110 and fit.frequency.min() >= 1.0
    validation(f"Transmissibility fit round trip through the simulator (seed {seed})",
               "Cv = 60 N s/m inside the 95 % interval (3 % noise on |T|)",
               abs(fit.parameters["viscous_damping"] - 60.0) / ((high - low) / 2), 1.0,
               measure="|fit - truth| / 95 % half-width")


def test_two_parameters_with_stiction(curve, tmp_path):
    import matplotlib.pyplot as plt

    fit = fit_transmissibility(*curve, ("viscous_damping", "stiction_force"), excitation=CHIRP)
    assert fit.parameters["viscous_damping"] == pytest.approx(60.0, rel=0.02)
    assert fit.parameters["stiction_force"] == pytest.approx(6.0, rel=0.1)  # plateaus: see doc
    low, high = fit.intervals["stiction_force"]  # coverage: tests/identify/test_transmissibility_coverage.py
    assert low < fit.parameters["stiction_force"] < high and high - low < 0.3 * 6.0
    plt.close(fit.plot(path=tmp_path / "fit.png"))
    assert (tmp_path / "fit.png").exists()


def test_controller_gain_can_be_free(curve):
    fit = fit_transmissibility(*curve, "pi_kp", isolator=qzs.IsolatorParameters(
        viscous_damping=60.0, stiction_force=6.0), excitation=CHIRP, bounds={"pi_kp": (5, 500)})
    assert fit.controller.pi_kp == pytest.approx(50.0, rel=0.3)


def test_bad_input(curve):
    frequency, magnitude = curve
    with pytest.raises(ParameterError, match="unknown or non-numeric parameter.*'friction'"):
        fit_transmissibility(frequency, magnitude, ("friction",))
    with pytest.raises(ParameterError, match="start of 'damping_gain' must be > 0"):
        fit_transmissibility(frequency, magnitude, ("damping_gain",))
    with pytest.raises(ParameterError, match="`bounds` for 'viscous_damping'"):
        fit_transmissibility(frequency, magnitude, ("viscous_damping",), bounds={
            "viscous_damping": (200, 300)})
    with pytest.raises(ParameterError, match=r"unknown parameter\(s\) \['mass'\] in `initial`"):
        fit_transmissibility(frequency, magnitude, ("viscous_damping",), initial={"mass": 6})
    with pytest.raises(ParameterError, match=r"unknown parameter\(s\) \['mass'\] in `bounds`"):
        fit_transmissibility(frequency, magnitude, ("viscous_damping",),
                             bounds={"mass": (1, 9)})
    with pytest.raises(DataError, match="only 1 points of the curve lie in the band"):
        fit_transmissibility(frequency[:12], magnitude[:12], ("viscous_damping", "mass"))
    with pytest.raises(DataError, match="`magnitude` has 1 non-finite"):
        fit_transmissibility(frequency, np.where(frequency == frequency[20], np.nan, magnitude))
    with pytest.raises(ParameterError, match="chirp ends at 10 Hz"):
        fit_transmissibility(frequency, magnitude, band=(1, 20),
                             excitation=qzs.Chirp(f1=10.0, duration=60))


def test_non_convergence_is_an_error(curve):
    with pytest.raises(FitError, match="did not converge after"):
        fit_transmissibility(*curve, ("viscous_damping",), excitation=CHIRP, scan_points=0,
                             max_simulations=2)


def test_bad_jitter_samples(curve):
    with pytest.raises(ParameterError, match="`jitter_samples` must be an integer >= 0"):
        fit_transmissibility(*curve, ("viscous_damping",), jitter_samples=-1)
