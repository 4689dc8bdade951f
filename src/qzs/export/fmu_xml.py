"""The XML of the isolator FMU: ``modelDescription.xml`` (FMI 2.0 or 3.0) and FMI 3.0's
``sources/buildDescription.xml``.

Written with :mod:`xml.etree.ElementTree` from the variable table of
:mod:`qzs.export.fmu_variables` (an array's elements one FMI 3 array variable with its
``Dimension``, FMI 2 scalars ``name[k]``); every unit used is declared in
``UnitDefinitions`` with its SI base-unit exponents. Co-simulation only: the FMU steps itself (fixed internal step, events
inside the step), so the importer needs no event handling.
"""
import xml.etree.ElementTree as ET

from qzs._version import __version__
from qzs.export.fmu_variables import UNITS

__all__ = ["model_description", "build_description", "LOG_CATEGORIES"]

#: The log categories the FMU reports in.
LOG_CATEGORIES = {"logEvents": "information on the run",
                  "logStatusWarning": "warnings", "logStatusError": "errors: why a call failed"}
_FMI3_TYPES = {"F": "Float64", "I": "Int32", "B": "Boolean"}
_FMI2_TYPES = {"F": "Real", "I": "Integer", "B": "Boolean"}


def _number(value, kind):
    if kind == "I":
        return str(int(value))
    if kind == "B":
        return "true" if value else "false"
    return repr(float(value))


