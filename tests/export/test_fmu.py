"""The exported FMU, checked with FMPy, the tool users have (issue 33).

FMPy validates every FMU's model description (schema, names, model structure, start values,
causality/variability, units) and simulates it: the closed-loop FMU with an internal
excitation reproduces :func:`qzs.simulate` at the same step and solver (every channel within
1e-12 of its range; in fact to the bit, the C being the kernels' operation for operation);
fed base-motion inputs it converges on the DisplacementRecord run at second order in the
communication step (the stated extrapolation); the plant FMU driven by the exported
controller in an FMPy loop reproduces the closed loop; bad calls get an FMI error status and
a logged reason, never a crash.
"""
import ctypes
import zipfile

import numpy as np
import pytest

import qzs
from qzs.engine.base_motion import base_motion_series
from qzs.engine.channels import CHANNELS
from qzs.errors import CompilerError, MissingDependencyError, ParameterError
from qzs.export import fmu as export

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

try:
    from qzs.export.csource import find_compiler
    find_compiler()
except CompilerError:  # pragma: no cover
    pytest.skip("no C compiler", allow_module_level=True)

CHIRP = qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=20.0)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fmus")


def exported(folder, name, **kwargs):
    path = folder / f"{name}.fmu"
    if not path.exists():
        export.export_fmu(path, **kwargs)
    return path


def compare(result, reference, channels=None):
    """The largest difference of each channel over its range: {channel: value}."""
    out = {}
    for name in channels or [c for c in CHANNELS if c != "time"]:
        ours = np.asarray(reference[name])
        theirs = np.asarray(result[name])
        out[name] = np.abs(theirs - ours).max() / (np.ptp(ours) or 1.0)
    return out


@pytest.mark.parametrize("fmi_version", [3, 2])
@pytest.mark.parametrize("mode", ["closed-loop", "plant"])
@pytest.mark.parametrize("base_motion", ["internal", "input"])
def test_every_kind_of_fmu_validates(folder, fmi_version, mode, base_motion):
    excitation = CHIRP if base_motion == "internal" else None
    path = exported(folder, f"{fmi_version}-{mode}-{base_motion}", excitation=excitation,
                    fmi_version=fmi_version, mode=mode, base_motion=base_motion)
    assert validate_fmu(str(path)) == []
    description = read_model_description(str(path))
    names = {v.name: v for v in description.modelVariables}
    for name, info in qzs.model.registry.PARAMETERS.items():
        variable = names[f"{info.section}.{name}"]
        assert variable.causality == "parameter" and variable.start is not None
        if info.unit and info.unit != "-":
            assert variable.unit == info.unit
            assert variable.unit in description.unitDefinitions.__class__.__name__ or any(
                unit.name == info.unit for unit in description.unitDefinitions)
    assert names["isolator.mass"].description == "moving mass m"
    inputs = {v.name for v in description.modelVariables if v.causality == "input"}
    assert ("motor_force" in inputs) == (mode == "plant")
    assert ({"base_displacement", "base_velocity", "base_acceleration"} <= inputs) == (
        base_motion == "input")
    outputs = {v.name for v in description.modelVariables if v.causality == "output"}
    assert {"relative_position", "payload_acceleration", "friction_force", "stop_force",
            "spring_force", "base_work", "friction_dissipation", "locked",
            "stop_contact"} <= outputs
    with zipfile.ZipFile(path) as archive:
        files = set(archive.namelist())
    binary = f"binaries/{export.platform_folder(fmi_version)}/isolator.so"
    assert binary in files and "sources/qzs_plant.c" in files and "sources/qzs_fmu.c" in files
    assert ("sources/buildDescription.xml" in files) == (fmi_version == 3)
    assert not any(name.startswith("sources/fmi") and name.endswith(".h") for name in files)


def test_the_build_description_follows_the_standards_schema(folder):
    lxml = pytest.importorskip("lxml.etree")
    from pathlib import Path

    path = exported(folder, "3-closed-loop-internal", excitation=CHIRP)
    schema = Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3BuildDescription.xsd"
    with zipfile.ZipFile(path) as archive:
        document = lxml.fromstring(archive.read("sources/buildDescription.xml"))
        listed = {e.get("name") for e in document.iter("SourceFile")}
        assert {f"sources/{name}" for name in listed} <= set(archive.namelist())
    lxml.XMLSchema(lxml.parse(str(schema))).assertValid(document)


