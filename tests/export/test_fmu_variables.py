"""The FMU's variable table: every registry parameter with its unit and start, the modes'
inputs and outputs, and the same table as C."""
import numpy as np
import pytest

import qzs
from qzs.engine import kernels as K
from qzs.errors import CompilerError
from qzs.export.fmu_variables import UNITS, fmu_variables, variables_header
from qzs.model.registry import PARAMETERS

EXCITATION = qzs.Sine(amplitude=0.004, frequency=3.0, phase=0.5).pack()[0]


def table(mode="closed-loop", base_motion="internal", **isolator):
    return fmu_variables(isolator=qzs.IsolatorParameters(**isolator),
                         controller=qzs.ControllerParameters(pi_kp=77.0),
                         excitation_scalars=EXCITATION, dt=2e-4,
                         solver_code=K.SOLVER_RK4, mode=mode, base_motion=base_motion)


def test_every_registry_parameter_is_a_parameter_with_its_unit_and_start():
    variables = {v.name: v for v in table(stop_model="plastic", mass=7.5)}
    for name, info in PARAMETERS.items():
        variable = variables[f"{info.section}.{name}"]
        assert variable.causality == "parameter" and variable.description
        assert variable.unit == (info.unit if info.unit in UNITS else "")
    assert variables["isolator.mass"].start == 7.5
    assert variables["controller.pi_kp"].start == 77.0
    assert variables["isolator.stop_model"].start == 1
    assert variables["isolator.stop_model"].type == "I"
    assert variables["isolator.stop_center"].start == qzs.ControllerParameters().position_setpoint
    assert variables["step_size"].start == 2e-4 and variables["solver"].start == K.SOLVER_RK4
    assert variables["excitation.kind"].start == 2 and variables["excitation.f0"].start == 3.0
    assert variables["excitation.phase"].start == 0.5


def test_references_are_indices_and_names_unique():
    for mode in ("closed-loop", "plant"):
        for base in ("internal", "input"):
            variables = table(mode, base)
            assert [v.reference for v in variables] == list(range(len(variables)))
            assert len({v.name for v in variables}) == len(variables)
            assert len({v.macro for v in variables}) == len(variables)


def test_the_modes_inputs_and_outputs():
    plant = {v.name: v for v in table("plant", "input")}
    assert plant["motor_force"].causality == "input"
    assert "pi_force" not in plant and "damping_force" not in plant
    assert all(plant[n].causality == "input" for n in ("base_displacement", "base_velocity",
                                                       "base_acceleration"))
    assert not any(n.startswith("excitation.") for n in plant)
    closed = {v.name: v for v in table()}
    assert closed["motor_force"].causality == "output"
    assert closed["motor_force"].channel == K.C_F_MOTOR and closed["locked"].channel == 100
    assert closed["stop_contact"].type == "B"


def test_the_si_units_are_consistent():
    def combine(*terms):
        out = {}
        for sign, name in terms:
            for base, power in UNITS[name].items():
                out[base] = out.get(base, 0) + sign * power
        return {k: v for k, v in out.items() if v}

    assert UNITS["N"] == combine((1, "kg"), (1, "m/s^2"))
    assert UNITS["J"] == combine((1, "N"), (1, "m"))
    assert UNITS["N*s/m"] == combine((1, "N"), (1, "s"), (-1, "m"))
    assert UNITS["N/(m*s)"] == combine((1, "N"), (-1, "m"), (-1, "s"))
    assert UNITS["N/m"] == combine((1, "N"), (-1, "m"))


def test_the_header_is_the_table_and_compiles(tmp_path):
    from qzs.export.csource import compile_shared

    variables = table()
    header = variables_header(variables, mode="closed-loop", base_motion="internal",
                              token="{x}")
    (tmp_path / "qzs_fmu_variables.h").write_text(header)
    (tmp_path / "check.c").write_text(
        '#include "qzs_fmu_variables.h"\n'
        "typedef char n[sizeof QZS_FMU_START / sizeof(double) == QZS_FMU_N_VARIABLES ? 1 : -1];\n"
        "typedef char t[sizeof QZS_FMU_TYPES - 1 == QZS_FMU_N_VARIABLES ? 1 : -1];\n"
        "typedef char m[QZS_VR_ISOLATOR_MASS == %d ? 1 : -1];\n"
        "double qzs_check(void) { return QZS_FMU_START[QZS_VR_STEP_SIZE]; }\n"
        % next(v.reference for v in variables if v.name == "isolator.mass"))
    try:
        compile_shared([tmp_path / "check.c"], tmp_path / "check.so", include=[tmp_path])
    except CompilerError as error:  # pragma: no cover
        pytest.skip(str(error))
    import ctypes

    library = ctypes.CDLL(str(tmp_path / "check.so"))
    library.qzs_check.restype = ctypes.c_double
    assert library.qzs_check() == 2e-4
    assert np.isclose(float(header.count("QZS_VR_")), len(variables) + 0)


