"""The stepped sine with a spring law (issue 41): the hardening Duffing isolator simulated to
its steady state, against the single-harmonic closed form, the sweeps up and down on the two
branches inside the folds, and beside the harmonic balance of the same law."""
import numpy as np
import pytest

from helpers import (DUFFING_HARDENING, duffing_amplitudes, duffing_case,
                     duffing_harmonic_bound, duffing_transmissibility)
from qzs.analysis.harmonic_balance import SmoothModel, periodic_response
from qzs.workflows.response import steady_state_response

#: Relative error allowed for the time integration at the chosen step (its estimate is
#: below 1e-8 dB here), the periodicity tolerance 1e-6 and the DFT of 256 samples [-].
INTEGRATION = 1e-5


@pytest.fixture(scope="module")
def duffing_response():
    k3, amplitude = DUFFING_HARDENING
    isolator, controller = duffing_case(k3)
    response = steady_state_response([1.15, 1.3, 1.36, 1.45], amplitude, isolator, controller,
                                     direction="both", harmonic_balance=True,
                                     balance_harmonics=7, workers=1)
    return k3, amplitude, response


def test_the_steady_state_is_the_closed_form_within_the_harmonics_bound(duffing_response):
    """Each settled point's fundamental: off the folds the closed form's one root, inside
    them (1.36 Hz, folds at 1.349 and 1.372 Hz) the up sweep on the upper root and the down
    sweep on the lower (the jump's hysteresis, 5.4 mm against 2.3 mm), within the third
    harmonic's bound (``helpers.duffing_harmonic_bound``, the simulated third harmonic) plus
    the integration's error; the transmissibility as the closed form's at that amplitude."""
    k3, amplitude, response = duffing_response
    assert all(p.converged for p in response.points)
    for point in response.points:
        roots = duffing_amplitudes(point.frequency, k3, amplitude)
        if roots.size == 3:
            closed = roots[-1] if point.direction == "up" else roots[0]
        else:
            (closed,) = roots
        third = point.harmonics[1] * amplitude / 9  # payload acceleration ratio 9 |Z3| / Y
        allowed = duffing_harmonic_bound(point.frequency, k3, closed, third)
        assert abs(point.relative_amplitude - closed) <= allowed + INTEGRATION * closed, point
        expected = duffing_transmissibility(point.frequency, k3, amplitude, closed)
        assert point.transmissibility == pytest.approx(expected, rel=0.01)
    inside = {p.direction: p.relative_amplitude for p in response.points if p.frequency == 1.36}
    assert inside["up"] > 2 * inside["down"]


def test_the_steady_state_is_the_harmonic_balance_of_the_same_law(duffing_response):
    """Off the folds the sweeps and the harmonic balance (7 harmonics, drawn beside them and
    solved here at the sweep's frequencies) agree to the integration's error."""
    k3, amplitude, response = duffing_response
    assert response.balance is not None and response.balance.frequency.size > 10
    model = SmoothModel.from_parameters(response.isolator, response.controller,
                                        amplitude=amplitude)
    assert model.spring_law == response.isolator.spring
    for point in response.points:
        if point.frequency == 1.36:
            continue
        solution = periodic_response(point.frequency, model, harmonics=7)
        assert point.relative_amplitude == pytest.approx(solution.relative_amplitude,
                                                         rel=INTEGRATION)
        assert point.transmissibility == pytest.approx(solution.transmissibility,
                                                       rel=INTEGRATION)
    top = float(np.max(response.balance.relative_amplitude))
    assert top == pytest.approx(duffing_amplitudes(1.36, k3, amplitude)[-1], rel=0.02)



def test_the_responses_files_record_the_law(duffing_response, tmp_path):
    """The dataset and the NetCDF and CSV files write the law as a run's records do:
    ``isolator.spring.law`` and its fields with their units."""
    import qzs

    _, _, response = duffing_response
    attrs = response.to_xarray().attrs
    assert attrs["isolator.spring.law"] == "polynomial"
    assert list(attrs["isolator.spring.coefficients"]) == list(
        response.isolator.spring.coefficients)
    assert attrs["isolator.spring.center"] == -0.060
    assert attrs["isolator.spring.center_units"] == "m"
    read = qzs.read_result(response.save(tmp_path / "duffing.nc")).attrs
    assert read["isolator.spring.law"] == "polynomial"
    assert list(read["isolator.spring.coefficients"]) == list(attrs["isolator.spring.coefficients"])
    text = response.save(tmp_path / "duffing.csv").read_text(encoding="utf-8")
    assert "# isolator.spring.law = polynomial" in text
