"""The six-axis platform's tab as data (qzs.app.platform): the linear record of the shipped
platform, and the API's own validation."""
import numpy as np
import pytest

from qzs import ControllerParameters
from qzs.errors import ParameterError


def test_platform_tab_is_the_linear_record_of_the_shipped_platform():
    from qzs.app.platform import compute_platform
    from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, linear_record, load_hexapod

    data = compute_platform()
    _, record = linear_record(load_hexapod(SHIPPED_DEFAULT))
    np.testing.assert_allclose(data.natural_frequencies,
                               np.asarray(record["natural_frequencies"], dtype=float))
    assert data.stable == record["stable"]
    assert data.base_joints.shape == data.top_joints.shape == (6, 3)
    assert np.all(data.top_joints[:, 2] > data.base_joints[:, 2])
    assert data.grid_png[:8] == b"\x89PNG\r\n\x1a\n"
    weak = compute_platform({"pi_kp": 50.0, "pi_ki": 20.0})  # the paper's gains: unstable
    assert not weak.stable and np.isnan(weak.natural_frequencies).any()


def test_platform_tab_validates_as_the_api():
    from qzs.app.platform import compute_platform

    with pytest.raises(ParameterError, match="unknown platform setting"):
        compute_platform({"mass": 3.0})
    with pytest.raises(ParameterError) as got:
        compute_platform({"pi_kp": -1.0})
    with pytest.raises(ParameterError) as expected:
        ControllerParameters(pi_kp=-1.0)
    assert str(expected.value) in str(got.value)