@pytest.mark.parametrize("fmi_version", [3, 2])
def test_the_closed_loop_fmu_reproduces_simulate(folder, fmi_version):
    """The paper's chirp (shortened) through FMPy and through qzs.simulate, dt = 1e-4 s, ode3,
    communication every 1 ms: every channel within 1e-12 of its range, and to the bit."""
    path = exported(folder, f"{fmi_version}-closed-loop-internal", excitation=CHIRP,
                    fmi_version=fmi_version)
    result = simulate_fmu(str(path), stop_time=20.0, output_interval=1e-3)
    reference = qzs.simulate(CHIRP, duration=20.0, dt=1e-4, sample_rate=1000.0)
    assert reference.run["stick_events"] > 0
    differences = compare(result, reference)
    assert max(differences.values()) <= 1e-12, differences
    for name in differences:
        np.testing.assert_array_equal(result[name], np.asarray(reference[name]), err_msg=name)
    np.testing.assert_array_equal(result["locked"], np.asarray(reference.locked))


def test_parameters_set_through_fmi_are_the_runs(folder):
    """Plastic stops, a sampled controller, rk4 and a sine, all set through FMI on the default
    FMU: the run qzs.simulate makes with the same parameters."""
    path = exported(folder, "3-closed-loop-internal", excitation=CHIRP)
    start = {"isolator.stop_model": 1, "controller.controller_rate": 500.0,
             "controller.damping_gain": 300.0, "solver": 2, "excitation.kind": 2,
             "excitation.amplitude": 0.1, "excitation.f0": 2.0, "excitation.fade_in": 0.5}
    result = simulate_fmu(str(path), stop_time=3.0, output_interval=1e-3, start_values=start)
    reference = qzs.simulate(
        qzs.Sine(amplitude=0.1, frequency=2.0, fade_in=0.5),
        qzs.IsolatorParameters(stop_model="plastic"),
        qzs.ControllerParameters(controller_rate=500.0, damping_gain=300.0),
        duration=3.0, dt=1e-4, sample_rate=1000.0, solver="rk4")
    assert reference.run["stop_contacts"] > 0
    assert max(compare(result, reference).values()) <= 1e-12


def test_base_motion_inputs_converge_on_the_record_at_second_order(folder):
    """A record's displacement, velocity and acceleration fed at the communication points:
    the FMU extrapolates the acceleration linearly over each step (docs/fmu.md), so the run
    approaches the DisplacementRecord run as h**2."""
    t = np.arange(0.0, 4.0001, 0.005)
    random = qzs.RandomExcitation(amplitude=0.003, f_high=15.0, duration=4.0, seed=2)
    record = qzs.DisplacementRecord(time=t, displacement=base_motion_series(random, t)[0],
                                    fade_in=0.0)
    reference = qzs.simulate(record, duration=3.0, dt=1e-4, sample_rate=1000.0)
    path = exported(folder, "3-closed-loop-input", base_motion="input")
    errors = []
    for h in (1e-3, 5e-4):
        times = np.arange(0.0, 3.0 + h / 2, h)
        y, yd, ydd = base_motion_series(record, times)
        signal = np.array(list(zip(times, y, yd, ydd)), dtype=[
            ("time", float), ("base_displacement", float), ("base_velocity", float),
            ("base_acceleration", float)])
        result = simulate_fmu(str(path), stop_time=3.0, output_interval=h, input=signal)
        errors.append(compare(result[::int(round(1e-3 / h))], reference,
                              ["relative_position", "spring_force", "motor_force"]))
    for name in errors[0]:
        assert errors[1][name] < 1e-3, (name, errors)
        assert errors[0][name] / errors[1][name] > 3.0, (name, errors)  # second order


