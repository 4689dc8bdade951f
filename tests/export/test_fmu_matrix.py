"""Every FMU qzs writes, exported with its defaults, starts and runs through FMPy to its default
stop time as ``qzs simulate`` runs the same inputs (issue 39): each internal excitation
(linear and logarithmic chirp, sine) and the base motion as inputs, closed loop and plant,
FMI 3.0 and 2.0. Plant mode is fed the motor force the closed loop computed (sampled at the
communication rate, the value at t_k+1 held over [t_k, t_k+1]: docs/fmu.md §5); base-motion
inputs are fed the base motion a qzs run recorded.

The same FMUs are validated (schema, names, units against the registry, the files inside),
rebuilt from their own ``sources/`` with every warning an error, and their parameters'
variability held to what the FMU does. Each FMU is compiled once per session
(tests/export/conftest.py: ``fmus``); the chirps are 4 s long, the sine and the inputs run
their 10 s default.
"""
import functools
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

import qzs
from qzs.engine.channels import CHANNELS
from qzs.export import fmu as export
from qzs.export.csource import CFLAGS, find_compiler
from qzs.model.registry import PARAMETERS, unit_of

from export.fmu_support import EXCITATIONS, Logged, compare, recorded_inputs

fmpy = pytest.importorskip("fmpy")
from fmpy import read_model_description, simulate_fmu  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

#: The base motion fed to the input FMUs: a qzs run's own record of this sine.
FED = EXCITATIONS["sine"]
MODES = ("closed-loop", "plant")
VERSIONS = (3, 2)
MATRIX = [(e, m, v) for e in EXCITATIONS for m in MODES for v in VERSIONS]
#: Largest difference over a channel's range allowed [-]: an internal excitation is stepped
#: as qzs steps it (to the bit, in fact); fed base motion is extrapolated over each step
#: (docs/fmu.md §6: the acceleration within h^2 max|d4y/dt4|, second order in the
#: communication step h), measured 1.1e-3 of the payload acceleration's range (2.7e-4 of the
#: relative position's) at 1 ms.
TOLERANCE = {"internal": 1e-12, "input": 2e-3}


@functools.lru_cache(maxsize=None)
def reference_of(excitation, mode, duration, step):
    """The qzs run the FMU's defaults make: its excitation (or the one fed), at the FMU's
    internal step, the controller sampled at the communication rate in plant mode."""
    controller = qzs.ControllerParameters(controller_rate=1.0 / step) if mode == "plant" else None
    return qzs.simulate(EXCITATIONS[excitation] or FED, None, controller, duration=duration,
                        dt=1e-4, sample_rate=1.0 / step)


@pytest.mark.parametrize("excitation, mode, version", MATRIX)
def test_every_fmu_starts_with_its_defaults_and_runs_as_qzs_simulate(fmus, excitation, mode,
                                                                    version):
    path = fmus(excitation, mode, version)
    experiment = read_model_description(str(path)).defaultExperiment
    stop, step = float(experiment.stopTime), float(experiment.stepSize)
    source = EXCITATIONS[excitation]
    assert stop == (source.duration if source is not None and source.duration else 10.0)
    reference = reference_of(excitation, mode, stop, step)
    signal = recorded_inputs(reference, step, motor=mode == "plant", base=source is None)
    result = simulate_fmu(str(path), output_interval=step, input=signal)  # default stop time
    assert result["time"][-1] == pytest.approx(stop) and len(result) == len(reference.time)
    skipped = ({"time", "pi_force", "damping_force", "motor_force"} if mode == "plant"
               else {"time"})  # the plant's motor force is its input
    differences = compare(result, reference, [c for c in CHANNELS if c not in skipped and (
        source is not None or c not in ("base_displacement", "base_velocity",
                                        "base_acceleration"))])
    tolerance = TOLERANCE["internal" if source is not None else "input"]
    assert max(differences.values()) <= tolerance, differences
    if source is not None:  # the C is the kernels operation for operation: the same bits
        for name in differences:
            np.testing.assert_array_equal(result[name], np.asarray(reference[name]), name)
        np.testing.assert_array_equal(result["locked"], np.asarray(reference.locked))
    np.testing.assert_array_equal(result["stop_contact"], np.asarray(reference.stop_contact))
    assert np.ptp(np.asarray(reference.relative_position)) > 1e-4  # the payload moved
    assert reference.run["stick_events"] > 0  # and stuck and slipped


@pytest.mark.parametrize("excitation, mode, version", MATRIX)
def test_every_fmu_validates_with_the_registrys_units(fmus, excitation, mode, version):
    path = fmus(excitation, mode, version)
    assert validate_fmu(str(path)) == []
    description = read_model_description(str(path))
    names = {v.name: v for v in description.modelVariables}
    declared = {unit.name for unit in description.unitDefinitions}
    for name, info in PARAMETERS.items():
        variable = names[f"{info.section}.{name}"]
        assert variable.causality == "parameter" and variable.start is not None
        if info.unit not in ("", "-", "1"):
            assert variable.unit == info.unit and info.unit in declared, name
    source = EXCITATIONS[excitation]
    if source is not None:
        kind = "sine" if isinstance(source, qzs.Sine) else "chirp"
        registry = {"amplitude": (kind, "amplitude"), "fade_in": (kind, "fade_in"),
                    "f0": ("chirp", "f0") if kind == "chirp" else ("sine", "frequency"),
                    "f1": ("chirp", "f1"), "duration": ("chirp", "duration"),
                    "phase": ("sine", "phase")}
        for suffix, (of, option) in registry.items():
            assert names[f"excitation.{suffix}"].unit == unit_of(f"excitation.{option}", of), \
                suffix
    assert names["step_size"].unit == "s"
    for name, (_, unit, _) in CHANNELS.items():
        if name in names and unit:
            assert names[name].unit == unit, name
    assert names["isolator.mass"].description == "moving mass m"
    inputs = {v.name for v in description.modelVariables if v.causality == "input"}
    assert ("motor_force" in inputs) == (mode == "plant")
    assert ({"base_displacement", "base_velocity", "base_acceleration"} <= inputs) == (
        source is None)
    outputs = {v.name for v in description.modelVariables if v.causality == "output"}
    assert {"relative_position", "payload_acceleration", "friction_force", "stop_force",
            "spring_force", "base_work", "friction_dissipation", "locked",
            "stop_contact"} <= outputs
    with zipfile.ZipFile(path) as archive:
        files = set(archive.namelist())
    binary = f"binaries/{export.platform_folder(version)}/isolator.so"
    assert binary in files and "sources/qzs_plant.c" in files and "sources/qzs_fmu.c" in files
    assert ("sources/buildDescription.xml" in files) == (version == 3)
    assert not any(name.startswith("sources/fmi") and name.endswith(".h") for name in files)


