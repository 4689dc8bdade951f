"""The FMU runs every spring law as ``qzs simulate`` does (issue 41).

An oblique-spring QZS at its quasi-zero condition, a cubic polynomial and a table sampled from
the tanh that extends, each exported in FMI 3.0 and 2.0 and started by FMPy with its own
defaults (no start value set): every recorded channel equals :func:`qzs.simulate`'s to the
bit, and the energy ledger closes on the FMU's outputs. The law's numbers are FMU parameters
with units (a table's positions and forces an FMI 3 array with its ``Dimension``, FMI 2
scalars ``spring.positions[k]``); a changed one (an oblique spring's stiffness, a polynomial's
coefficient, a table's forces, computed into PCHIP pieces by the C) gives the run qzs makes
with the law changed so. A run that leaves a table refusing positions outside it fails with an
error that says so, and positions that do not increase are refused at initialisation.
"""
import dataclasses

import numpy as np
import pytest
from export.fmu_support import Logged, exported, starts
from helpers import (EXPORT_LEAVING_SINE, EXPORT_REFUSING_TABLE, EXPORT_SETTINGS,
                     EXPORT_SPRING_LAWS, EXPORT_SPRING_SINE)

import qzs
from qzs.errors import SimulationError
from qzs.model.springs import TabulatedSpring

fmpy = pytest.importorskip("fmpy")
from fmpy import simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402

VERSIONS = (3, 2)
DURATION = 1.5
STEP = 1.0 / EXPORT_SETTINGS["sample_rate"]


def _fmu(folder, name, version, law, excitation=EXPORT_SPRING_SINE):
    return exported(folder, f"spring-{name.replace(' ', '-')}-{version}", excitation=excitation,
                    isolator=qzs.IsolatorParameters(spring=law), fmi_version=version,
                    dt=EXPORT_SETTINGS["dt"], duration=DURATION, communication_step=STEP)


def _simulate(law, excitation=EXPORT_SPRING_SINE):
    return qzs.simulate(excitation, qzs.IsolatorParameters(spring=law), duration=DURATION,
                        **EXPORT_SETTINGS)


