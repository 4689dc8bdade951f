"""The FMU's XML: FMPy reads and validates the model description of both FMI versions; the
build description lists the sources."""
import xml.etree.ElementTree as ET

import pytest

import qzs
from qzs.engine import kernels as K
from qzs.export.fmu_variables import fmu_variables
from qzs.export.fmu_xml import build_description, model_description

VARIABLES = fmu_variables(isolator=qzs.IsolatorParameters(), controller=qzs.ControllerParameters(),
                          excitation_scalars=qzs.Chirp().pack()[0], dt=1e-4,
                          solver_code=K.SOLVER_ODE3, mode="closed-loop", base_motion="internal")
SOURCES = ("qzs_plant.c", "fmi3_api.c")


def describe(version):
    return model_description(VARIABLES, fmi_version=version, model_identifier="isolator",
                             token="{0}", description="test", dt=1e-4, stop_time=10.0,
                             step=1e-3, sources=SOURCES, generated="2026-01-01T00:00:00Z")


@pytest.mark.parametrize("version", [2, 3])
def test_fmpy_reads_and_validates_it(tmp_path, version):
    fmpy = pytest.importorskip("fmpy")
    (tmp_path / "modelDescription.xml").write_text(describe(version))
    description = fmpy.read_model_description(str(tmp_path), validate=True,
                                              validate_variable_names=True,
                                              validate_model_structure=True)
    names = [v.name for v in description.modelVariables]
    expected = [v.name for v in VARIABLES if version == 3 or v.causality != "independent"]
    assert names == expected
    assert description.coSimulation.modelIdentifier == "isolator"
    assert description.defaultExperiment.stepSize == "0.001" or float(
        description.defaultExperiment.stepSize) == 1e-3
    used = {v.unit for v in VARIABLES if v.unit and v.type == "F"}
    assert {unit.name for unit in description.unitDefinitions} == used


def test_fmi2_structure_indices_point_at_the_outputs():
    root = ET.fromstring(describe(2))
    scalars = root.find("ModelVariables").findall("ScalarVariable")
    indices = [int(u.get("index")) for u in root.find("ModelStructure/Outputs")]
    assert indices and all(scalars[i - 1].get("causality") == "output" for i in indices)
    assert len(indices) == sum(v.causality == "output" for v in VARIABLES)
    assert [f.get("name") for f in root.iter("File")] == list(SOURCES)


def test_the_build_description_lists_the_sources():
    root = ET.fromstring(build_description(model_identifier="isolator", sources=SOURCES))
    assert root.get("fmiVersion") == "3.0"
    assert [f.get("name") for f in root.iter("SourceFile")] == list(SOURCES)
    assert root.find("BuildConfiguration").get("modelIdentifier") == "isolator"
