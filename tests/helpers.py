"""Named parameter sets and small helpers shared by the simulator tests."""
import ctypes as _ctypes

import numpy as np

import qzs
from qzs import Chirp, ControllerParameters, IsolatorParameters
from qzs.engine import kernels as _K

#: MagSpring shape [1/m] small enough that ``-a*tanh(b*z)`` is linear to ~1e-10 over the
#: strokes used in the linear tests: the stiffness is then ``a*b`` about z = 0.
LINEAR_SHAPE = 1e-3

#: The default chirp shortened to 20 s: 10 mm, 0 -> 20 Hz, breaks stiction near 2 Hz.
SHORT_CHIRP = Chirp(duration=20.0)
PASSIVE = ControllerParameters(pi_kp=0.0, pi_ki=0.0)


def linear_isolator(stiffness=100.0, damping=100.0, mass=6.4, **overrides):
    """A frictionless, weightless isolator with a linear spring and no reachable stop.

    The stops are centred on z = 0 and 1 km away, the motor never saturates.
    """
    settings = dict(mass=mass, gravity=0.0, stiction_force=0.0, coulomb_force=0.0,
                    spring_shape=LINEAR_SHAPE, spring_force=stiffness / LINEAR_SHAPE,
                    viscous_damping=damping, stop_center=0.0, stroke_half=1e3,
                    motor_force_max=1e9)
    settings.update(overrides)
    return IsolatorParameters(**settings)


def linear_controller(**overrides):
    """PI (+ damping) loop about the setpoint z = 0, continuous, high-pass off."""
    settings = dict(position_setpoint=0.0, pi_kp=0.0, pi_ki=0.0, damping_gain=0.0,
                    velocity_highpass=0.0, controller_rate=0.0)
    settings.update(overrides)
    return ControllerParameters(**settings)


def steady_transmissibility(excitation_frequency, isolator, controller, *, duration=40.0,
                            window=10.0, dt=1e-4):
    """``|X/Y|`` [-] of a simulated run in its steady state, from the fundamental's Fourier
    coefficients of the payload's and the base's velocity over the last ``window`` seconds
    (whole periods: ``window*f`` a whole number and ``1/(f dt)`` too).

    The velocities, not the accelerations: they are continuous where a held force jumps, so
    the samples' sum is the integral over whole periods; a slow transient of the position
    (the PI's integral) is smaller in them by its rate over the excitation's frequency.
    """
    run = qzs.simulate(qzs.Sine(amplitude=1e-3, frequency=excitation_frequency, fade_in=0.0),
                       isolator, controller, duration=duration, dt=dt, sample_rate=1.0 / dt)
    per_period = int(round(1.0 / (excitation_frequency * dt)))
    first = int(np.searchsorted(run.time, duration - window - 0.5 * dt))
    chosen = slice(first, first + int(round(window * excitation_frequency)) * per_period)
    phase = np.exp(-2j * np.pi * excitation_frequency * run.time[chosen])
    payload = np.sum(run["payload_velocity"][chosen] * phase)
    base = np.sum(run["base_velocity"][chosen] * phase)
    return float(abs(payload / base))


#: A lead on the measured payload velocity: -Kd (1 + s/w_z)/(1 + s/w_p), zero 2 Hz, pole 20 Hz.
LEAD_LAG = dict(gain=50.0, zero=2 * np.pi * 2.0, pole=2 * np.pi * 20.0)


def lead_lag(sample_time=0.0):
    """:data:`LEAD_LAG` as a LinearController on the charge amplifier's velocity (continuous,
    or held: ``control.c2d`` with a zero-order hold)."""
    import control

    system = control.tf([-LEAD_LAG["gain"] / LEAD_LAG["zero"], -LEAD_LAG["gain"]],
                        [1 / LEAD_LAG["pole"], 1.0])
    if sample_time:
        system = control.c2d(system, sample_time, "zoh")
    return qzs.LinearController.from_system(system, inputs=("measured_payload_velocity",))


def vertical_legs(height=0.5):
    """Six vertical legs, each top joint straight above its base joint, symmetric in pairs.

    ``HexapodGeometry`` rightly refuses parallel legs (its Jacobian is singular: nothing
    holds the platform sideways), so the object is built around its checks. The engine
    copes: the static leg forces and, when several legs are locked, their holding forces are
    the minimum-norm ones (equal shares). Under a platform of six masses and base motion in
    z, each leg is the single-axis isolator.
    """
    from qzs.model.hexapod import HexapodGeometry

    xy = np.array([[0.2, 0.1], [-0.2, -0.1], [0.2, -0.1], [-0.2, 0.1], [0.15, 0.0],
                   [-0.15, 0.0]])
    joints = np.column_stack([xy, np.zeros(6)])
    geometry = object.__new__(HexapodGeometry)
    for name, value in (("base_joints", joints), ("top_joints", joints.copy()),
                        ("home_position", np.array([0.0, 0.0, height])), ("stroke_half", 0.080)):
        object.__setattr__(geometry, name, value)
    return geometry


