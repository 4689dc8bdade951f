"""The FMU behaves as the FMI standard says (issue 39), FMI 3.0 and 2.0: a call it cannot honour
gets an error status and a logged reason and leaves nothing half done (a refused multi-value
set changes nothing); a ``doStep`` past the experiment's stop time, or past a chirp's end,
is an error; any positive communication step is taken on the grid of internal steps (one
internal step, a step that is no multiple of it, the sampled controller's timing kept); a
step_size qzs would refuse (unstable, too coarse for the excitation) is refused at
initialisation, with the largest stable step computed in C as qzs.engine.stability computes
it, and one above the exported step is warned of; the parameters qzs refuses, the FMU refuses,
and those a configuration does not use it neither requires nor checks.
"""
import ctypes

import numpy as np
import pytest

import qzs
from qzs.engine import kernels as K
from qzs.engine.stability import largest_stable_step, stability_test
from qzs.errors import ParameterError
from qzs.export.csource import compile_shared, source_folder

from export.fmu_support import EXCITATIONS, Logged, compare, exported

fmpy = pytest.importorskip("fmpy")
from fmpy import read_model_description, simulate_fmu  # noqa: E402

CHIRP = EXCITATIONS["chirp-linear"]
DT = 1e-4  # the Python export's step (literal)


def started(path, version=3, stop_time=None, **values):
    """An instance with ``values`` set in initialisation mode, initialised."""
    instance = Logged(path, version)
    instance.enter(stop_time)
    if values:
        instance.set(**values)
    instance.fmu.exitInitializationMode()
    return instance


# ---------------------------------------------------------------- refused calls
def test_bad_calls_get_an_error_status_and_a_logged_reason(fmus):
    fmu = Logged(fmus("chirp-linear"))
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
    for step in (0.0, -1e-3):
        assert "must be positive" in fmu.failing(f.doStep, 0.0, step)
    f.doStep(0.0, 1e-3)  # the FMU goes on after a refused call
    assert "is not the FMU's time" in fmu.failing(f.doStep, 0.0, 1e-3)
    fmu.free()


def test_fmi2_bad_calls_are_logged_through_the_callbacks(fmus):
    fmu = Logged(fmus("chirp-linear", version=2), version=2)
    fmu.enter()
    fmu.set(isolator__mass=-1.0)
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "isolator.mass" in message
    fmu.set(isolator__mass=6.4)
    fmu.fmu.exitInitializationMode()
    assert "is not the FMU's time" in fmu.failing(fmu.fmu.doStep, 1.0, 1e-3)
    fmu.free()


def test_a_rate_that_is_no_whole_number_of_steps_and_model_exchange_are_refused(fmus):
    path = fmus("chirp-linear")
    fmu = Logged(path)
    fmu.enter()
    fmu.set(controller__controller_rate=333.0)
    assert "controller_rate" in fmu.failing(fmu.fmu.exitInitializationMode)
    fmu.fmu.freeInstance()
    description = read_model_description(str(path))
    from fmpy import extract
    from fmpy.fmi3 import FMU3Model

    model = FMU3Model(guid=description.guid, unzipDirectory=extract(str(path)),
                      modelIdentifier=description.coSimulation.modelIdentifier)
    messages = []
    with pytest.raises(Exception):
        model.instantiate(logMessage=lambda e, s, c, m: messages.append(m.decode()))
    assert any("model exchange is not supported" in m for m in messages)


@pytest.mark.parametrize("version", [3, 2])
def test_a_refused_multi_value_set_changes_nothing(fmus, version):
    """All or nothing: mass 7 with gravity NaN in one call is refused, and the mass stays;
    so does a set with one unknown reference."""
    fmu = Logged(fmus("chirp-linear", version=version), version)
    fmu.enter()
    before = fmu.get("isolator.mass", "isolator.gravity")
    message = fmu.failing(lambda: fmu.set(isolator__mass=7.0, isolator__gravity=float("nan")))
    assert "isolator.gravity" in message
    assert fmu.get("isolator.mass", "isolator.gravity") == before
    setter = fmu.fmu.setFloat64 if version == 3 else fmu.fmu.setReal
    fmu.failing(setter, [fmu.refs["isolator.mass"], 999], [7.0, 1.0])
    assert fmu.get("isolator.mass") == before[:1]
    fmu.set(isolator__mass=7.0, isolator__gravity=9.0)  # a valid set still takes both
    assert fmu.get("isolator.mass", "isolator.gravity") == [7.0, 9.0]
    fmu.free()


