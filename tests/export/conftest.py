"""The FMUs the export's tests share: each compiled once per session (a compilation takes
about a second), in one temporary folder."""
import pytest


@pytest.fixture(scope="session")
def fmu_folder(tmp_path_factory):
    """The folder the session's FMUs are exported into."""
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def fmus(fmu_folder):
    """``fmus(excitation, mode="closed-loop", version=3)``: an FMU of the matrix
    (``export.fmu_support.EXCITATIONS``), exported with defaults when first used."""
    from export.fmu_support import matrix_exporter

    return matrix_exporter(fmu_folder)
