"""Optional dependencies (qzs._optional): a missing one names the extra that installs it, and
the base install simulates and reports without any of them."""
import pickle
import subprocess
import sys

import pytest

from qzs._optional import OPTIONAL, require
from qzs.errors import MissingDependencyError


def test_a_missing_optional_dependency_names_its_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "asammdf", None)  # makes `import asammdf` fail
    with pytest.raises(MissingDependencyError) as error:
        require("asammdf", "reading MF4 logs")
    assert error.value.extra == "rig" and error.value.package == "asammdf"
    assert 'pip install "qzs[rig]"' in str(error.value)
    assert pickle.loads(pickle.dumps(error.value)).extra == "rig"


# An import of a blocked package fails, and asking whether it is there
# (importlib.util.find_spec, as xarray does for dask) says no, as for a package not installed.
BLOCKER = """
import importlib.util
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in {blocked!r}:
            raise ImportError(f"blocked: {{name}}")
sys.meta_path.insert(0, Block())
_find_spec = importlib.util.find_spec
def find_spec(name, package=None):
    if name.split('.')[0] in {blocked!r}:
        return None
    return _find_spec(name, package)
importlib.util.find_spec = find_spec
"""


def test_the_base_install_simulates_and_reports_without_the_extras(tmp_path):
    """Without asammdf, dask, distributed and zarr: simulate and a study run; MF4 says how."""
    blocked = sorted(OPTIONAL)
    code = BLOCKER.format(blocked=blocked) + f"""
from qzs.cli import main
assert main(["simulate", "--excitation", "sine", "--frequency", "3", "--duration", "0.5",
             "--plot", "none", "--quiet"]) == 0
assert main(["study", "spring", "--out", {str(tmp_path / "study")!r}, "--workers", "1",
             "--quiet"]) == 0
import qzs.workflows.paper.report, qzs.workflows.sweeps
from qzs.iotools.rig import read_recording
from qzs.errors import MissingDependencyError
open({str(tmp_path / "log.mf4")!r}, "wb").write(b"MDF     ")
open({str(tmp_path / "map.toml")!r}, "w").write('[channels.base_velocity]\\nsource = "b"\\nunit = "m/s"\\n')
try:
    read_recording({str(tmp_path / "log.mf4")!r}, {str(tmp_path / "map.toml")!r})
except MissingDependencyError as error:
    print("MISSING", error.extra)
for name in {blocked!r}:
    assert name not in sys.modules, name
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "MISSING rig" in done.stdout
    assert (tmp_path / "study" / "report.html").exists()
