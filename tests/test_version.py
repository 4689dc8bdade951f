"""The version is written once (src/qzs/_version.py) and the installed metadata agrees with it."""
from importlib.metadata import version

from qzs import __version__


def test_the_installed_metadata_carries_the_version_of_the_source():
    assert version("qzs") == __version__
