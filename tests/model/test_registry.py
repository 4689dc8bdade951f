"""The parameter registry, errors that carry data, and optional dependencies."""
import dataclasses
import pickle
import subprocess
import sys

import pytest

import qzs
from qzs._optional import OPTIONAL, require
from qzs.errors import CaseError, MissingDependencyError, ParameterError
from qzs.model.excitation import EXCITATION_KINDS, EXCITATION_OPTIONS, build_excitation
from qzs.model.registry import (PARAMETERS, SECTIONS, numeric_parameters, parameter_info,
                                parameter_table, unit_of, update_parameters)


def test_every_parameter_has_a_unit_a_doc_and_its_default():
    for name, info in PARAMETERS.items():
        assert info.unit and info.doc, name
        cls = SECTIONS[info.section]
        assert getattr(cls(), name) == info.default, name
    assert [row[1] for row in parameter_table()] == list(PARAMETERS)
    assert unit_of("pi_kp") == "N/m" and unit_of("stribeck_decay") == "s/m"
    assert "stop_center" not in numeric_parameters() and "stop_model" not in numeric_parameters()
    assert "stiction_force" in numeric_parameters()


def test_every_excitation_option_has_a_unit_and_builds_its_kind():
    for kind, options in EXCITATION_OPTIONS.items():
        for option in options:
            info = parameter_info(f"excitation.{option}", kind)
            assert info.unit or option == "record", (kind, option)
    assert unit_of("excitation.f0", "random") == "Hz"
    assert unit_of("excitation.phase") == "rad" and unit_of("excitation.amplitude") == "m"
    for field in dataclasses.fields(qzs.Chirp):
        assert field.metadata["unit"], field.name
    random = build_excitation("random", {"f0": 1.0, "f1": 5.0, "seed": 3.0, "duration": 8.0})
    assert (random.f_low, random.f_high, random.seed) == (1.0, 5.0, 3)
    assert isinstance(build_excitation("chirp"), EXCITATION_KINDS["chirp"])


@pytest.mark.parametrize("kind, options, message", [
    ("square", {}, "`kind` must be one of"),
    ("sine", {"f0": 1.0}, "takes no option(s) ['f0']"),
    ("file", {}, "needs `record`"),
    ("chirp", {"amplitude": -1.0}, "`amplitude` must be non-negative"),
])
def test_the_excitation_factory_names_what_is_wrong(kind, options, message):
    with pytest.raises(qzs.ExcitationError) as error:
        build_excitation(kind, options)
    assert message in str(error.value)


def test_update_parameters_places_each_name_in_its_section():
    isolator, controller = update_parameters(qzs.IsolatorParameters(),
                                             qzs.ControllerParameters(),
                                             {"mass": "7.5", "pi_kp": 12, "stop_center": "none"})
    assert isolator.mass == 7.5 and controller.pi_kp == 12.0 and isolator.stop_center is None
    with pytest.raises(ParameterError, match="unknown parameter 'masss'; valid names are: .*mass"):
        update_parameters(qzs.IsolatorParameters(), qzs.ControllerParameters(), {"masss": 1})
    with pytest.raises(ParameterError, match="unknown parameter 'excitation.f_low'"):
        parameter_info("excitation.f_low")


def test_a_failing_case_is_named_by_an_attribute_not_by_text():
    cases = [(qzs.IsolatorParameters(), qzs.ControllerParameters()),
             (qzs.IsolatorParameters(stop_stiffness=1e12), qzs.ControllerParameters())]
    with pytest.raises(CaseError) as error:
        qzs.simulate_batch(cases, qzs.Chirp(duration=1.0), sample_rate=100.0)
    assert error.value.index == 1 and "largest stable step" in error.value.reason
    assert isinstance(error.value, ParameterError)
    copy = pickle.loads(pickle.dumps(error.value))  # crosses process and Dask boundaries
    assert (copy.index, copy.reason) == (error.value.index, error.value.reason)


def test_a_missing_optional_dependency_names_its_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "asammdf", None)  # makes `import asammdf` fail
    with pytest.raises(MissingDependencyError) as error:
        require("asammdf", "reading MF4 logs")
    assert error.value.extra == "rig" and error.value.package == "asammdf"
    assert 'pip install "qzs[rig]"' in str(error.value)
    assert pickle.loads(pickle.dumps(error.value)).extra == "rig"


BLOCKER = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in {blocked!r}:
            raise ImportError(f"blocked: {{name}}")
sys.meta_path.insert(0, Block())
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
import qzs.workflows.report, qzs.workflows.sweeps
from qzs.iotools.readers import read_recording
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
