"""The sweep's checks and step choice (qzs.workflows.response.sweep): bad input refused
before any work, the step chosen for an accuracy by default."""
import pytest

from qzs import ControllerParameters, ParameterError
from qzs.workflows.response import SAMPLES_PER_PERIOD, steady_state_response


@pytest.mark.parametrize("arguments, options, name", [
    (([-1.0, 2.0],), {}, "frequencies"),
    (([float("nan")],), {}, "frequencies"),
    (([],), {}, "frequencies"),
    (([2.0], 0.0), {}, "amplitude"),
    (([2.0],), {"direction": "sideways"}, "direction"),
    (([2.0],), {"dt": 1e-3, "tolerance": 0.01}, "dt"),
    (([2.0],), {"dt": 0.05}, "dt"),
    (([60.0],), {"dt": 1e-3}, "frequencies"),
    (([2.0],), {"harmonics": 100}, "harmonics"),
    (([2.0],), {"periodic_tolerance": 0.5}, "periodic_tolerance"),
    (([2.0],), {"max_periods": 2}, "max_periods"),
    (([2.0],), {"workers": 0}, "workers"),
])
def test_bad_input_is_refused_before_any_work(arguments, options, name):
    with pytest.raises(ParameterError, match=name):
        steady_state_response(*arguments, harmonic_balance=False, **options)


def test_a_sampled_controller_is_refused():
    with pytest.raises(ParameterError, match="controller_rate"):
        steady_state_response([2.0], controller=ControllerParameters(controller_rate=1000.0),
                              dt=1e-3)


def test_the_step_is_chosen_for_accuracy_by_default():
    response = steady_state_response([3.0, 6.0], direction="up", harmonic_balance=False,
                                     workers=1)
    assert response.step is not None and response.dt == response.step.dt
    assert any("accuracy-driven" in note and "(tolerance 0.01 dB" in note
               for note in response.notes)
    for p in response.points:
        assert p.dt <= response.dt and round(1 / (p.frequency * p.dt)) % SAMPLES_PER_PERIOD == 0


def test_1e8_frequencies_fail_at_once():
    import time

    import numpy as np

    from qzs.errors import CountLimitError
    from qzs.workflows.response.sweep import MAX_FREQUENCIES

    frequencies = np.linspace(1.0, 20.0, 10 ** 8)
    began = time.perf_counter()
    with pytest.raises(CountLimitError) as caught:
        steady_state_response(frequencies)
    assert time.perf_counter() - began < 2.0
    assert (caught.value.count, caught.value.limit) == (10 ** 8, MAX_FREQUENCIES)


def test_tolerance_db_is_the_deprecated_name_of_tolerance():
    """One release more: it warns with the new name, and means what ``tolerance`` means (so
    with a ``dt`` it is refused as ``tolerance`` is)."""
    with pytest.warns(DeprecationWarning, match="use `tolerance`"), \
            pytest.raises(ParameterError, match="`dt`.*`tolerance`.*not both"):
        steady_state_response([2.0], dt=1e-3, tolerance_db=0.01)
    with pytest.raises(ParameterError, match="give `tolerance` only"):
        steady_state_response([2.0], tolerance=0.01, tolerance_db=0.01)
