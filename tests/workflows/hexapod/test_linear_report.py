"""The linear report of a six-axis set-up (qzs.workflows.hexapod.linear_report), against the
cubic configuration's closed form: six legs of axial stiffness k along three orthogonal
directions (two legs each) make an isotropic translational stiffness 2 k at the cube's
centre, uncoupled from the rotations."""
import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.workflows.hexapod.linear_report import linear_record, linear_text
from qzs.workflows.hexapod.platform_setup import hexapod_setup
from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod


def test_the_cubic_platform_is_isotropic_in_translation_at_the_cube_centre():
    setup = load_hexapod(SHIPPED_DEFAULT)
    k = 1000.0
    model, record = linear_record(setup, leg_stiffness=k, frame="cube_center",
                                  include_preload=False)
    stiffness = np.asarray(record["stiffness_matrix"])
    np.testing.assert_allclose(stiffness[:3, :3], 2 * k * np.eye(3), atol=1e-9 * k)
    np.testing.assert_allclose(stiffness[:3, 3:], 0.0, atol=1e-9 * k)
    np.testing.assert_allclose(stiffness, stiffness.T, atol=1e-9 * k)
    assert record["frame"] == "cube_center" and record["leg_stiffness"] == k
    text = linear_text(setup, model, record)
    assert "matrices at the cube's centre, without the preload stiffness" in text
    assert f"every leg's axial stiffness set to {k:g} N/m" in text


def test_the_cube_centre_needs_a_cubic_geometry():
    from qzs.model.hexapod import radial_geometry

    radial = hexapod_setup(geometry=radial_geometry(base_radius=0.2, top_radius=0.15,
                                                    base_angle=0.2, top_angle=0.2, height=0.1),
                           kind="radial")
    with pytest.raises(ParameterError, match="`frame` 'cube_center' needs a cubic geometry"):
        linear_record(radial, frame="cube_center")
