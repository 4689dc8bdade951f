"""The Sobol indices of Ishigami's function, computed once for the sensitivity tests."""
import pytest

from qzs.workflows.design_space.sensitivity import sensitivity

from workflows.design_space.ishigami import ishigami, ishigami_problem


@pytest.fixture(scope="session")
def ishigami_sobol():
    return sensitivity(ishigami_problem(samples=2 ** 12), evaluate=ishigami, progress=False)