def test_the_motor_force_starts_where_qzs_holds_the_payload_at_rest():
    """The plant mode's start is the motor force a qzs run at rest holds the payload at the
    setpoint with (its PI preloaded with the static load, qzs.engine.prepare): friction has
    nothing to hold and the payload does not move, whatever the mass; a light payload, which
    the spring more than carries, is pulled down (a negative force); beyond the motor's limit,
    either way, it is the limit."""
    from qzs.export.fmu_variables import holding_force

    controller = qzs.ControllerParameters()
    for isolator, limited in ((qzs.IsolatorParameters(mass=6.4), False),
                              (qzs.IsolatorParameters(mass=7.5), False),
                              (qzs.IsolatorParameters(mass=5.0), False),
                              (qzs.IsolatorParameters(mass=9.0, motor_force_max=5.0), True),
                              (qzs.IsolatorParameters(mass=3.0, motor_force_max=5.0), True)):
        hold = holding_force(isolator, controller)
        run = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                           duration=0.01, dt=1e-4, sample_rate=1e4)
        weight = isolator.mass * isolator.gravity
        assert hold == pytest.approx(float(np.asarray(run.motor_force)[0]),
                                     rel=0, abs=1e-12 * weight), isolator
        if limited:
            assert abs(hold) == isolator.motor_force_max
        else:
            assert np.all(np.asarray(run.friction_force) == 0.0)
            assert np.ptp(np.asarray(run.relative_position)) == 0.0
    assert holding_force(qzs.IsolatorParameters(mass=5.0), controller) < 0.0
    plant = {v.name: v for v in table("plant")}
    assert plant["motor_force"].start == holding_force(qzs.IsolatorParameters(),
                                                       qzs.ControllerParameters(pi_kp=77.0))


def test_the_excitations_units_are_the_registrys():
    from qzs.model.registry import unit_of

    variables = {v.name: v for v in table()}
    assert variables["excitation.duration"].unit == unit_of("excitation.duration", "chirp")
    assert variables["excitation.f0"].unit == unit_of("excitation.frequency", "sine")
    assert variables["excitation.phase"].unit == unit_of("excitation.phase", "sine")
    assert variables["excitation.fade_in"].unit == unit_of("excitation.fade_in", "sine")
    assert "chirps only" in variables["excitation.duration"].description


def test_the_header_carries_the_exported_step_and_how_it_was_chosen():
    variables = table()
    literal = variables_header(variables, mode="closed-loop", base_motion="internal",
                               token="{x}")
    assert "#define QZS_FMU_EXPORTED_STEP 0.0002\n" in literal
    assert "#define QZS_FMU_STEP_CHOSEN 0\n" in literal
    chosen = qzs.resolve(qzs.Chirp(duration=4.0, f1=5.0), step="chosen").step
    assert chosen.chosen
    header = variables_header(variables, mode="closed-loop", base_motion="internal",
                              token="{x}", step=chosen)
    assert "#define QZS_FMU_STEP_CHOSEN 1\n" in header and chosen.line() in header


def test_a_linear_controllers_parameters_are_its_matrices_by_name_with_their_units():
    """A 2-state controller on all five sensors, A not symmetric: each ``linear.a[i,j]``,
    ``b_<sensor>[i]``, ``c[i]``, ``d_<sensor>`` starts at that entry of the matrices (1-based,
    row then column), and a feedthrough's unit is the force [N] per its sensor's unit."""
    from qzs.engine.prepare import pack_model
    from qzs.model.sensors import SENSORS

    a = np.array([[-3.0, 5.0], [-7.0, -11.0]])
    b = np.arange(1.0, 11.0).reshape(2, 5)
    c, d = np.array([13.0, 17.0]), np.array([[19.0, 23.0, 0.0, 29.0, 31.0]])
    linear = qzs.LinearController(a=a, b=b, c=c, d=d, inputs=tuple(SENSORS))
    isolator, controller = qzs.IsolatorParameters(), qzs.PIDamping(linear=linear)
    rows = {v.name: v for v in fmu_variables(
        isolator=isolator, controller=controller, excitation_scalars=EXCITATION, dt=2e-4,
        solver_code=K.SOLVER_RK4, mode="closed-loop", base_motion="internal",
        model=pack_model(isolator, controller, 2e-4), blocks_state=np.zeros(K.N_X))}
    for i in range(2):
        assert float(rows[f"controller.linear.c[{i + 1}]"].start) == c[i]
        for j in range(2):
            assert float(rows[f"controller.linear.a[{i + 1},{j + 1}]"].start) == a[i, j]
        for k, sensor in enumerate(SENSORS):
            assert float(rows[f"controller.linear.b_{sensor}[{i + 1}]"].start) == b[i, k]
    for k, (sensor, (unit, _)) in enumerate(SENSORS.items()):
        row = rows[f"controller.linear.d_{sensor}"]
        assert float(row.start) == d[0, k], sensor
        per = {base: UNITS["N"].get(base, 0) - UNITS[unit].get(base, 0)
               for base in set(UNITS["N"]) | set(UNITS[unit])}
        assert {k: v for k, v in UNITS[row.unit].items() if v} == \
            {k: v for k, v in per.items() if v}, sensor
