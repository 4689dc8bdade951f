"""The exported FMU, checked with FMPy, the tool users have (issues 33, 39).

The closed-loop FMU with an internal excitation reproduces :func:`qzs.simulate` at the same
step and solver (every channel within 1e-12 of its range; in fact to the bit, the C being the
kernels' operation for operation), with parameters set through FMI too (plastic and compliant
stops, a sampled controller, rk4, a sine); fed base-motion inputs it converges on the
DisplacementRecord run at second order in the communication step (the stated
extrapolation); the plant FMU driven by the exported controller in an FMPy loop reproduces
the closed loop, and left alone it holds the payload at the setpoint. The FMI behaviours
(refused calls, steps, stop time) are tests/export/test_fmu_fmi.py's; every kind of FMU with
its defaults is tests/export/test_fmu_matrix.py's.
"""
import ctypes
import zipfile

import numpy as np
import pytest
from helpers import EXPORT_PASSIVE

import qzs
from qzs.engine.base_motion import base_motion_series
from qzs.errors import MissingDependencyError, ParameterError
from qzs.export import fmu as export

from export.fmu_support import compare, starts

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402

CHIRP = qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=20.0)


def test_the_build_description_follows_the_standards_schema(fmus):
    lxml = pytest.importorskip("lxml.etree")
    from pathlib import Path

    path = fmus("chirp-linear")
    schema = Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3BuildDescription.xsd"
    with zipfile.ZipFile(path) as archive:
        document = lxml.fromstring(archive.read("sources/buildDescription.xml"))
        listed = {e.get("name") for e in document.iter("SourceFile")}
        assert {f"sources/{name}" for name in listed} <= set(archive.namelist())
    lxml.XMLSchema(lxml.parse(str(schema))).assertValid(document)


def test_parameters_set_through_fmi_are_the_runs(fmus):
    """Plastic stops, a sampled controller, rk4 and a sine, all set through FMI on a chirp's
    FMU: the run qzs.simulate makes with the same parameters."""
    path = fmus("chirp-linear")
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


def test_compliant_stop_contact_through_fmi_is_the_run(fmus):
    """The passive isolator driven into its compliant stops, whose damping (2500 N*s/m) is not
    the guide's viscous damping (100 N*s/m): the contact force, its dissipation and the
    motion are qzs.simulate's."""
    path = fmus("chirp-linear")
    start = {"controller.pi_kp": 0.0, "controller.pi_ki": 0.0, "isolator.stop_damping": 2500.0,
             "excitation.kind": 2, "excitation.amplitude": 0.1, "excitation.f0": 2.0,
             "excitation.fade_in": 0.5}
    result = simulate_fmu(str(path), stop_time=3.0, output_interval=1e-3, start_values=start)
    reference = qzs.simulate(qzs.Sine(amplitude=0.1, frequency=2.0, fade_in=0.5),
                             qzs.IsolatorParameters(stop_damping=2500.0), EXPORT_PASSIVE,
                             duration=3.0, dt=1e-4, sample_rate=1000.0)
    assert reference.run["stop_contacts"] > 0 and reference.isolator.stop_model == "compliant"
    assert np.asarray(reference.stop_dissipation)[-1] > 0.1  # [J]: the stop's damper worked
    differences = compare(result, reference)
    assert max(differences.values()) <= 1e-12, differences


def test_the_plant_fmu_holds_the_payload_until_its_input_is_connected(fmus):
    """``motor_force`` starts at the force that holds the setpoint statically: with the base at
    rest (its inputs unconnected) and no friction to hold it, the payload stays at the
    setpoint; at 0 N (what it started at before) it sinks. The start is the force qzs
    preloads its PI with (the kernels' static balance)."""
    path = fmus("input", "plant")
    variable = starts(path)["motor_force"]
    preload = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), duration=0.01, dt=1e-4,
                           sample_rate=1000.0).motor_force[0]
    assert float(variable.start) == pytest.approx(preload, rel=1e-12, abs=1e-12)
    assert "holds the setpoint" in variable.description
    frictionless = {"isolator.stiction_force": 0.0, "isolator.coulomb_force": 0.0}
    setpoint = qzs.ControllerParameters().position_setpoint
    held = simulate_fmu(str(path), stop_time=5.0, output_interval=1e-2,
                        start_values=frictionless)
    assert np.abs(held["relative_position"] - setpoint).max() < 1e-9
    dropped = simulate_fmu(str(path), stop_time=5.0, output_interval=1e-2,
                           start_values={**frictionless, "motor_force": 0.0})
    assert dropped["relative_position"][-1] < setpoint - 1e-3


def test_base_motion_inputs_converge_on_the_record_at_second_order(fmus):
    """A record's displacement, velocity and acceleration fed at the communication points:
    the FMU extrapolates the acceleration linearly over each step (docs/fmu.md), so the run
    approaches the DisplacementRecord run as h**2."""
    t = np.arange(0.0, 4.0001, 0.005)
    random = qzs.RandomExcitation(amplitude=0.003, f_high=15.0, duration=4.0, seed=2)
    record = qzs.DisplacementRecord(time=t, displacement=base_motion_series(random, t)[0],
                                    fade_in=0.0)
    reference = qzs.simulate(record, duration=3.0, dt=1e-4, sample_rate=1000.0)
    path = fmus("input")
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


def test_the_plant_fmu_driven_by_the_exported_controller_is_the_closed_loop(fmus):
    from export.fmu_support import EXCITATIONS

    controller = qzs.ControllerParameters(controller_rate=1000.0, damping_gain=200.0)
    path = fmus("chirp-linear", "plant")
    rows = run_plant_loop(path, controller, 4.0, 1e-3)
    reference = qzs.simulate(EXCITATIONS["chirp-linear"], None, controller, duration=4.0,
                             dt=1e-4, sample_rate=1000.0)
    for column, name in enumerate(["relative_position", "friction_force"]):
        ours = np.asarray(reference[name])
        assert np.abs(rows[:, column] - ours).max() <= 1e-12 * np.ptp(ours), name
    assert reference.run["stick_events"] > 0


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
    for bad in (0.0, -1e-3, float("nan"), float("inf")):
        with pytest.raises(ParameterError) as caught:
            export.export_fmu(tmp_path / "a.fmu", CHIRP, communication_step=bad)
        assert caught.value.options == ("communication_step",) and repr(bad) in str(caught.value)
    with pytest.raises(ParameterError) as caught:
        export.export_fmu(tmp_path / "a.fmu", CHIRP, communication_step=30.0)
    assert "must not exceed `duration`" in str(caught.value)
    with pytest.raises(ParameterError) as caught:
        export.export_fmu(tmp_path / "a.fmu", qzs.Sine(frequency=0.0))
    assert caught.value.options == ("frequency",) and "0.0 Hz" in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_without_fmpy_the_export_names_the_extra(monkeypatch, tmp_path):
    import sys

    monkeypatch.setitem(sys.modules, "fmpy", None)
    with pytest.raises(MissingDependencyError) as caught:
        export.export_fmu(tmp_path / "a.fmu", CHIRP)
    assert caught.value.extra == "fmu"
    assert list(tmp_path.iterdir()) == []
