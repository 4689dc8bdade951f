"""The six-axis transmissibility's settings: the platform's size that makes rotations lengths."""
import numpy as np
import pytest

from qzs.model.hexapod import cubic_geometry
from qzs.workflows.hexapod.transmissibility.settings import _scale, platform_size


def test_the_size_is_the_top_joints_rms_distance_from_their_centroid():
    """Against a hand computation on the cubic geometry's joints."""
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    joints = np.asarray(geometry.top_joints)
    centroid = joints.sum(axis=0) / 6
    expected = np.sqrt(sum(np.dot(j - centroid, j - centroid) for j in joints) / 6)
    assert platform_size(geometry) == pytest.approx(expected, rel=1e-14)


def test_the_scale_turns_rotations_into_lengths_and_back():
    """A rotation per translation counts times the size, a translation per rotation over it."""
    scale = _scale(0.2)
    assert np.allclose(np.diag(scale), 1.0)
    assert scale[3, 0] == pytest.approx(0.2) and scale[0, 3] == pytest.approx(5.0)
    assert np.allclose(scale * scale.T, 1.0)