# ---------------------------------------------------------------- the experiment's end
@pytest.mark.parametrize("version", [3, 2])
def test_a_step_past_the_stop_time_is_an_error_with_a_reason(fmus, version):
    fmu = started(fmus("chirp-linear", version=version), version, stop_time=0.01)
    fmu.fmu.doStep(0.0, 0.005)
    message = fmu.failing(fmu.fmu.doStep, 0.005, 0.006)
    assert "past the stop time" in message and "0.01" in message
    fmu.fmu.doStep(0.005, 0.005)  # up to the stop time: taken
    assert fmu.get("relative_position")[0] == pytest.approx(-0.06, abs=1e-3)
    fmu.free()


def test_a_chirp_is_not_run_past_its_sweep(fmus):
    """qzs runs no chirp past its sweep time (its frequency would go on rising): a stop time
    past it is refused at initialisation, a step past it without a stop time at doStep."""
    path = fmus("chirp-linear")
    fmu = Logged(path)
    fmu.enter(stop_time=CHIRP.duration + 1.0)
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "past the chirp's end" in message and "excitation.duration" in message
    fmu.free()
    fmu = started(path)
    fmu.fmu.doStep(0.0, CHIRP.duration)
    assert "past the chirp's end" in fmu.failing(fmu.fmu.doStep, CHIRP.duration, 1e-3)
    fmu.free()


# ---------------------------------------------------------------- communication steps
def test_one_internal_step_per_communication_is_the_run_to_the_bit(fmus):
    result = simulate_fmu(str(fmus("chirp-linear")), stop_time=0.5, output_interval=DT)
    reference = qzs.simulate(CHIRP, duration=0.5, dt=DT, sample_rate=1.0 / DT)
    assert len(result) == len(reference.time)
    for name, difference in compare(result, reference).items():
        assert difference == 0.0, name


#: A sine set through FMI on the chirp's FMU, and the same for qzs.
SINE_START = {"excitation.kind": 2, "excitation.amplitude": 0.02, "excitation.f0": 6.0,
              "excitation.fade_in": 0.0}
SINE = qzs.Sine(amplitude=0.02, frequency=6.0, fade_in=0.0)


@pytest.mark.parametrize("h, stop, start, excitation", [(3.7e-4, CHIRP.duration, {}, CHIRP),
                                                        (7.3e-5, 1.0, SINE_START, SINE)])
def test_any_communication_step_is_taken_on_the_grid(fmus, h, stop, start, excitation):
    """Communication steps of 3.7 and of 0.73 internal steps, the last one shortened to the
    stop time by FMPy: each grid step a point falls inside is split there; at the points that
    are grid points the run is qzs's within the splits' truncation error (measured 2e-8 of
    each channel's range at most), and the times are the importer's."""
    result = simulate_fmu(str(fmus("chirp-linear")), stop_time=stop, output_interval=h,
                          start_values=start)
    times = np.minimum(np.arange(len(result)) * h, stop)
    np.testing.assert_allclose(result["time"], times, rtol=0, atol=1e-12)
    reference = qzs.simulate(excitation, duration=stop, dt=DT, sample_rate=1.0 / DT)
    assert np.ptp(np.asarray(reference.relative_position)) > 1e-3  # it moves
    index = np.round(times / DT).astype(int)
    on_grid = np.abs(times / DT - index) < 1e-6
    assert on_grid.sum() > 100
    for name in ("relative_position", "spring_force", "payload_velocity",
                 "payload_acceleration", "friction_dissipation"):
        ours = np.asarray(reference[name])
        difference = np.abs(result[name][on_grid] - ours[index[on_grid]]).max()
        assert difference < 1e-7 * np.ptp(ours), (name, difference / np.ptp(ours))