def run_plant_loop(path, controller, duration, period):
    """The plant FMU (FMI 3) in an FMPy loop with the exported controller, every ``period``."""
    from qzs.export.controller import exported_parameters

    parameters, preload = exported_parameters(controller, dt=1e-4)
    description = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    plant = FMU3Slave(guid=description.guid, unzipDirectory=extract(str(path)),
                      modelIdentifier=description.coSimulation.modelIdentifier)
    plant.instantiate()
    law = qzs.engine.laws.controller_law.py_func
    integral = preload
    command = law(parameters["position_setpoint"], parameters["pi_kp"], parameters["pi_ki"],
                  parameters["damping_gain"], parameters["motor_force_max"],
                  parameters["position_setpoint"], 0.0, integral)
    plant.enterInitializationMode()
    plant.setFloat64([refs["motor_force"]], [command[2]])
    plant.exitInitializationMode()
    names = ["relative_position", "measured_payload_velocity", "friction_force"]
    rows = []
    steps = int(round(duration / period))
    lib = controller_library(controller)
    state = lib.state
    for k in range(steps + 1):
        z, measured, friction = plant.getFloat64([refs[n] for n in names])
        rows.append((z, friction))
        if k == steps:
            break
        out = lib.qzs_controller_step(ctypes.byref(state), z, measured)
        plant.setFloat64([refs["motor_force"]], [out.motor])
        plant.doStep(k * period, period)
    plant.terminate()
    plant.freeInstance()
    return np.array(rows)


def controller_library(controller):
    """The exported controller.c compiled and initialised (tests/export/test_controller.py)."""
    import tempfile
    from pathlib import Path

    from helpers import Controller, Parameters
    from helpers import build_controller as build

    from qzs.export import controller as exported_controller

    folder = Path(tempfile.mkdtemp(prefix="qzs-controller-"))
    lib = build(folder, exported_controller.controller_source(controller, dt=1e-4))
    lib.state = Controller()
    lib.qzs_controller_init(ctypes.byref(lib.state),
                            Parameters.in_dll(lib, exported_controller.PARAMETERS_NAME),
                            ctypes.c_double.in_dll(lib, exported_controller.PRELOAD_NAME).value)
    return lib


def test_the_plant_fmu_driven_by_the_exported_controller_is_the_closed_loop(folder):
    controller = qzs.ControllerParameters(controller_rate=1000.0, damping_gain=200.0)
    path = exported(folder, "3-plant-internal", excitation=CHIRP, mode="plant")
    rows = run_plant_loop(path, controller, 10.0, 1e-3)
    reference = qzs.simulate(CHIRP, None, controller, duration=10.0, dt=1e-4,
                             sample_rate=1000.0)
    for column, name in enumerate(["relative_position", "friction_force"]):
        ours = np.asarray(reference[name])
        assert np.abs(rows[:, column] - ours).max() <= 1e-12 * np.ptp(ours), name
    assert reference.run["stick_events"] > 0


# ---------------------------------------------------------------- bad calls through FMI
class Logged:
    """An FMI 3 instance of an FMU whose log messages are kept."""

    def __init__(self, path):
        description = read_model_description(str(path))
        self.refs = {v.name: v.valueReference for v in description.modelVariables}
        self.messages = []
        self.fmu = FMU3Slave(guid=description.guid, unzipDirectory=extract(str(path)),
                             modelIdentifier=description.coSimulation.modelIdentifier)

        def log(environment, status, category, message):
            self.messages.append((status, category.decode(), message.decode()))
        self.fmu.instantiate(loggingOn=True, logMessage=log)

    def failing(self, call, *args):
        before = len(self.messages)
        with pytest.raises(FMICallException) as caught:
            call(*args)
        assert caught.value.status == 3
        assert len(self.messages) > before and self.messages[-1][0] == 3
        return self.messages[-1][2]


