"""A case's spectral reduction (qzs.workflows.sweeps.reduction): a payload that is the base
scaled by g has transmissibility g in every bin, coherence 1, and every band mean, band RMS
and metric at a frequency equal to g (a closed form: H1 = S_xy/S_xx = g)."""
import numpy as np
import pytest

from qzs.workflows.sweeps.definition import load_sweep
from qzs.workflows.sweeps.reduction import reduce_case
from qzs.workflows.sweeps.store import COUNTS, schema

GAIN = 0.37


def arrays_of(definition, n):
    arrays = {}
    for name, (dims, dtype, fill, _) in schema(definition, 0).items():
        shape = tuple(n if d == "case" else definition.frequency.size for d in dims)
        if name in COUNTS:
            dtype, fill = np.float64, np.nan
        arrays[name] = np.full(shape, fill, dtype=object if name == "message" else dtype)
    return arrays


def test_a_scaled_payload_has_that_transmissibility_everywhere():
    definition = load_sweep({
        "sweep": {"name": "reduce"}, "grid": {"pi_kp": [5.0]},
        "analysis": {"fft_length": 1024, "n_averages": 8, "band": [0.5, 20.0],
                     "at_frequencies": [2.0]},
        "outputs": {"coherence": True, "bands": {"low": [1.0, 3.0]},
                    "rms_bands": {"mid": [2.0, 8.0]}}})
    rate = definition.analysis["sample_rate"]
    base = np.random.default_rng(3).standard_normal(int(definition.analysis["duration"] * rate))
    arrays = arrays_of(definition, 2)
    reduce_case(definition, base, GAIN * base, arrays, 1)
    assert np.isnan(arrays["transmissibility"][0]).all()  # only row 1 is written
    np.testing.assert_allclose(arrays["transmissibility"][1], GAIN, rtol=1e-12)
    np.testing.assert_allclose(arrays["coherence"][1], 1.0, rtol=1e-12)
    assert arrays["mean_transmissibility_low"][1] == pytest.approx(GAIN, rel=1e-12)
    assert arrays["rms_transmissibility_mid"][1] == pytest.approx(GAIN, rel=1e-12)
    assert arrays["transmissibility_at_2_hz"][1] == pytest.approx(GAIN, rel=1e-12)
    assert arrays["n_averages"][1] >= 8


def test_a_batch_is_estimated_at_once_each_case_as_alone_and_a_bad_case_fails_alone():
    """estimate_cases: each case's estimate the same bits as its own transmissibility; a
    case the analysis refuses (NaN samples) gets its own error and the others their
    estimates."""
    from qzs.analysis.spectral import transmissibility
    from qzs.errors import DataError
    from qzs.workflows.sweeps.reduction import estimate_cases

    definition = load_sweep({"sweep": {"name": "reduce"}, "grid": {"pi_kp": [5.0]},
                             "analysis": {"fft_length": 1024, "n_averages": 8}})
    a = definition.analysis
    rng = np.random.default_rng(5)
    base = rng.standard_normal((5, int(a["duration"] * a["sample_rate"])))
    payload = np.cumsum(rng.standard_normal(base.shape), axis=1) * 0.01 + GAIN * base
    for bad in (None, 2):
        if bad is not None:
            payload[bad, 100] = np.nan
        estimates = estimate_cases(definition, base, payload)
        assert len(estimates) == 5
        for i, estimate in enumerate(estimates):
            if i == bad:
                assert isinstance(estimate, DataError) and "non-finite" in str(estimate)
                continue
            alone = transmissibility(base[i], payload[i], a["sample_rate"],
                                     fft_length=a["fft_length"], overlap=a["overlap"])
            for name in ("magnitude", "phase", "coherence", "trusted"):
                assert np.array_equal(getattr(estimate, name), getattr(alone, name),
                                      equal_nan=True)
            arrays, given = arrays_of(definition, 1), arrays_of(definition, 1)
            reduce_case(definition, base[i], payload[i], arrays, 0)
            reduce_case(definition, None, None, given, 0, estimate=estimate)
            for name in arrays:
                assert np.array_equal(arrays[name], given[name],
                                      equal_nan=arrays[name].dtype.kind == "f"), name