def stick_rises(locked):
    """Number of slip -> locked transitions in a boolean series."""
    return int(np.count_nonzero(np.diff(locked.astype(np.int8)) == 1))


def shipped_designs(count, seed, *, highpass_off=False, page=()):
    """``count`` random designs across qzs's shipped ranges: ``(isolators, controllers)``.

    Each design takes the shipped design problems in turn
    (:func:`qzs.workflows.design_space.problem.shipped_problems`, as ``qzs optimize`` builds
    its cases): the problem's fixed parameters, each decision variable uniform over its
    bounds (on ``log10`` for a log scale), each uncertain parameter from its own
    distribution (a list of values: one of them). The parameters named in ``page`` are drawn
    uniformly over the tuning page's slider ranges instead (``qzs.app.page.SLIDERS``, the
    ranges a user moves them over). ``highpass_off``: every other design has
    ``velocity_highpass = 0`` (the damping without its high-pass). All from numpy's
    generator seeded with ``seed``.
    """
    from qzs.workflows.design_space.problem import load_problem, shipped_problems
    from qzs.workflows.sweeps.cases import build_model

    problems = [load_problem(path) for path in shipped_problems()]
    sliders = {}
    if page:
        from qzs.app.page import SLIDERS as sliders
    rng = np.random.default_rng(seed)
    isolators, controllers = [], []
    for k in range(count):
        problem = problems[k % len(problems)]
        case = {v.name: float(v.to_unit(rng.uniform(*v.search_bounds)))
                for v in problem.variables}
        case.update({u.name: float(u.quantile(rng.uniform())) for u in problem.uncertain})
        case.update({name: float(rng.uniform(*sliders[name][:2])) for name in page})
        if highpass_off and k % 2:
            case["velocity_highpass"] = 0.0
        isolator, controller = build_model(problem.sweep, case)
        isolators.append(isolator)
        controllers.append(controller)
    return isolators, controllers


EXPORT_PASSIVE = qzs.ControllerParameters(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0)
EXPORT_SETTINGS = dict(dt=1e-4, sample_rate=1000.0)

#: The cases the C model, the exported controller and the FMU are checked on (issue 33),
#: name: (excitation, isolator, controller, run settings)
EXPORT_CASES = {
    "default": (qzs.Sine(amplitude=0.01, frequency=5.0), None, None, dict(duration=4.0)),
    "passive": (qzs.Sine(amplitude=0.005, frequency=4.0), None, EXPORT_PASSIVE, dict(duration=4.0)),
    "plastic stops": (qzs.Sine(amplitude=0.1, frequency=2.0, fade_in=0.5),
                      qzs.IsolatorParameters(stop_model="plastic"), EXPORT_PASSIVE,
                      dict(duration=3.0)),
    "compliant stops": (qzs.Sine(amplitude=0.1, frequency=2.0, fade_in=0.5), None, EXPORT_PASSIVE,
                        dict(duration=3.0)),
    "sampled damping": (qzs.Sine(amplitude=0.005, frequency=6.0),
                        None,
                        qzs.ControllerParameters(controller_rate=1000.0, damping_gain=300.0),
                        dict(duration=4.0)),
    "regularised friction": (qzs.Sine(amplitude=0.005, frequency=5.0),
                             qzs.IsolatorParameters(friction_regularisation=1e-3), None,
                             dict(duration=3.0, solver="rk4")),
    "high stiction": (qzs.Sine(amplitude=0.01, frequency=8.0),
                      qzs.IsolatorParameters(stiction_force=60.0, coulomb_force=40.0), None,
                      dict(duration=3.0, solver="euler", dt=2e-5)),
    "random": (qzs.RandomExcitation(amplitude=0.002, f_high=30.0, duration=5.0, seed=3), None,
               None, dict(duration=5.0)),
    "paper chirp shortened": (qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=20.0), None,
                              None, dict(duration=20.0)),
}


