"""Files shipped with qzs (qzs.iotools.shipped): the package's folders listed, a shipped file
found by its name without the order prefix, a path used as given."""
from pathlib import Path

import pytest

from qzs.errors import ParameterError
from qzs.iotools.shipped import resolve_shipped, shipped_files

SOURCE = Path(__file__).resolve().parents[2] / "src" / "qzs"


@pytest.mark.parametrize("folder", ["workflows/paper/study_files", "workflows/sweeps/sweep_files",
                                    "workflows/hexapod/hexapod_files"])
def test_the_listing_is_the_folders_toml_files_in_order(folder):
    expected = sorted(p.name for p in (SOURCE / folder).glob("*.toml"))
    assert expected and [p.name for p in shipped_files(folder)] == expected


def test_a_shipped_file_is_named_without_its_order_prefix(tmp_path):
    found = resolve_shipped("stiction", "workflows/paper/study_files", "study", "studies")
    assert found.name == "02_stiction.toml" and found.exists()
    own = tmp_path / "stiction"
    own.write_text("")
    assert resolve_shipped(own, "workflows/paper/study_files", "study", "studies") == own
    with pytest.raises(ParameterError, match=r"study file not found: 'nope'; shipped studies "
                                             r"are \['damping', 'no_pi', 'pi_gains'"):
        resolve_shipped("nope", "workflows/paper/study_files", "study", "studies")


def test_a_folder_named_as_a_shipped_file_does_not_hide_it(tmp_path, monkeypatch):
    """A command's output folder is named as its shipped problem (``qzs optimize
    isolation_vs_effort`` writes ``isolation_vs_effort/``); run again in the same place, the
    name must still be the shipped file, not the folder (a folder is never the file)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "isolation_vs_effort").mkdir()
    found = resolve_shipped("isolation_vs_effort", "workflows/design_space/problem_files",
                            "problem", "problems")
    assert found.is_file() and found.suffix == ".toml"
    (tmp_path / "mine").mkdir()  # a folder that names no shipped file stays what it is
    assert resolve_shipped("mine", "workflows/design_space/problem_files", "problem",
                           "problems") == Path("mine")
