"""A sweep's cases (qzs.workflows.sweeps.backends): each grid point becomes the parameters
and excitation it names, fixed values kept, excitation axes slowest; cases that share an
excitation share its key (they run in one lockstep batch)."""
import itertools

import pytest

from qzs.workflows.sweeps import load_sweep
from qzs.workflows.sweeps.backends import build_case, case_duration, case_settings
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
