"""A sweep's cases (qzs.workflows.sweeps.cases): each grid point becomes the parameters
and excitation it names, fixed values kept, excitation axes slowest; cases that share an
excitation share its key (they run in one lockstep batch)."""
import itertools

import pytest

from qzs.workflows.sweeps import load_sweep
from qzs.workflows.sweeps.cases import build_case, case_duration, case_settings
from qzs.workflows.sweeps.definition import sample_cases

DOCUMENT = {"sweep": {"name": "cases", "batch_size": 2},
            "grid": {"pi_kp": [5.0, 20.0], "excitation.f1": [10.0, 15.0]},
            "parameters": {"stiction_force": 7.0},
            "excitation": {"amplitude": 0.005, "duration": 12.0},
            "simulation": {"dt": 1e-4},
            "analysis": {"fft_length": 2048, "n_averages": 8, "band": [0.0, 10.0]}}


def test_each_case_is_the_grid_point_it_names():
    definition = load_sweep(DOCUMENT)
    cases = case_settings(definition, sample_cases(definition))
    expected = [{"excitation.f1": f1, "pi_kp": kp}
                for f1, kp in itertools.product([10.0, 15.0], [5.0, 20.0])]
    assert cases == expected
    keys = []
    for case in cases:
        isolator, controller, (excitation, duration), key = build_case(definition, case)
        assert controller.pi_kp == case["pi_kp"] and isolator.stiction_force == 7.0
        assert (excitation.f1, excitation.amplitude) == (case["excitation.f1"], 0.005)
        assert duration == pytest.approx(12.0) == case_duration(definition, case)
        keys.append(key)
    assert keys[0] == keys[1] != keys[2] == keys[3]


# ---------------------------------------------------------------- invalid cases, before any run
def test_invalid_cases_are_named_before_any_case_runs():
    """A negative stiction and a NaN gain: every such case is listed with its values and
    reason, and none runs (a CaseError, so `except CaseError` still catches it)."""
    import math

    from qzs.errors import CaseError, InvalidCasesError
    from qzs.workflows.sweeps.cases import check_cases

    sweep = load_sweep({"sweep": {"name": "bad"}, "analysis": {"fft_length": 1024,
                                                              "n_averages": 4},
                        "grid": {"pi_kp": [5.0, math.nan], "stiction_force": [10.0, -5.0]}})
    with pytest.raises(InvalidCasesError) as caught:
        check_cases(sweep, case_settings(sweep, sample_cases(sweep)))
    error = caught.value
    assert isinstance(error, CaseError) and error.total == 4
    assert [i for i, _, _ in error.cases] == [1, 2, 3]
    assert error.cases[0][1] == {"pi_kp": 5.0, "stiction_force": -5.0}
    assert "`stiction_force` must be non-negative, got -5.0" in error.cases[0][2]
    assert "`pi_kp` must be finite, got nan" in error.cases[1][2]
    assert (error.index, error.reason) == (1, error.cases[0][2])
    assert str(error).startswith("3 of 4 cases are invalid, so none runs: case 1 ("
                                 "pi_kp = 5.0, stiction_force = -5.0)")


def test_an_invalid_excitation_value_names_its_cases():
    from qzs.errors import InvalidCasesError
    from qzs.workflows.sweeps.cases import check_cases

    sweep = load_sweep({"sweep": {"name": "bad"}, "analysis": {"fft_length": 1024,
                                                              "n_averages": 4},
                        "grid": {"excitation.amplitude": [0.01, -0.01], "pi_kp": [5.0, 10.0]}})
    with pytest.raises(InvalidCasesError) as caught:
        check_cases(sweep, case_settings(sweep, sample_cases(sweep)))
    assert [i for i, _, _ in caught.value.cases] == [2, 3]
    assert "`amplitude` must be non-negative" in caught.value.reason


def test_a_batch_keeps_the_accelerations_its_estimates_read_then_the_series_it_stores():
    from qzs.workflows.sweeps.cases import ESTIMATE_CHANNELS, batch_channels, needs_estimates
    from qzs.workflows.sweeps.definition import load_sweep

    base = {"sweep": {"name": "c"}, "grid": {"pi_kp": [5.0]},
            "analysis": {"fft_length": 1024, "n_averages": 4}}
    estimated = load_sweep(base)
    assert needs_estimates(estimated) and batch_channels(estimated) == ESTIMATE_CHANNELS
    series = load_sweep({**base, "outputs": {"time_series": ["payload_acceleration",
                                                             "motor_force"]}})
    assert batch_channels(series) == (*ESTIMATE_CHANNELS, "motor_force")
    plain = load_sweep({**base, "outputs": {"transmissibility": False, "metrics": [],
                                            "time_series": ["motor_force"]}})
    assert not needs_estimates(plain) and batch_channels(plain) == ("motor_force",)


def test_each_output_read_from_the_estimates_needs_them():
    """The transmissibility, the coherence, a metric, a band or an RMS band, each alone, is
    read from the cases' transmissibility estimates: the batch keeps the accelerations."""
    from qzs.workflows.sweeps.cases import ESTIMATE_CHANNELS, batch_channels, needs_estimates
    from qzs.workflows.sweeps.definition import load_sweep

    base = {"sweep": {"name": "c"}, "grid": {"pi_kp": [5.0]},
            "analysis": {"fft_length": 1024, "n_averages": 4}}
    none = {"transmissibility": False, "metrics": []}
    for alone in ({"transmissibility": True}, {"coherence": True},
                  {"metrics": ["resonance_peak"]}, {"bands": {"mid": [2.0, 8.0]}},
                  {"rms_bands": {"mid": [2.0, 8.0]}}):
        sweep = load_sweep({**base, "outputs": {**none, **alone}})
        assert needs_estimates(sweep) and batch_channels(sweep) == ESTIMATE_CHANNELS, alone
    assert not needs_estimates(load_sweep({**base, "outputs": none}))


def test_a_block_channel_that_a_case_lacks_is_refused_before_any_run():
    """`compensation_force` kept from cases without a compensation: every case is named,
    with the fix, before any run; with the block in [parameters] the same sweep is valid."""
    from qzs.errors import InvalidCasesError
    from qzs.workflows.sweeps.cases import check_cases

    document = {**DOCUMENT, "outputs": {"time_series": ["compensation_force"]}}
    sweep = load_sweep(document)
    with pytest.raises(InvalidCasesError) as caught:
        check_cases(sweep, case_settings(sweep, sample_cases(sweep)))
    assert caught.value.total == 4 and len(caught.value.cases) == 4
    reason = caught.value.cases[0][2]
    assert "compensation_force" in reason and "compensation.fraction" in reason
    fixed = load_sweep({**document, "parameters": {"stiction_force": 7.0,
                                                   "compensation.fraction": 0.5}})
    check_cases(fixed, case_settings(fixed, sample_cases(fixed)))
    with pytest.raises(Exception, match="compensation_forse"):
        load_sweep({**document, "outputs": {"time_series": ["compensation_forse"]}})