#: A 2-state continuous lead-lag damping loop on the charge amplifier's velocity: a lead
#: between 3 and 30 Hz, rolled off at 200 Hz [N per m/s].
_LEAD, _LAG, _ROLL = 2 * np.pi * 3.0, 2 * np.pi * 30.0, 2 * np.pi * 200.0
EXPORT_LEAD_LAG = qzs.LinearController.from_transfer_function(
    [-40.0 * _LAG * _ROLL / _LEAD, -40.0 * _LAG * _ROLL],
    np.polymul([1.0, _LAG], [1.0, _ROLL]), "measured_payload_velocity")
#: A 2-state discrete controller at 1 kHz on the position error and the payload's
#: acceleration (read with the force held until the sample).
EXPORT_DISCRETE = qzs.LinearController(
    a=[[0.9, 0.05], [0.0, 0.8]], b=[[1e-3, 0.0], [0.0, 0.01]], c=[30.0, -2.0], d=[10.0, 0.0],
    inputs=("position_error", "payload_acceleration"), sample_time=1e-3)
#: The controllers with blocks the C model, the exported controller and the FMU are checked on
#: (issue 40), on a 3 Hz sine that sticks and slips at Table 1's friction; name: (excitation,
#: isolator, controller, run settings).
EXPORT_BLOCK_CASES = {
    "compensation with observer": (
        qzs.Sine(amplitude=0.01, frequency=3.0), None,
        qzs.PIDamping(compensation=qzs.FrictionCompensation(fraction=0.8,
                                                            observer_bandwidth=5.0)),
        dict(duration=3.0)),
    "sampled compensation with observer": (
        qzs.Sine(amplitude=0.01, frequency=3.0), None,
        qzs.PIDamping(controller_rate=1000.0, damping_gain=50.0,
                      compensation=qzs.FrictionCompensation(fraction=0.8, deadband=1e-4,
                                                            observer_bandwidth=5.0)),
        dict(duration=3.0)),
    "dither": (qzs.Sine(amplitude=0.01, frequency=3.0), None,
               qzs.PIDamping(dither=qzs.Dither(amplitude=3.0, frequency=40.0)),
               dict(duration=3.0)),
    "continuous lead-lag": (qzs.Sine(amplitude=0.01, frequency=3.0), None,
                            qzs.PIDamping(linear=EXPORT_LEAD_LAG), dict(duration=3.0)),
    "discrete controller": (qzs.Sine(amplitude=0.01, frequency=3.0), None,
                            qzs.PIDamping(linear=EXPORT_DISCRETE), dict(duration=3.0)),
}


#: The spring laws the C model and the FMU are checked on (issue 41), name: law, each run on
#: :data:`EXPORT_SPRING_SINE` (the payload slides and sticks on them): an oblique-spring QZS at
#: its quasi-zero condition, a cubic polynomial and a table sampled from the tanh that extends.
EXPORT_SPRING_LAWS = {
    "oblique": qzs.ObliqueSpringQZS.quasi_zero(),
    "cubic polynomial": qzs.PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -4e4),
                                             center=-0.06),
    "table of the tanh": qzs.TabulatedSpring.from_law(qzs.TanhSpring(),
                                                      np.linspace(-0.2, 0.1, 61),
                                                      outside="extend"),
}
EXPORT_SPRING_SINE = qzs.Sine(amplitude=5e-3, frequency=5.0)
#: A table of the tanh that refuses positions outside it, and a base motion that takes the
#: payload out of it (at t = 0.6812 s with EXPORT_SETTINGS).
EXPORT_REFUSING_TABLE = qzs.TabulatedSpring.from_law(qzs.TanhSpring(),
                                                     np.linspace(-0.065, -0.055, 21))
EXPORT_LEAVING_SINE = qzs.Sine(amplitude=0.03, frequency=6.0)


def run_both(cases, settings, name):
    """``(name, qzs.simulate's run, the C model's run)`` of case ``name`` of ``cases`` (its
    settings from ``settings(name)``): what the C model's tests compare."""
    from qzs.export.cmodel import simulate_c

    excitation, isolator, controller, _ = cases[name]
    kwargs = settings(name)
    return name, qzs.simulate(excitation, isolator, controller, **kwargs), simulate_c(
        excitation, isolator, controller, **kwargs)


def export_block_settings(case):
    """The run settings of a case with blocks: :data:`EXPORT_SETTINGS` updated by its own."""
    return {**EXPORT_SETTINGS, **EXPORT_BLOCK_CASES[case][3]}


