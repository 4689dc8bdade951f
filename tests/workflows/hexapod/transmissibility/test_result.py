"""The result's views agree with its arrays: file, record and summary from one matrix."""
import numpy as np
import pytest

from qzs.model.hexapod import PlatformParameters, cubic_geometry
from qzs.workflows.hexapod.setups import hexapod_setup
from qzs.workflows.hexapod.transmissibility import matrix, plan


@pytest.fixture(scope="module")
def by_hand():
    """A matrix built by hand around a known z/z entry of 0.5 (no simulation)."""
    setup = hexapod_setup(geometry=cubic_geometry(cube_edge=0.3, cube_center_height=0.3),
                          platform=PlatformParameters(mass=22.17,
                                                      inertia=np.diag([0.3, 0.3, 0.5])))
    axes, amplitudes, common, _, _ = plan._plan(
        setup, ("z",), None, 0.0, 20.0, 60.0, 1e-3, None, None, None, "h1", -100.0, 1, False)
    n = common["fft_length"] // 2 + 1
    frequency = np.arange(n) * common["sample_rate"] / common["fft_length"]
    response = np.zeros((6, n), dtype=complex)
    response[2] = 0.5
    column = dict(axis="z", frequency=frequency, response=response,
                  coherence=np.ones((6, n)), trusted=np.ones((6, n), dtype=bool),
                  record=dict(energy_residual=0.0, base_work_max=1.0))
    return matrix._assemble(setup, axes, amplitudes, common, {"z": column})


def test_the_dataset_holds_the_matrix_with_its_flags(by_hand):
    data = by_hand.to_xarray()
    magnitude = data["magnitude"].sel(output_dof="z", input_dof="z").values
    np.testing.assert_array_equal(magnitude, np.abs(by_hand.response[:, 2, 2]))
    np.testing.assert_array_equal(data["trusted"].values, by_hand.trusted.astype(np.int8))
    assert data["excited"].sel(input_dof="z").item() == 1
    assert data["excited"].sel(input_dof="x").item() == 0
    assert all("units" in data[name].attrs for name in ("magnitude", "phase", "coherence"))


def test_the_amplitudes_are_per_base_axis_and_undefined_where_not_excited(by_hand):
    amplitude = by_hand.to_xarray()["amplitude"]
    assert amplitude.sel(input_dof="z").item() == pytest.approx(by_hand.amplitude["z"])
    assert np.isnan(amplitude.sel(input_dof="rx").item())
