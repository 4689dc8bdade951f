"""A sweep's batch task (qzs.workflows.sweeps.batch): each case of a batch is the single run
of its parameters, bit for bit; a case that cannot be built is recorded invalid and the others
run; run_local yields every batch, in order."""
import numpy as np
import pytest

import qzs
from qzs.workflows.sweeps.batch import run_batch, run_local
from qzs.workflows.sweeps.definition import load_sweep
from qzs.workflows.sweeps.store import INVALID, OK

DT = 5e-4  # [s]: two steps per output sample at 1000 Hz

DOCUMENT = {"sweep": {"name": "batch", "batch_size": 3},
            "grid": {"pi_kp": [5.0, 200.0]},
            "parameters": {"pi_ki": 2.0},
            "excitation": {"f1": 10.0},
            "simulation": {"dt": DT},
            "analysis": {"fft_length": 2048, "n_averages": 8, "band": [0.0, 10.0]},
            "outputs": {"time_series": ["relative_position"]}}


@pytest.fixture(scope="module")
def sweep():
    return load_sweep(DOCUMENT)


def test_each_case_is_its_single_run_and_an_invalid_case_is_recorded(sweep):
    duration = sweep.analysis["duration"]
    n_time = int(round(duration * sweep.analysis["sample_rate"])) + 1
    settings = [{"pi_kp": 5.0}, {"pi_kp": -1.0}, {"pi_kp": 200.0}]
    result = run_batch(sweep, 7, settings, n_time, threads=1)
    arrays = result["arrays"]
    assert result["start"] == 7 and result["steps"] > 0 and result["elapsed"] > 0
    assert arrays["status"].tolist() == [OK, INVALID, OK]
    assert "pi_kp" in arrays["message"][1] and arrays["message"][0] == ""
    assert np.isnan(arrays["relative_position"][1]).all()
    for i in (0, 2):
        run = qzs.simulate(qzs.Chirp(f1=10.0, duration=duration), qzs.IsolatorParameters(),
                           qzs.ControllerParameters(pi_kp=settings[i]["pi_kp"], pi_ki=2.0),
                           dt=DT)
        np.testing.assert_array_equal(arrays["relative_position"][i], run.relative_position)
        assert arrays["stop_contacts"][i] == run.run["stop_contacts"]


def test_run_local_yields_every_batch_in_order(sweep):
    settings = [{"pi_kp": 5.0}, {"pi_kp": 50.0}, {"pi_kp": 200.0}]
    results = list(run_local(sweep, [(0, 1), (1, 3)], settings, 0, 1))
    assert [r["start"] for r in results] == [0, 1]
    assert [len(r["arrays"]["status"]) for r in results] == [1, 2]
    together = run_batch(sweep, 0, settings, 0, threads=1)["arrays"]
    for name in ("transmissibility", "peak_stroke"):  # batching does not change a case
        np.testing.assert_array_equal(
            np.concatenate([r["arrays"][name] for r in results]), together[name])


def test_a_sweep_keeps_a_block_channel_as_the_single_run_records_it():
    """A sweep over the compensation fraction keeps `compensation_force` [N] of each case,
    bit for bit the single run's, with its unit in the store's layout."""
    from qzs.workflows.sweeps.store import schema

    document = {**DOCUMENT, "grid": {"compensation.fraction": [0.0, 1.0]},
                "outputs": {"time_series": ["compensation_force"]}}
    sweep = load_sweep(document)
    duration = sweep.analysis["duration"]
    n_time = int(round(duration * sweep.analysis["sample_rate"])) + 1
    settings = [{"compensation.fraction": 0.0}, {"compensation.fraction": 1.0}]
    arrays = run_batch(sweep, 0, settings, n_time, threads=1)["arrays"]
    for i, fraction in enumerate((0.0, 1.0)):
        run = qzs.simulate(qzs.Chirp(f1=10.0, duration=duration), qzs.IsolatorParameters(),
                           qzs.ControllerParameters(pi_ki=2.0, compensation=qzs
                                                    .FrictionCompensation(fraction=fraction)),
                           dt=DT)
        np.testing.assert_array_equal(arrays["compensation_force"][i], run.compensation_force)
    assert np.all(arrays["compensation_force"][0] == 0.0)
    assert np.any(arrays["compensation_force"][1] != 0.0)
    assert schema(sweep, n_time)["compensation_force"][3]["units"] == "N"