def _assert_same(result, reference):
    for channel in set(reference.channels) - {"time"}:
        np.testing.assert_array_equal(np.asarray(result[channel], dtype=float),
                                      np.asarray(reference[channel], dtype=float),
                                      err_msg=channel)


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", list(EXPORT_SPRING_LAWS))
def test_the_fmu_of_every_law_with_its_own_defaults_is_qzs_simulate(fmu_folder, name, version):
    law = EXPORT_SPRING_LAWS[name]
    result = simulate_fmu(str(_fmu(fmu_folder, name, version, law)), stop_time=DURATION,
                          output_interval=STEP)  # no start values: the FMU's own defaults
    reference = _simulate(law)
    assert np.ptp(np.asarray(reference.relative_position)) > 5e-3  # m: the law is travelled
    _assert_same(result, reference)
    # the energy ledger closes on the FMU's outputs: dE = W_base + W_motor - D_friction - D_stop
    energy = sum(np.asarray(result[c]) for c in ("kinetic_energy", "spring_energy",
                                                 "gravity_energy", "stop_energy"))
    work = (np.asarray(result["base_work"]) + np.asarray(result["motor_work"])
            - np.asarray(result["friction_dissipation"]) - np.asarray(result["stop_dissipation"]))
    throughput = np.abs(np.asarray(result["base_work"])).max()
    assert throughput > 0.01  # J
    assert np.abs((energy - energy[0]) - work).max() < 1e-8 * throughput
    # the stored energy is the law's
    np.testing.assert_allclose(result["spring_energy"], law.energy(result["relative_position"]),
                               rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("version", VERSIONS)
def test_the_laws_parameters_are_the_fmus_with_units(fmu_folder, version):
    table = EXPORT_SPRING_LAWS["table of the tanh"]
    path = _fmu(fmu_folder, "table of the tanh", version, table)
    variables = starts(path)
    n = table.positions.size
    if version == 3:
        positions = variables["spring.positions"]
        assert positions.shape == (n,) and positions.unit == "m"
        np.testing.assert_array_equal(np.array(positions.start.split(), dtype=float),
                                      table.positions)
        assert variables["spring.forces"].unit == "N"
        assert not any(name.startswith("spring.positions[") for name in variables)
    else:
        assert [float(variables[f"spring.positions[{k + 1}]"].start) for k in range(n)] == \
            table.positions.tolist()
        assert variables[f"spring.forces[{n}]"].unit == "N"
    assert int(variables["spring.outside"].start) == 1  # extend
    assert "not used" in variables["isolator.spring_shape"].description
    oblique = starts(_fmu(fmu_folder, "oblique", version, EXPORT_SPRING_LAWS["oblique"]))
    assert oblique["spring.vertical_stiffness"].unit == "N/m"
    assert float(oblique["spring.vertical_stiffness"].start) == \
        EXPORT_SPRING_LAWS["oblique"].vertical_stiffness


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("name", list(EXPORT_SPRING_LAWS))
def test_a_changed_law_parameter_is_the_run_with_the_law_changed(fmu_folder, name, version):
    law = EXPORT_SPRING_LAWS[name]
    if name == "oblique":
        changed = dataclasses.replace(law, vertical_stiffness=law.vertical_stiffness + 40.0)
        start = {"spring.vertical_stiffness": changed.vertical_stiffness}
    elif name == "cubic polynomial":
        changed = dataclasses.replace(law, coefficients=law.coefficients * [1.0, 1.5, 1.0, 0.5])
        start = ({"spring.coefficients": changed.coefficients.tolist()} if version == 3 else
                 {"spring.coefficients[2]": changed.coefficients[1],
                  "spring.coefficients[4]": changed.coefficients[3]})
    else:  # the table's forces: the C computes the PCHIP pieces from them
        forces = law.forces * (1.0 + 0.1 * np.sin(20.0 * law.positions))
        changed = TabulatedSpring(positions=law.positions, forces=forces, outside="extend")
        start = ({"spring.forces": forces.tolist()} if version == 3 else
                 {f"spring.forces[{k + 1}]": f for k, f in enumerate(forces)})
    result = simulate_fmu(str(_fmu(fmu_folder, name, version, law)), stop_time=DURATION,
                          output_interval=STEP, start_values=start)
    reference = _simulate(changed)
    assert np.abs(np.asarray(reference.spring_force) - np.asarray(_simulate(law).spring_force)
                  ).max() > 0.1  # N: the change changes the run
    _assert_same(result, reference)


@pytest.mark.parametrize("version", VERSIONS)
def test_a_run_leaving_a_refusing_table_fails_with_an_error(fmu_folder, version):
    with pytest.raises(SimulationError, match="left the spring table"):
        _simulate(EXPORT_REFUSING_TABLE, EXPORT_LEAVING_SINE)
    path = _fmu(fmu_folder, "refusing table", version, EXPORT_REFUSING_TABLE,
                EXPORT_LEAVING_SINE)
    fmu = Logged(path, version)
    fmu.enter(stop_time=DURATION)
    fmu.fmu.exitInitializationMode()
    message = None
    time = 0.0
    for _ in range(int(round(DURATION / STEP))):
        try:
            fmu.fmu.doStep(currentCommunicationPoint=time, communicationStepSize=STEP)
        except FMICallException as error:
            assert error.status == 3  # fmi2Error / fmi3Error, not NaN outputs
            message = fmu.messages[-1][2]
            break
        time += STEP
        assert np.all(np.isfinite(fmu.get("relative_position", "spring_force")))
    fmu.free()
    assert message is not None and "left the spring table [-0.065, -0.055] m" in message
    assert "spring.outside = 1" in message
    assert 0.681 <= time <= 0.682  # s: where qzs.simulate stops (t = 0.6812 s)


@pytest.mark.parametrize("version", VERSIONS)
def test_positions_that_do_not_increase_are_refused_at_initialisation(fmu_folder, version):
    law = EXPORT_SPRING_LAWS["table of the tanh"]
    fmu = Logged(_fmu(fmu_folder, "table of the tanh", version, law), version)
    fmu.enter(stop_time=DURATION)
    if version == 3:
        positions = law.positions.copy()
        positions[5] = positions[4]
        fmu.fmu.setFloat64([fmu.refs["spring.positions"]], positions.tolist())
    else:
        fmu.set(**{"spring.positions[6]": float(law.positions[4])})
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "`spring.positions[6]`" in message and "increase strictly" in message
    fmu.free()


def test_an_fmi3_array_takes_exactly_its_values(fmu_folder):
    law = EXPORT_SPRING_LAWS["table of the tanh"]
    fmu = Logged(_fmu(fmu_folder, "table of the tanh", 3, law), 3)
    reference = fmu.refs["spring.forces"]
    got = fmu.fmu.getFloat64([reference], nValues=law.forces.size)
    np.testing.assert_array_equal(got, law.forces)
    message = fmu.failing(fmu.fmu.setFloat64, [reference], [1.0, 2.0])
    assert f"hold {law.forces.size} Float64 values, not the 2 given" in message
    message = fmu.failing(fmu.fmu.getFloat64, [reference + 1])  # an element, not a variable
    assert f"no variable has value reference {reference + 1}" in message
    fmu.free()



@pytest.mark.parametrize("version", VERSIONS)
def test_an_oblique_spring_out_of_its_range_is_refused_at_initialisation(fmu_folder, version):
    fmu = Logged(_fmu(fmu_folder, "oblique", version, EXPORT_SPRING_LAWS["oblique"]), version)
    fmu.enter(stop_time=DURATION)
    fmu.set(**{"spring.free_length": 0.0})
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "`spring.free_length` = 0 must be positive [m]" in message
    fmu.free()


@pytest.mark.parametrize("version", VERSIONS)
def test_the_step_is_checked_against_the_law_s_stiffness(fmu_folder, version):
    """A stiff law (a polynomial of 1e5 N/m) lowers the largest stable step below the tanh's:
    the FMU refuses a step a thousandth above the law's limit, naming the limit qzs computes
    for that isolator (qzs.engine.stability, the law's stiffness peak over the stroke), as
    qzs.simulate refuses it, and takes one a thousandth below."""
    from qzs.engine.stability import largest_stable_step

    law = qzs.PolynomialSpring(coefficients=(62.784, -1e5), center=-0.06)
    isolator = qzs.IsolatorParameters(spring=law)
    limit = largest_stable_step(isolator, qzs.ControllerParameters(), "ode3")
    assert limit < 0.97 * largest_stable_step()  # the law's stiffness sets it, not the stops
    with pytest.raises(qzs.StabilityError):
        qzs.simulate(EXPORT_SPRING_SINE, isolator, duration=0.1, dt=limit * 1.001,
                     sample_rate=1.0 / (limit * 1.001))
    path = _fmu(fmu_folder, "stiff polynomial", version, law)
    fmu = Logged(path, version)
    fmu.enter(stop_time=DURATION)
    fmu.set(step_size=limit * 1.001)
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "largest stable step is %.3g s" % limit in message and "step_size" in message
    fmu.free()
    fmu = Logged(path, version)
    fmu.enter(stop_time=DURATION)
    fmu.set(step_size=limit * 0.999)
    fmu.fmu.exitInitializationMode()
    fmu.free()