def export_settings(case):
    """The run settings of a case: :data:`EXPORT_SETTINGS` updated by its own."""
    return {**EXPORT_SETTINGS, **EXPORT_CASES[case][3]}


# ---------------------------------------------------------------- the exported controller (ctypes)
class Parameters(_ctypes.Structure):
    _fields_ = [(name, _ctypes.c_double) for name in (
        "position_setpoint", "pi_kp", "pi_ki", "damping_gain", "motor_force_max",
        "period_steps", "step_time")]


class Output(_ctypes.Structure):
    _fields_ = [(name, _ctypes.c_double) for name in ("pi", "damping", "motor", "integral_rate")]


class Controller(_ctypes.Structure):
    _fields_ = [("parameters", Parameters), ("integral", _ctypes.c_double), ("output", Output)]


class Blocks(_ctypes.Structure):
    _fields_ = [("x", _ctypes.c_double * _K.N_X)]


class BlockParameters(_ctypes.Structure):
    _fields_ = [("control", Parameters), ("velocity_regularisation", _ctypes.c_double),
                ("model", _ctypes.c_double * _K.N_MODEL)]


class BlockOutput(_ctypes.Structure):
    _fields_ = [(name, _ctypes.c_double) for name in (
        "pi", "damping", "compensation", "dither", "linear", "motor", "friction_estimate")]


class BlockController(_ctypes.Structure):
    _fields_ = [("parameters", BlockParameters), ("integral", _ctypes.c_double),
                ("x", Blocks), ("output", BlockOutput)]


class Sensors(_ctypes.Structure):
    _fields_ = [(name, _ctypes.c_double) for name in (
        "time", "position", "measured_velocity", "relative_velocity", "payload_acceleration",
        "base_acceleration", "friction_force")]


def build_controller(tmp_path, source):
    """Compile an exported controller.c alone, strictly (-Wall -Wextra -pedantic -Werror),
    without include folders; its functions declared for ctypes."""
    from qzs.export.csource import compile_shared

    path = tmp_path / "controller.c"
    path.write_text(source)
    library = compile_shared([path], tmp_path / "controller.so",
                             flags=("-O2", "-std=c99", "-pedantic", "-Wall", "-Wextra",
                                    "-Werror", "-ffp-contract=off", "-fPIC"))
    lib = _ctypes.CDLL(str(library))
    lib.qzs_controller_init.argtypes = [_ctypes.POINTER(Controller), _ctypes.POINTER(Parameters),
                                        _ctypes.c_double]
    lib.qzs_controller_step.argtypes = [_ctypes.POINTER(Controller), _ctypes.c_double,
                                        _ctypes.c_double]
    lib.qzs_controller_step.restype = Output
    lib.qzs_block_controller_init.argtypes = [
        _ctypes.POINTER(BlockController), _ctypes.POINTER(BlockParameters), _ctypes.c_double,
        _ctypes.POINTER(Blocks), _ctypes.POINTER(BlockOutput)]
    lib.qzs_block_controller_step.argtypes = [_ctypes.POINTER(BlockController),
                                              _ctypes.POINTER(Sensors)]
    lib.qzs_block_controller_step.restype = BlockOutput
    return lib


# ---------------------------------------------------------------- rig logs (tests/iotools/rig)
#: A rig log's sample rate [Hz], time [s], base and payload velocities [mm/s].
LOG_RATE = 200.0
LOG_TIME = np.arange(400) / LOG_RATE
LOG_BASE = 50.0 * np.sin(2 * np.pi * 3.0 * LOG_TIME)
LOG_PAYLOAD = 20.0 * np.cos(2 * np.pi * 3.0 * LOG_TIME)
#: The channel map of those logs (the payload through a scale of 2).
LOG_MAP = {"channels": {"base_velocity": {"source": "shaker_vel", "unit": "mm/s"},
                        "payload_velocity": {"source": "payload_vel", "unit": "mm/s",
                                             "scale": 2.0}}}


def check_log_recording(recording, rtol=1e-7):
    """The Recording of a log of LOG_TIME, LOG_BASE and LOG_PAYLOAD read through LOG_MAP."""
    import pytest

    from qzs.iotools.rig import Recording

    assert isinstance(recording, Recording)
    assert recording.sample_rate == pytest.approx(LOG_RATE)
    np.testing.assert_allclose(recording.time, LOG_TIME, atol=1e-9)
    np.testing.assert_allclose(recording["base_velocity"], LOG_BASE * 1e-3, rtol=rtol, atol=1e-9)
    np.testing.assert_allclose(recording["payload_velocity"], 2 * LOG_PAYLOAD * 1e-3, rtol=rtol,
                               atol=1e-9)
    assert dict(recording.units) == {"base_velocity": "m/s", "payload_velocity": "m/s"}