def _units(parent, variables):
    used = sorted({v.unit for v in variables if v.unit})
    definitions = ET.SubElement(parent, "UnitDefinitions")
    for name in used:
        unit = ET.SubElement(definitions, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", {key: str(value) for key, value in UNITS[name].items()})


def _categories(parent):
    categories = ET.SubElement(parent, "LogCategories")
    for name, description in LOG_CATEGORIES.items():
        ET.SubElement(categories, "Category", name=name, description=description)


def _text(root):
    ET.indent(root, space="  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def model_description(variables, *, fmi_version, model_identifier, token, description,
                      dt, stop_time, step, sources, generated):
    """``modelDescription.xml`` of the FMU.

    Parameters
    ----------
    variables : tuple of FmuVariable
        :func:`qzs.export.fmu_variables.fmu_variables`.
    fmi_version : {2, 3}
        FMI version.
    model_identifier : str
        Name of the binary and prefix of nothing (the functions are unprefixed).
    token : str
        Instantiation token (FMI 3) or GUID (FMI 2).
    description : str
        The model's one-line description.
    dt : float
        The internal step [s] (FMI 3 ``fixedInternalStepSize``).
    stop_time : float
        Default experiment's stop time [s].
    step : float
        Default experiment's communication step [s].
    sources : sequence of str
        The C files in ``sources/`` (FMI 2 lists them here).
    generated : str
        ISO 8601 date and time of the export.

    Returns
    -------
    str
    """
    version = "3.0" if fmi_version == 3 else "2.0"
    common = dict(fmiVersion=version, modelName=model_identifier, description=description,
                  generationTool=f"qzs {__version__}", generationDateAndTime=generated,
                  variableNamingConvention="structured")
    if fmi_version == 3:
        root = ET.Element("fmiModelDescription", instantiationToken=token, **common)
        ET.SubElement(root, "CoSimulation", modelIdentifier=model_identifier,
                      canHandleVariableCommunicationStepSize="true",
                      fixedInternalStepSize=repr(float(dt)), hasEventMode="false",
                      canGetAndSetFMUState="false", canSerializeFMUState="false",
                      providesDirectionalDerivatives="false",
                      providesAdjointDerivatives="false")
    else:
        root = ET.Element("fmiModelDescription", guid=token, numberOfEventIndicators="0",
                          **common)
        cosim = ET.SubElement(root, "CoSimulation", modelIdentifier=model_identifier,
                              canHandleVariableCommunicationStepSize="true",
                              canInterpolateInputs="false", maxOutputDerivativeOrder="0",
                              canGetAndSetFMUstate="false", canSerializeFMUstate="false",
                              providesDirectionalDerivative="false")
        files = ET.SubElement(cosim, "SourceFiles")
        for name in sources:
            ET.SubElement(files, "File", name=name)
    _units(root, variables)
    _categories(root)
    ET.SubElement(root, "DefaultExperiment", startTime="0.0", stopTime=repr(float(stop_time)),
                  stepSize=repr(float(step)))
    model_variables = ET.SubElement(root, "ModelVariables")
    listed = []
    for i, v in enumerate(variables):
        if fmi_version == 2 and v.causality == "independent":
            continue  # FMI 2 has no time variable
        if fmi_version == 3 and v.array and i > 0 and variables[i - 1].array == v.array:
            continue  # an element of the FMI 3 array its first element declares
        listed.append(v)
        attributes = dict(name=v.name, valueReference=str(v.reference),
                          description=v.description, causality=v.causality)
        if v.causality == "parameter":
            attributes.update(variability="fixed")
        elif v.causality != "independent":
            attributes.update(variability="discrete" if v.type in "IB" else "continuous")
        if fmi_version == 3:
            elements = [w for w in variables if w.array == v.array] if v.array else [v]
            if v.array:
                attributes["name"] = v.array
            if v.unit and v.type == "F":
                attributes["unit"] = v.unit
            if v.start is not None:
                attributes["start"] = " ".join(_number(w.start, w.type) for w in elements)
            declared = ET.SubElement(model_variables, _FMI3_TYPES[v.type], attributes)
            if v.array:
                ET.SubElement(declared, "Dimension", start=str(len(elements)))
        else:
            if v.causality == "output":
                attributes["initial"] = "calculated"
            scalar = ET.SubElement(model_variables, "ScalarVariable", attributes)
            typed = {}
            if v.start is not None:
                typed["start"] = _number(v.start, v.type)
            if v.unit and v.type == "F":
                typed["unit"] = v.unit
            ET.SubElement(scalar, _FMI2_TYPES[v.type], typed)
    structure = ET.SubElement(root, "ModelStructure")
    outputs = [(i, v) for i, v in enumerate(listed, start=1) if v.causality == "output"]
    if fmi_version == 3:
        for _, v in outputs:
            ET.SubElement(structure, "Output", valueReference=str(v.reference))
        for _, v in outputs:
            ET.SubElement(structure, "InitialUnknown", valueReference=str(v.reference))
    else:
        block = ET.SubElement(structure, "Outputs")
        for index, _ in outputs:
            ET.SubElement(block, "Unknown", index=str(index))
        block = ET.SubElement(structure, "InitialUnknowns")
        for index, _ in outputs:
            ET.SubElement(block, "Unknown", index=str(index))
    return _text(root)


def build_description(*, model_identifier, sources):
    """FMI 3.0's ``sources/buildDescription.xml``: the C files of one build, in C99.

    Parameters
    ----------
    model_identifier : str
        The FMU's model identifier.
    sources : sequence of str
        The ``.c`` files to compile (in ``sources/``).

    Returns
    -------
    str
    """
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    configuration = ET.SubElement(root, "BuildConfiguration", modelIdentifier=model_identifier,
                                  description="qzs's C model of the isolator and its FMI 3.0 "
                                              "interface. Compile without fast-math and without "
                                              "implicit contraction into fused multiply-adds "
                                              "(gcc/clang: -ffp-contract=off) to get qzs's bits; "
                                              "link the C math library")
    files = ET.SubElement(configuration, "SourceFileSet", language="C99")
    for name in sources:
        ET.SubElement(files, "SourceFile", name=name)
    ET.SubElement(configuration, "Library", name="m",
                  description="the C math library (libm; part of the C runtime elsewhere)")
    return _text(root)