def test_the_sampled_controller_keeps_its_timing_at_any_communication_step(fmus):
    """With the controller sampled at 500 Hz (every 20 internal steps) and a communication
    step of 0.3 ms, the held command changes only over a communication step that holds a
    sample point, as qzs's does."""
    h, rate = 3e-4, 500.0
    start = {"controller.controller_rate": rate, "controller.damping_gain": 300.0}
    result = simulate_fmu(str(fmus("chirp-linear")), stop_time=2.0, output_interval=h,
                          start_values=start)
    time = np.arange(len(result)) * h
    changed = np.flatnonzero(np.diff(result["motor_force"]) != 0.0)
    assert changed.size > 0.5 * 2.0 * rate
    samples = np.arange(0.0, 2.0 + 1e-9, 1.0 / rate)
    for k in changed:  # a sample point in [t_k, t_k+1): the doStep from t_k took it
        assert np.any((samples >= time[k] - 1e-12) & (samples < time[k + 1] - 1e-12)), time[k]


# ---------------------------------------------------------------- the internal step
def test_a_step_qzs_would_refuse_is_refused_at_initialisation_and_a_coarser_one_warned(fmus):
    """The default configuration is stable up to 6.05 ms (ode3): 1 cm steps are refused with
    the limit in the reason, 5 ms (the issue's) is taken with a warning that it is above
    the 0.1 ms the FMU was exported with; a step too coarse for the excitation's 20 Hz is
    refused as qzs.simulate refuses it."""
    path = fmus("chirp-linear")
    limit = largest_stable_step()
    for version in (3, 2):
        fmu = Logged(fmus("chirp-linear", version=version), version)
        fmu.enter()
        fmu.set(step_size=limit * 1.001)
        message = fmu.failing(fmu.fmu.exitInitializationMode)
        assert "largest stable step is %.3g s" % limit in message and "step_size" in message
        fmu.free()
    for step in (1e-2, 2e-2):
        fmu = Logged(path)
        fmu.enter()
        fmu.set(step_size=step)
        assert "largest stable step" in fmu.failing(fmu.fmu.exitInitializationMode)
        fmu.free()
    fmu = started(path, step_size=5e-3)
    assert any("above the 0.0001 s given at export" in w for w in fmu.warnings())
    fmu.fmu.doStep(0.0, 1e-2)
    fmu.free()
    assert not started(path).warnings()  # the exported step: no warning
    fmu = Logged(path)
    fmu.enter()
    fmu.fmu.setInt32([fmu.refs["excitation.kind"]], [2])
    fmu.set(step_size=5.5e-3, excitation__f0=20.0)
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "fewer than 10 steps per period" in message and "20 Hz" in message
    with pytest.raises(qzs.errors.UnresolvedExcitationError):
        qzs.simulate(qzs.Sine(frequency=20.0), duration=1.0, dt=5.5e-3, sample_rate=1 / 5.5e-3)
    fmu.free()


def test_a_step_above_the_one_chosen_for_accuracy_is_warned_of(fmu_folder):
    """Exported with the step qzs chooses (``qzs export fmu``'s default): a larger step_size
    is logged as a warning naming the chosen step and how it was chosen; the chosen one or a
    finer one is not."""
    path = exported(fmu_folder, "chosen", excitation=CHIRP, step="chosen")
    chosen = float(read_model_description(str(path)).coSimulation.fixedInternalStepSize)
    assert chosen > DT
    fmu = started(path, step_size=chosen * 2)
    (warning,) = fmu.warnings()
    assert "qzs chose at export for accuracy" in warning and f"{chosen:.12g} s" in warning
    assert "accuracy-driven" in warning
    fmu.free()
    for step in (chosen, chosen / 2):
        assert not started(path, step_size=step).warnings()