def write_log_csv(path, time=LOG_TIME, base=LOG_BASE, payload=LOG_PAYLOAD):
    """A rig log as CSV: a comment line, the names, the rows (and an unused column)."""
    with open(path, "w") as handle:
        handle.write("# a comment line\ntime, shaker_vel, payload_vel, unused\n")
        for row in zip(time, base, payload, np.zeros(len(time))):
            handle.write(",".join(repr(float(x)) for x in row) + "\n")
    return path


class HeldExecutor:
    """An executor whose futures the test completes, in any order (the app's updates)."""

    def __init__(self):
        self.jobs = []

    def submit(self, function, request):
        from concurrent.futures import Future

        future = Future()
        self.jobs.append((future, function, request))
        return future

    def finish(self, index=0):
        """Compute the job at ``index`` in this thread; its future's callbacks run here."""
        future, function, request = self.jobs.pop(index)
        try:
            future.set_result(function(request))
        except Exception as error:  # noqa: BLE001 - the updater delivers it
            future.set_exception(error)


#: A Duffing isolator (issue 41): mass [kg], linear stiffness k1 [N/m] and viscous damping c
#: [N*s/m] (damping ratio 0.030 at 1.258 Hz) about the equilibrium z = -0.060 m, where the
#: polynomial's constant carries the weight; no dry friction, no controller, stops 79 mm away.
DUFFING_MASS, DUFFING_K1, DUFFING_DAMPING, DUFFING_CENTER = 6.4, 400.0, 3.0, -0.060
#: Cubic stiffness k3 [N/m^3] and base amplitude Y [m] of a hardening and a softening case.
DUFFING_HARDENING = (3.2e6, 0.3e-3)
DUFFING_SOFTENING = (-1.6e6, 0.35e-3)


def duffing_case(k3):
    """``(isolator, controller)`` of the Duffing isolator with cubic stiffness ``k3``.

    In relative coordinates ``u = z - center`` under the base ``y = Y cos(w t)`` it is
    ``m u'' + c u' + k1 u + k3 u^3 = m Y w^2 cos(w t)`` (the weight carried by the
    polynomial's constant, so the mean of ``u`` is zero for an odd restoring force).
    """
    m = DUFFING_MASS
    law = qzs.PolynomialSpring(coefficients=(m * 9.81, -DUFFING_K1, 0.0, -k3),
                               center=DUFFING_CENTER)
    isolator = IsolatorParameters(mass=m, gravity=9.81, stiction_force=0.0, coulomb_force=0.0,
                                  viscous_damping=DUFFING_DAMPING, spring=law, stroke_half=0.079)
    return isolator, ControllerParameters(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0,
                                          position_setpoint=DUFFING_CENTER)


def duffing_amplitudes(frequency, k3, amplitude):
    """The single-harmonic closed form: every fundamental amplitude A [m] of ``u`` at
    ``frequency`` [Hz], the positive roots of
    ``[(k1 + 3/4 k3 A^2 - m w^2)^2 + (c w)^2] A^2 = (m Y w^2)^2`` (a cubic in A^2),
    ascending (three inside the folds)."""
    m, k1, c = DUFFING_MASS, DUFFING_K1, DUFFING_DAMPING
    w = 2 * np.pi * frequency
    a, d = 0.75 * k3, k1 - m * w * w
    roots = np.roots([a * a, 2 * a * d, d * d + (c * w) ** 2, -(m * amplitude * w * w) ** 2])
    squares = roots[(np.abs(roots.imag) <= 1e-9 * np.abs(roots)) & (roots.real > 0)].real
    return np.sort(np.sqrt(squares))


def duffing_transmissibility(frequency, k3, amplitude, relative):
    """Payload over base fundamental of the closed form at the amplitude ``relative`` [m]:
    ``|1 + m w^2 / (k1 + 3/4 k3 A^2 - m w^2 + i c w)|`` [-]."""
    w = 2 * np.pi * frequency
    m = DUFFING_MASS
    stiffness = DUFFING_K1 + 0.75 * k3 * relative ** 2
    return abs(1 + m * w * w / (stiffness - m * w * w + 1j * DUFFING_DAMPING * w))