def test_bad_calls_get_an_error_status_and_a_logged_reason(folder):
    path = exported(folder, "3-closed-loop-internal", excitation=CHIRP)
    fmu = Logged(path)
    f = fmu.fmu
    assert "no variable has value reference 999" in fmu.failing(f.setFloat64, [999], [1.0])
    assert "is an output" in fmu.failing(f.setFloat64, [fmu.refs["relative_position"]], [1.0])
    assert "not Float64" in fmu.failing(f.setFloat64, [fmu.refs["solver"]], [1.0])
    assert "not a finite number" in fmu.failing(f.setFloat64, [fmu.refs["isolator.mass"]],
                                                [float("nan")])
    f.enterInitializationMode()
    f.setFloat64([fmu.refs["isolator.mass"]], [-6.4])
    message = fmu.failing(f.exitInitializationMode)
    assert "isolator.mass" in message and "-6.4" in message and "positive" in message
    f.setFloat64([fmu.refs["isolator.mass"]], [6.4])
    f.exitInitializationMode()
    assert "fixed parameter" in fmu.failing(f.setFloat64, [fmu.refs["isolator.mass"]], [7.0])
    message = fmu.failing(f.doStep, 0.0, 2.5e-4 * 1.5)
    assert "not a whole number of internal steps" in message and "0.000375" in message
    f.doStep(0.0, 1e-3)  # the FMU goes on after a refused call
    assert "is not the FMU's time" in fmu.failing(f.doStep, 0.0, 1e-3)
    f.terminate()
    f.freeInstance()


def test_a_rate_that_is_no_whole_number_of_steps_and_model_exchange_are_refused(folder):
    path = exported(folder, "3-closed-loop-internal", excitation=CHIRP)
    fmu = Logged(path)
    fmu.fmu.enterInitializationMode()
    fmu.fmu.setFloat64([fmu.refs["controller.controller_rate"]], [333.0])
    assert "controller_rate" in fmu.failing(fmu.fmu.exitInitializationMode)
    fmu.fmu.freeInstance()
    description = read_model_description(str(path))
    from fmpy.fmi3 import FMU3Model

    model = FMU3Model(guid=description.guid, unzipDirectory=extract(str(path)),
                      modelIdentifier=description.coSimulation.modelIdentifier)
    messages = []
    with pytest.raises(Exception):
        model.instantiate(logMessage=lambda e, s, c, m: messages.append(m.decode()))
    assert any("model exchange is not supported" in m for m in messages)


def test_fmi2_bad_calls_are_logged_through_the_callbacks(folder):
    path = exported(folder, "2-closed-loop-internal", excitation=CHIRP, fmi_version=2)
    description = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    messages = []

    def log(environment, name, status, category, message):
        messages.append((status, message.decode()))
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(log)
    callbacks.allocateMemory = fmpy.fmi2.fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
    callbacks.freeMemory = fmpy.fmi2.fmi2CallbackFreeMemoryTYPE(fmpy.free)
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(path)),
                    modelIdentifier=description.coSimulation.modelIdentifier)
    fmu.instantiate(callbacks=callbacks)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([refs["isolator.mass"]], [-1.0])
    with pytest.raises(FMICallException):
        fmu.exitInitializationMode()
    assert messages[-1][0] == 3 and "isolator.mass" in messages[-1][1]
    fmu.setReal([refs["isolator.mass"]], [6.4])
    fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        fmu.doStep(0.0, 1.5e-4)
    assert "not a whole number of internal steps" in messages[-1][1]
    fmu.terminate()
    fmu.freeInstance()


# ---------------------------------------------------------------- the export's own checks
def test_bad_export_arguments_are_refused_before_compiling(tmp_path):
    with pytest.raises(ParameterError, match="fmi_version"):
        export.export_fmu(tmp_path / "a.fmu", fmi_version=4)
    with pytest.raises(ParameterError, match="Chirp or a Sine"):
        export.export_fmu(tmp_path / "a.fmu", qzs.RandomExcitation())
    with pytest.raises(ParameterError, match="--out|path"):
        export.export_fmu(tmp_path / "a.zip")
    with pytest.raises(qzs.StabilityError):
        export.export_fmu(tmp_path / "a.fmu", CHIRP, dt=0.05)
    assert list(tmp_path.iterdir()) == []


def test_without_fmpy_the_export_names_the_extra(monkeypatch, tmp_path):
    import sys

    monkeypatch.setitem(sys.modules, "fmpy", None)
    with pytest.raises(MissingDependencyError) as caught:
        export.export_fmu(tmp_path / "a.fmu", CHIRP)
    assert caught.value.extra == "fmu"
    assert list(tmp_path.iterdir()) == []