def _stability_library(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stability")
    source = source_folder()
    library = ctypes.CDLL(str(compile_shared([source / "qzs_stability.c"],
                                             folder / "stability.so", include=[source])))
    double_p = ctypes.POINTER(ctypes.c_double)
    library.qzs_stable_step.argtypes = [double_p, ctypes.c_int, ctypes.c_int, ctypes.c_double]
    library.qzs_largest_stable_step.argtypes = [double_p, ctypes.c_int, ctypes.c_int]
    library.qzs_largest_stable_step.restype = ctypes.c_double
    return library


def random_designs(count, seed):
    """Designs drawn across the ranges qzs ships (the design problem's spring and gains, its
    stiction; stops, damping, mass and high-pass around Table 1's)."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        stiction = rng.uniform(5.0, 15.0)
        plastic = rng.random() < 0.25
        isolator = qzs.IsolatorParameters(
            mass=rng.uniform(3.0, 12.0), spring_force=rng.uniform(58.0, 68.0),
            stiction_force=stiction, coulomb_force=rng.uniform(0.0, stiction),
            viscous_damping=rng.uniform(0.0, 300.0),
            stop_stiffness=10 ** rng.uniform(5.0, 7.0), stop_damping=rng.uniform(0.0, 5000.0),
            stop_model="plastic" if plastic else "compliant",
            friction_regularisation=0.0 if plastic or rng.random() < 0.5
            else 10 ** rng.uniform(-4.0, -2.0))
        controller = qzs.ControllerParameters(
            pi_kp=10 ** rng.uniform(1.0, np.log10(3000.0)), pi_ki=10 ** rng.uniform(-1.0, 2.0),
            damping_gain=rng.uniform(0.0, 400.0), velocity_highpass=rng.uniform(0.0, 5.0))
        yield isolator, controller, str(rng.choice(["euler", "ode3", "rk4"]))


def test_the_c_stability_test_is_qzs_over_random_designs(tmp_path_factory):
    """qzs_stability.c against qzs.engine.stability over 200 random designs: the largest
    stable step within 1e-5, and the verdict the same a thousandth either side of it; in
    plant mode the PI and damping gains are left out (they act outside the FMU)."""
    from qzs.engine.prepare import _pack_parameters
    from qzs.engine.stability import SOLVERS

    library = _stability_library(tmp_path_factory)
    for isolator, controller, solver in random_designs(200, seed=39):
        code = SOLVERS[solver][0]
        for closed_loop in (1, 0):
            python = controller if closed_loop else qzs.ControllerParameters(
                pi_kp=0.0, pi_ki=controller.pi_ki, damping_gain=0.0,
                velocity_highpass=controller.velocity_highpass)
            packed = _pack_parameters(isolator, controller, 1e-4, 0)
            P = packed.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
            limit = largest_stable_step(isolator, python, solver)
            assert library.qzs_largest_stable_step(P, code, closed_loop) == pytest.approx(
                limit, rel=1e-5), (isolator, controller, solver, closed_loop)
            stable = stability_test(isolator, python, solver)
            for h in (limit * 0.999, limit * 1.001):
                assert bool(library.qzs_stable_step(P, code, closed_loop, h)) == stable(h)
    assert K.SOLVER_ODE3 == SOLVERS["ode3"][0]


def test_plant_mode_neither_checks_nor_counts_the_controllers_gains(fmus):
    """The plant FMU's controller is the importer's: gains it does not use are not checked,
    and do not make its internal step unstable; the closed loop refuses the same values."""
    stiff = dict(controller__pi_kp=1e9, controller__damping_gain=-5.0)
    fmu = started(fmus("chirp-linear", "plant"), **stiff)
    fmu.fmu.doStep(0.0, 1e-3)
    fmu.free()
    closed = Logged(fmus("chirp-linear"))
    closed.enter()
    closed.set(**stiff)
    assert "controller.damping_gain" in closed.failing(closed.fmu.exitInitializationMode)
    closed.free()


# ---------------------------------------------------------------- the parameters' checks
#: Values qzs refuses: FMU start values, the variable the FMU names, and how qzs is given them.
REFUSED = [
    ({"isolator.coulomb_force": 20.0, "isolator.stiction_force": 10.0},
     "isolator.coulomb_force",
     lambda: qzs.IsolatorParameters(coulomb_force=20.0, stiction_force=10.0)),
    ({"isolator.mass": 0.0}, "isolator.mass", lambda: qzs.IsolatorParameters(mass=0.0)),
    ({"isolator.gravity": -1.0}, "isolator.gravity",
     lambda: qzs.IsolatorParameters(gravity=-1.0)),
    ({"isolator.spring_shape": 0.0}, "isolator.spring_shape",
     lambda: qzs.IsolatorParameters(spring_shape=0.0)),
    ({"isolator.stroke_half": 0.0}, "isolator.stroke_half",
     lambda: qzs.IsolatorParameters(stroke_half=0.0)),
    ({"isolator.stop_damping": -1.0}, "isolator.stop_damping",
     lambda: qzs.IsolatorParameters(stop_damping=-1.0)),
    ({"isolator.friction_regularisation": 1e-3, "isolator.stop_model": 1},
     "isolator.friction_regularisation",
     lambda: qzs.IsolatorParameters(friction_regularisation=1e-3, stop_model="plastic")),
    ({"controller.pi_ki": -1.0}, "controller.pi_ki",
     lambda: qzs.ControllerParameters(pi_ki=-1.0)),
    ({"controller.velocity_highpass": -1.0}, "controller.velocity_highpass",
     lambda: qzs.ControllerParameters(velocity_highpass=-1.0)),
    ({"excitation.amplitude": -0.01}, "excitation.amplitude",
     lambda: qzs.Chirp(amplitude=-0.01)),
    ({"excitation.kind": 1, "excitation.f0": 0.0}, "excitation.f0",
     lambda: qzs.Chirp(method="logarithmic", f0=0.0)),
    ({"excitation.f1": -1.0}, "excitation.f1", lambda: qzs.Chirp(f1=-1.0)),
    ({"excitation.duration": 0.0}, "excitation.duration", lambda: qzs.Chirp(duration=0.0)),
    ({"excitation.fade_in": 5.0}, "excitation.fade_in",
     lambda: qzs.Chirp(duration=CHIRP.duration, fade_in=5.0)),
]


@pytest.mark.parametrize("values, name, python", REFUSED, ids=[r[1] for r in REFUSED])
def test_what_qzs_refuses_the_fmu_refuses_at_initialisation(fmus, values, name, python):
    with pytest.raises(ParameterError):
        python()
    fmu = Logged(fmus("chirp-linear"))
    fmu.enter()
    for variable, value in values.items():
        if variable in ("isolator.stop_model", "excitation.kind"):
            fmu.fmu.setInt32([fmu.refs[variable]], [int(value)])
        else:
            fmu.set(**{variable.replace(".", "__"): value})
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert f"`{name}`" in message and "set it so before initialisation ends" in message
    fmu.free()


@pytest.mark.parametrize("version", [3, 2])
def test_a_sine_neither_requires_nor_checks_a_chirps_parameters(fmus, version):
    """A sine FMU starts with its exported sweep time 0 and any end frequency (what a chirp
    would need); its own frequency must be positive, as the export requires."""
    path = fmus("sine", version=version)
    fmu = started(path, version, excitation__duration=0.0, excitation__f1=-3.0)
    fmu.fmu.doStep(0.0, 1e-2)
    fmu.free()
    fmu = Logged(path, version)
    fmu.enter()
    fmu.set(excitation__f0=0.0)
    message = fmu.failing(fmu.fmu.exitInitializationMode)
    assert "`excitation.f0`" in message and "positive" in message
    fmu.free()
    with pytest.raises(ParameterError):
        qzs.export_fmu(path.with_name("zero.fmu"), qzs.Sine(frequency=0.0))