def duffing_harmonic_bound(frequency, k3, relative, third):
    """Bound [m] on how far the fundamental of a response with harmonics lies from the
    single-harmonic closed form's ``relative`` [m], its third harmonic being ``third`` [m].

    The third harmonic adds ``3/4 k3 A^2 A3`` to the cubic force's fundamental (to first
    order); a force ``dF`` on the fundamental moves the amplitude of
    ``Phi(A) = A sqrt((K(A) - m w^2)^2 + (c w)^2) = F`` by at most ``dF / |Phi'(A)|`` to
    first order; twice that covers the higher orders (off the folds, where Phi' = 0).
    """
    m, c = DUFFING_MASS, DUFFING_DAMPING
    w = 2 * np.pi * frequency
    detuning = DUFFING_K1 + 0.75 * k3 * relative ** 2 - m * w * w
    dynamic = np.hypot(detuning, c * w)
    slope = dynamic + relative * detuning * 1.5 * k3 * relative / dynamic
    return 2 * 0.75 * abs(k3) * relative ** 2 * third / abs(slope)


def instron_test(seed=0, isolator=None, offset=3.0, noise=0.2, rate=1000.0, cycles=4,
                 amplitude=0.030, frequency=0.5):
    """Imposed sine about the operating point, force the machine applies (model law + noise):
    ``(time [s], displacement [m], force [N])`` of a friction test (``qzs.fit_friction``)."""
    isolator = isolator or IsolatorParameters()
    rng = np.random.default_rng(seed)
    time = np.arange(0.0, cycles / frequency, 1.0 / rate)
    omega = 2 * np.pi * frequency
    z = -0.060 + amplitude * np.sin(omega * time)
    v = amplitude * omega * np.cos(omega * time)
    a = -amplitude * omega ** 2 * np.sin(omega * time)
    force = (isolator.mass * a - qzs.spring_force(z, isolator) - qzs.friction_force(v, isolator)
             + offset + rng.normal(0.0, noise, time.size))
    return time, z + rng.normal(0.0, 2e-6, time.size), force


#: A small two-objective problem of the linearised isolator (``qzs.optimize``): a stiffer
#: position loop hunts less but isolates less at 1 Hz.
LINEAR_PROBLEM = {
    "problem": {"name": "linear", "title": "linear trade-off"},
    "variables": {"damping_gain": {"low": 0.0, "high": 300.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "objectives": [{"metric": "linear_transmissibility_at", "frequency": 1.0},
                   {"metric": "hunting_amplitude"}],
    "constraints": [{"metric": "linear_transmissibility_at", "frequency": 5.0, "max": 0.9}],
    "optimizer": {"population": 4, "generations": 2, "seed": 4},
}
#: A small sensitivity problem of the linearised isolator (``qzs.sensitivity``, 8 samples).
SENSITIVITY_PROBLEM = {
    "problem": {"name": "linear", "title": "Linearised isolator at 3 Hz"},
    "variables": {"pi_kp": {"low": 1.0, "high": 100.0}, "mass": {"low": 5.0, "high": 8.0}},
    "objectives": [{"metric": "linear_transmissibility_at", "frequency": 3.0}],
    "sensitivity": {"samples": 8}}


#: A small study of the paper's kind: two cases of the viscous study, short chirps, a given step.
SMALL_STUDY = """
[study]
name = "small"
title = "Passive isolator, two viscous frictions (small)"
kind = "transmissibility"
[[study.view]]
figure = "small"
frequency_range = [0.0, 20.0]
[defaults]
pi_kp = 5.0
pi_ki = 2.0
[[case]]
label = "Cv = 60 N s/m"
viscous_damping = 60.0
[[case]]
label = "Cv = 120 N s/m"
viscous_damping = 120.0
[excitation]
amplitude = 0.010
f0 = 0.0
f1 = 20.0
duration = 20.0
[analysis]
sample_rate = 100.0
fft_length = 512
[simulation]
dt = 5e-4
"""


def tiny_hexapod_study(folder):
    """The six-axis study's result (``qzs hexapod study``) from a tiny real run of its three
    cases: 4 s chirps at a given dt = 1 ms (its own quick run is 60 s chirps, minutes)."""
    import qzs
    from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod
    from qzs.workflows.hexapod.study import CASES, STUDY_AXES, study_result

    cases = {label: qzs.hexapod_transmissibility(load_hexapod(SHIPPED_DEFAULT, overrides),
                                                 axes=STUDY_AXES, duration=4.0, dt=1e-3,
                                                 fft_length=512, workers=1, progress=False)
             for label, (_, overrides) in CASES.items()}
    return study_result(cases, folder, quick=True, run_seconds=1.5)