def test_a_sine_or_input_fmu_runs_ten_seconds_by_default_and_a_chirp_its_sweep(fmus):
    """The default experiment: the excitation's length, else the 10 s ``qzs simulate`` runs
    a sine for (docs/fmu.md §1)."""
    for excitation, expected in (("sine", 10.0), ("input", 10.0), ("chirp-log", 4.0)):
        experiment = read_model_description(str(fmus(excitation, "closed-loop", 3)))
        assert float(experiment.defaultExperiment.stopTime) == expected, excitation
    assert export.default_stop_time(qzs.Chirp(duration=7.5)) == 7.5
    assert export.default_stop_time(None) == export.default_stop_time(qzs.Sine()) == 10.0


@pytest.mark.parametrize("mode, version", [(m, v) for m in MODES for v in VERSIONS])
def test_a_parameter_is_changed_after_initialisation_only_if_declared_tunable(fmus, mode,
                                                                             version):
    """FMI: a ``tunable`` parameter may be set between steps, a ``fixed`` one not; what the
    model description declares is what the FMU does."""
    path = fmus("chirp-linear", mode, version)
    variables = [v for v in read_model_description(str(path)).modelVariables
                 if v.causality == "parameter"]
    assert {v.variability for v in variables} <= {"fixed", "tunable"}
    instance = Logged(path, version)
    instance.enter()
    instance.fmu.exitInitializationMode()
    instance.fmu.doStep(0.0, 1e-3)
    for variable in variables:
        value = float(variable.start)
        setter = {"Real": "Real", "Float64": "Float64", "Integer": "Integer",
                  "Int32": "Int32"}[variable.type]
        call = getattr(instance.fmu, f"set{setter}")
        if variable.variability == "tunable":
            call([variable.valueReference], [type(value)(value)])
        else:
            message = instance.failing(call, [variable.valueReference],
                                       [int(value) if variable.type in ("Integer", "Int32")
                                        else value])
            assert "fixed parameter" in message and variable.name in message
    instance.free()


#: The compiler flags of a rebuild from sources/ (docs/fmu.md §12): the export's, with every
#: warning an error.
STRICT = ("-Wall", "-Wextra", "-pedantic", "-Werror")


def rebuild(path, folder, version):
    """The FMU at ``path`` rebuilt from its own sources/ into ``folder`` (its list of sources
    read from buildDescription.xml, FMI 3, or the model description, FMI 2)."""
    unpacked = folder / "unpacked"
    with zipfile.ZipFile(path) as archive:
        archive.extractall(unpacked)
    if version == 3:
        listed = ET.parse(unpacked / "sources" / "buildDescription.xml").iter("SourceFile")
    else:
        listed = ET.parse(unpacked / "modelDescription.xml").iter("File")
    sources = [str(unpacked / "sources" / e.get("name")) for e in listed]
    binary = unpacked / "binaries" / export.platform_folder(version) / "isolator.so"
    binary.unlink()
    command = [find_compiler(), *CFLAGS, *STRICT, "-fvisibility=hidden", "-shared",
               f"-I{unpacked / 'sources'}", f"-I{export.fmi_headers(version)}", "-o",
               str(binary), *sources, "-lm"]
    done = subprocess.run(command, capture_output=True, text=True)
    assert done.returncode == 0 and not done.stderr, done.stderr
    rebuilt = folder / "rebuilt.fmu"
    shutil.make_archive(str(rebuilt.with_suffix("")), "zip", unpacked)
    rebuilt.with_suffix(".zip").rename(rebuilt)
    return rebuilt


@pytest.mark.parametrize("excitation, mode", [("chirp-linear", "closed-loop"),
                                              ("input", "plant")])
@pytest.mark.parametrize("version", VERSIONS)
def test_the_sources_rebuild_warning_free_and_the_rebuilt_fmu_is_the_same(fmus, tmp_path,
                                                                          excitation, mode,
                                                                          version):
    """Both modes and both kinds of base motion (every branch of the sources' #if) compile
    with -Wall -Wextra -pedantic -Werror, and the FMU rebuilt so gives the same run, to
    the bit."""
    path = fmus(excitation, mode, version)
    rebuilt = rebuild(path, tmp_path, version)
    reference = reference_of(excitation, mode, 1.0, 1e-3)
    signal = recorded_inputs(reference, 1e-3, motor=mode == "plant",
                             base=EXCITATIONS[excitation] is None)
    runs = [simulate_fmu(str(fmu), stop_time=1.0, output_interval=1e-3, input=signal)
            for fmu in (path, rebuilt)]
    for name in runs[0].dtype.names:
        np.testing.assert_array_equal(runs[1][name], runs[0][name], err_msg=name)
