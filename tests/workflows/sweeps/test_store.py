"""A sweep's Zarr store (qzs.workflows.sweeps.store): a batch written is read back as written,
counts stay integers (-1 where a run has none), the cases not yet run stay pending."""
import numpy as np
import pytest

from qzs.workflows.sweeps import load_sweep
from qzs.workflows.sweeps.definition import sample_cases
from qzs.workflows.sweeps.store import (COUNT_FILL, STATUS, open_store, prepare_store, schema,
                                        write_batch)

pytest.importorskip("zarr")

DOCUMENT = {"sweep": {"name": "store", "batch_size": 2},
            "grid": {"pi_kp": [5.0, 20.0, 50.0, 80.0]},
            "simulation": {"dt": 1e-4},
            "analysis": {"fft_length": 2048, "n_averages": 8, "band": [0.0, 10.0]},
            "outputs": {"stats": ["z_min", "stick_events"], "metrics": []}}


def test_a_written_batch_reads_back_and_the_rest_stays_pending(tmp_path):
    definition = load_sweep(DOCUMENT)
    store = tmp_path / "store.zarr"
    done = prepare_store(store, definition, sample_cases(definition), 0)
    assert not done.any() and done.size == 4
    sizes = {"case": 2, "frequency": definition.frequency.size}
    arrays = {name: np.full([sizes[d] for d in dims], fill,
                            dtype=object if name == "message" else dtype)
              for name, (dims, dtype, fill, _) in schema(definition, 0).items()}
    arrays["status"][:] = [1, 3]                     # ok, failed
    arrays["message"][:] = ["", "diverged at t = 1 s"]
    arrays["z_min"][:] = [-0.07, np.nan]
    arrays["stick_events"] = np.array([12.0, np.nan])  # a float count, NaN for the failure
    write_batch(store, definition, 2, arrays, 0)
    data = open_store(store).load()
    assert data["done"].values.tolist() == [False, False, True, True]
    assert [STATUS[s] for s in data["status"].values] == ["pending", "pending", "ok", "failed"]
    assert data["message"].values.tolist()[2:] == ["", "diverged at t = 1 s"]
    np.testing.assert_array_equal(data["z_min"].values, [np.nan, np.nan, -0.07, np.nan])
    assert data["stick_events"].dtype.kind == "i"
    assert data["stick_events"].values.tolist()[2:] == [12, COUNT_FILL]
    np.testing.assert_array_equal(data["pi_kp"].values, [5.0, 20.0, 50.0, 80.0])
