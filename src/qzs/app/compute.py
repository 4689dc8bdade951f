"""What the tuning page shows, computed without any widget (docs/app.md).

:func:`page_request` turns the page's values, named as the parameter registry names them
(``stiction_force``, ``pi_kp``, ``excitation.f1``, ...), into a validated
:class:`PageRequest`: the same parameter objects and excitations as the API builds, so
the same checks and messages, plus the page's size limits (:data:`LIMITS`).
:func:`compute_page` runs a request through the public API and returns
:class:`PageData`, the arrays every figure draws; :func:`config_text` writes the request
as a TOML run configuration that ``qzs simulate --config`` reads.

>>> from qzs.app.compute import compute_page, page_request
>>> data = compute_page(page_request({"stiction_force": 5.0}))  # doctest: +SKIP
>>> data.frequency, data.transmissibility_db  # the trusted bins only  # doctest: +SKIP

Nothing here re-implements the model: the runs are :func:`qzs.simulate` and
:func:`qzs.workflows.response.steady_state_response`, the estimate
:func:`qzs.transmissibility`, the overlay :func:`qzs.linearize`, the integration step
:func:`qzs.engine.accuracy.choose_step`.
"""
import functools
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from qzs import defaults
from qzs._format import decibels
from qzs._validation import choice, integer, real
from qzs.errors import ParameterError, SizeLimitError
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import build_excitation
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import (ALL_PARAMETERS, SPRING_PARAMETERS, law_parameters,
                                parameter_info, parameter_value, update_parameters)
from qzs.model.springs import SpringLaw, TanhSpring

__all__ = ["PageRequest", "PageData", "SizeLimitError", "page_request", "compute_page",
           "config_text", "resolve_page_run", "page_values", "page_parameters",
           "law_slider_range", "LIMITS", "PAGE_DEFAULTS", "MODEL_PARAMETERS", "COMPENSATION",
           "EXCITATION_KINDS", "SAMPLE_RATES", "CONTROLLER_RATES",
           "MAX_STEPS", "TRACE_POINTS"]

#: The model parameters the page sets (registry names), in the order of its panels.
MODEL_PARAMETERS = ("stiction_force", "coulomb_force", "stribeck_decay", "viscous_damping",
                    "mass", "spring_force", "spring_shape", "pi_kp", "pi_ki", "damping_gain",
                    "velocity_highpass", "controller_rate", "compensation.fraction")
#: The MagSpring's tanh parameters among :data:`MODEL_PARAMETERS`: a page started with
#: another spring law (``qzs app --spring``) shows that law's ``spring.*`` parameters instead.
TANH_PARAMETERS = ("spring_force", "spring_shape")
#: The page's friction compensation: a fraction of the friction law [0, 1.5]; 0 (its
#: default) is no :class:`~qzs.model.controller.FrictionCompensation` block.
COMPENSATION = "compensation.fraction"
#: The page's excitations: a chirp estimated by Welch, or a stepped sine (steady state).
EXCITATION_KINDS = ("chirp", "stepped")
#: Output rates the page offers [Hz] (each a whole fraction of the paper's 1e4 Hz step rate).
SAMPLE_RATES = (250.0, 500.0, 1000.0, 2000.0)
#: Controller rates the page offers [Hz]; 0 is the continuous controller.
CONTROLLER_RATES = (0.0, 250.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0)

#: The page's own settings where the API's default is the paper's long run: a 200 s chirp
#: (0.1 Hz/s, ten times the paper's rate; its trusted transmissibility lies within a median
#: 0.01 dB of the paper's 2000 s chirp over 1-19 Hz, docs/app.md), the payload's response
#: to a 3 Hz sine over 10 s, 12 frequencies for a stepped sine.
PAGE_DEFAULTS: dict[str, Any] = {"excitation.kind": "chirp", "excitation.duration": 200.0,
                 "frequency_count": 12, "sine.frequency": 3.0, "sine.duration": 10.0,
                 "sample_rate": defaults.SIMULATION["sample_rate"]}

#: Bounds on what one request may ask for: name -> (lowest, highest, unit). They keep a
#: request from exhausting the machine (the sizes) or from asking for what the estimate
#: cannot deliver (a chirp too short for Welch segments).
LIMITS = {
    "excitation.duration": (10.0, 600.0, "s"),
    "excitation.f1": (0.0, 50.0, "Hz"),
    "frequency_count": (2, 40, "1"),
    "sine.frequency": (0.1, 50.0, "Hz"),
    "sine.duration": (4.0, 60.0, "s"),
    "sample_rate": (min(SAMPLE_RATES), max(SAMPLE_RATES), "Hz"),
}
#: Integration steps one request may take at most [-] (chirp or stepped sine, the sine's
#: time response and the step choice's probes aside): about 2 s of integration here.
MAX_STEPS = 10_000_000
#: Simulated time at most per frequency of a stepped sine [s] (the workflow's default cap,
#: 30 of the loop's slowest time constants, is 115 s for the paper's loop).
STEPPED_MAX_TIME = 120.0
#: Tolerance of the sine run's step: this share of the amplitude in relative position [-].
SINE_STATE_TOLERANCE = 1e-3
#: Welch segments a chirp's estimate averages about [-] (half-overlapping).
WELCH_SEGMENTS = 24
#: Points each time trace sends to the browser at most (a min/max envelope beyond).
TRACE_POINTS = 4000
#: Frequencies of the linear model's curve, log-spaced over the band [-].
LINEAR_POINTS = 400


def _other_law(spring):
    """``spring`` unless it is None or the MagSpring's tanh (whose sliders are the fields');
    anything but a law is refused."""
    if spring is not None and not isinstance(spring, SpringLaw):
        raise ParameterError(f"`spring` must be a spring law (qzs.model.springs) or None for "
                             f"the MagSpring, got {type(spring).__name__}.", ("spring",))
    return None if isinstance(spring, TanhSpring) else spring


def page_parameters(spring=None):
    """The model parameters of a page started with the spring law ``spring``, in panel order.

    Parameters
    ----------
    spring : SpringLaw, optional
        The page's spring law (``qzs app --spring``); None or a
        :class:`~qzs.model.springs.TanhSpring`: the MagSpring, whose parameters are
        ``spring_force`` and ``spring_shape``.

    Returns
    -------
    tuple of str
        :data:`MODEL_PARAMETERS`, the tanh's two replaced by the law's ``spring.*``
        parameters (:func:`qzs.model.registry.law_parameters`; none for a table).
    """
    law = _other_law(spring)
    if law is None:
        return MODEL_PARAMETERS
    names = []
    for name in MODEL_PARAMETERS:
        if name == TANH_PARAMETERS[0]:
            names.extend(law_parameters(law))
        elif name not in TANH_PARAMETERS:
            names.append(name)
    return tuple(names)


def _base_isolator(spring):
    """The paper's isolator with the page's spring law: a tanh's numbers in its fields (so
    its sliders are the MagSpring's), another law as ``spring``."""
    law = _other_law(spring)
    if law is not None:
        return IsolatorParameters(spring=law)
    if spring is None:
        return IsolatorParameters()
    return IsolatorParameters(spring_force=spring.plateau, spring_shape=spring.shape)


def _unit_scale(unit, isolator):
    """What a zero ``spring.*`` value's slider spans in ``unit``: the payload's weight m*g
    [N], m*g/h^k [N/m^k] (h the half-stroke), h [m]; None for another unit."""
    weight, h = isolator.mass * isolator.gravity, isolator.stroke_half
    if unit == "m":
        return h
    if unit == "N":
        return weight
    if unit.startswith("N/m"):
        power = unit[len("N/m"):]
        return weight / h ** (int(power[1:]) if power.startswith("^") else 1)
    return None


def _accepts(isolator, name, value):
    try:
        update_parameters(isolator, ControllerParameters(), {name: value})
    except ParameterError:
        return False
    return True


def law_slider_range(spring, name):
    """The slider of a law's parameter ``name`` around the law's value x: (start, end, step).

    ``[0, 2x]`` where the law keeps the parameter >= 0 (it takes 0 and refuses a negative
    value: the oblique spring's stiffnesses); ``x +- 50 %`` of ``|x|`` for any other (lengths
    kept > 0, the centre, the preload, a polynomial's coefficients). A zero value has no
    scale of its own: it spans ``+-S`` (``[0, S]`` where kept >= 0), ``S`` the scale of the
    registry's unit on the paper's isolator: its weight ``m*g`` for [N], ``m*g/h^k`` for
    [N/m^k] (``h`` the half-stroke), ``h`` for [m]. The step is the 1-2-5 number at most a
    200th of the span; the ends are whole steps around it.

    Parameters
    ----------
    spring : SpringLaw
        The page's law (not the tanh).
    name : str
        One of its ``spring.*`` parameters (:func:`qzs.model.registry.law_parameters`).

    Returns
    -------
    tuple of float
        Start, end and step in the registry's unit.

    Raises
    ------
    ParameterError
        ``name`` is no parameter of ``spring``.
    """
    isolator = _base_isolator(spring)
    if name not in law_parameters(isolator.spring):
        raise ParameterError(f"`name` ({name!r}) is no parameter of the spring law "
                             f"{spring.describe()}; its parameters are "
                             f"{', '.join(law_parameters(isolator.spring)) or 'none'}.",
                             ("name",))
    value = float(parameter_value(isolator, ControllerParameters(), name))
    half = abs(value) / 2 if value != 0.0 else (
        _unit_scale(SPRING_PARAMETERS[name].unit, isolator) or 1.0)
    kept = _accepts(isolator, name, 0.0) and not _accepts(isolator, name, -half)
    if value == 0.0:
        low, high = (0.0, half) if kept else (-half, half)
    elif kept and value > 0.0:
        low, high = 0.0, 2 * value
    else:
        low, high = value - half, value + half
    span = high - low
    exponent = math.floor(math.log10(span / 200))
    step = max(m * 10.0 ** exponent for m in (1, 2, 5) if m * 10.0 ** exponent <= span / 200)
    digits = max(0, -exponent)  # a whole step's decimals: no 0.09000000000000001
    return (round(math.floor(low / step) * step, digits),
            round(math.ceil(high / step) * step, digits), step)


def _bounded(name, value):
    low, high, unit = LIMITS[name]
    if not low <= value <= high:
        raise SizeLimitError(name, value, low, high, unit)
    return value


@dataclass(frozen=True, kw_only=True)
class PageRequest:
    """One setting of the page: everything a computation needs, validated.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    excitation : {"chirp", "stepped"}
        ``chirp``: a linear chirp over ``band`` in ``chirp_duration``, its transmissibility
        estimated by Welch; ``stepped``: a stepped sine, the steady state at
        ``frequency_count`` frequencies over ``band``.
    amplitude : float
        Base displacement amplitude of the chirp or the stepped sine [m].
    band : tuple of float
        ``(f0, f1)`` [Hz]: the chirp's start and end, the stepped sine's range.
    chirp_duration : float
        Sweep time of the chirp [s].
    frequency_count : int
        Frequencies of the stepped sine [-].
    sine_frequency : float
        Frequency of the sine whose time response the page shows [Hz].
    sine_duration : float
        Simulated time of that sine run [s] (2 s fade-in included).
    sample_rate : float
        Output rate of the runs [Hz], one of :data:`SAMPLE_RATES`.
    spring : SpringLaw, optional
        The spring law the page started with (``qzs app --spring``), before its sliders:
        it names the page's spring parameters (:func:`page_parameters`); ``isolator.spring``
        is this law with the sliders' values. None: the MagSpring.

    Raises
    ------
    ParameterError
        An invalid value (the API's own checks); :class:`SizeLimitError` for a value
        outside :data:`LIMITS`; an isolator whose spring law is not of ``spring``'s kind.
    """

    isolator: IsolatorParameters
    controller: ControllerParameters
    excitation: str = "chirp"
    amplitude: float = parameter_info("excitation.amplitude", "chirp").default
    band: tuple = (parameter_info("excitation.f0", "chirp").default,
                   parameter_info("excitation.f1", "chirp").default)
    chirp_duration: float = PAGE_DEFAULTS["excitation.duration"]
    frequency_count: int = PAGE_DEFAULTS["frequency_count"]
    sine_frequency: float = PAGE_DEFAULTS["sine.frequency"]
    sine_duration: float = PAGE_DEFAULTS["sine.duration"]
    sample_rate: float = PAGE_DEFAULTS["sample_rate"]
    spring: SpringLaw | None = None

    def __post_init__(self):
        if not isinstance(self.isolator, IsolatorParameters):
            raise ParameterError(f"`isolator` must be an IsolatorParameters, got "
                                 f"{type(self.isolator).__name__}.")
        base = _base_isolator(self.spring)  # refuses a `spring` that is no law
        if type(self.isolator.spring) is not type(base.spring):
            kinds = [getattr(law, "kind", "tanh") for law in (self.isolator.spring, base.spring)]
            raise ParameterError(
                f"`isolator` has a {kinds[0]!r} spring law and the page's `spring` is a "
                f"{kinds[1]!r} law: the page's sliders set the parameters of the law it "
                "started with; give an isolator with a law of that kind.",
                ("isolator", "spring"))
        if not isinstance(self.controller, ControllerParameters):
            raise ParameterError(f"`controller` must be a ControllerParameters, got "
                                 f"{type(self.controller).__name__}.")
        choice("excitation", self.excitation, EXCITATION_KINDS)
        try:
            f0, f1 = self.band
        except (TypeError, ValueError):
            raise ParameterError(f"`band` must be two frequencies (f0, f1) in Hz, got "
                                 f"{self.band!r}.") from None
        band = (real("excitation.f0", f0), real("excitation.f1", f1))
        object.__setattr__(self, "band", band)
        _bounded("excitation.f1", max(band))
        for name, field in (("sine.frequency", "sine_frequency"),
                            ("sine.duration", "sine_duration"),
                            ("excitation.duration", "chirp_duration"),
                            ("sample_rate", "sample_rate")):
            object.__setattr__(self, field, _bounded(name, real(name, getattr(self, field))))
        count = integer("frequency_count", self.frequency_count, 1)
        object.__setattr__(self, "frequency_count", _bounded("frequency_count", count))
        choice("sample_rate", self.sample_rate, SAMPLE_RATES)
        top = max(max(band), self.sine_frequency)
        if self.sample_rate < 5.0 * top:
            raise ParameterError(
                f"`sample_rate` ({self.sample_rate:g} Hz) must be at least 5 times the highest "
                f"frequency asked for ({top:g} Hz), so that the payload's acceleration is "
                "resolved; raise it or lower the frequencies.")
        self.chirp()  # the excitation's own checks (ExcitationError)
        self.sine()
        if self.excitation == "stepped":
            if band[1] <= 0.0 or band[0] > band[1]:
                raise ParameterError(f"a stepped sine needs a band 0 <= f0 <= f1 with f1 > 0, "
                                     f"got ({band[0]:g}, {band[1]:g}) Hz.")

    def chirp(self):
        """The chirp of the request (:class:`qzs.Chirp`), linear over ``band``."""
        return build_excitation("chirp", {"amplitude": self.amplitude, "f0": self.band[0],
                                          "f1": self.band[1], "duration": self.chirp_duration})

    def sine(self):
        """The sine of the time response (:class:`qzs.Sine`, the default 2 s fade-in)."""
        return build_excitation("sine", {"amplitude": self.amplitude,
                                         "frequency": self.sine_frequency})

    def stepped_frequencies(self):
        """Frequencies of the stepped sine [Hz], ascending.

        ``frequency_count`` log-spaced over the band, or, when the band starts at 0 Hz,
        linearly spaced over it without 0 (``f1*k/n``, k = 1..n).

        Returns
        -------
        ndarray
        """
        low, high = self.band
        n = self.frequency_count
        if low > 0.0:
            return np.geomspace(low, high, n)
        return high * np.arange(1, n + 1) / n

    def values(self):
        """The request as the page's values (:func:`page_request`'s input) [SI units]."""
        return page_values(self)


def page_values(request=None):
    """The page's values (registry names -> SI values) of a request, default the page's.

    Parameters
    ----------
    request : PageRequest, optional
        Default :func:`page_request` of nothing: the paper's parameters and
        :data:`PAGE_DEFAULTS`.

    Returns
    -------
    dict
        Every key :func:`page_request` takes.
    """
    request = request or page_request()
    values = {name: parameter_value(request.isolator, request.controller, name, 0.0)
              for name in page_parameters(request.spring)}
    values.update({"excitation.kind": request.excitation,
                   "excitation.amplitude": request.amplitude,
                   "excitation.f0": request.band[0], "excitation.f1": request.band[1],
                   "excitation.duration": request.chirp_duration,
                   "frequency_count": request.frequency_count,
                   "sine.frequency": request.sine_frequency,
                   "sine.duration": request.sine_duration,
                   "sample_rate": request.sample_rate})
    return values


_REQUEST_FIELDS = {"excitation.kind": "excitation", "excitation.amplitude": "amplitude",
                   "excitation.duration": "chirp_duration", "frequency_count": "frequency_count",
                   "sine.frequency": "sine_frequency", "sine.duration": "sine_duration",
                   "sample_rate": "sample_rate"}


def page_request(values=None, spring=None):
    """A validated :class:`PageRequest` from the page's values.

    Parameters
    ----------
    values : dict, optional
        Registry names of model parameters (``stiction_force`` [N], ``pi_kp`` [N/m], ...;
        see ``qzs params``; ``compensation.fraction`` [-] adds a friction compensation,
        0 none; with a ``spring`` law its ``spring.*`` parameters instead of
        ``spring_force`` and ``spring_shape``: :func:`page_parameters`) and the page's own
        settings: ``excitation.kind`` (``chirp`` or
        ``stepped``), ``excitation.amplitude`` [m], ``excitation.f0``, ``excitation.f1``
        [Hz], ``excitation.duration`` [s], ``frequency_count``, ``sine.frequency`` [Hz],
        ``sine.duration`` [s], ``sample_rate`` [Hz]. Missing ones take the paper's
        defaults and :data:`PAGE_DEFAULTS`.
    spring : SpringLaw, optional
        The page's spring law (``qzs app --spring``), to which the ``spring.*`` values
        apply; None: the MagSpring. A :class:`~qzs.model.springs.TanhSpring` gives its
        numbers to ``spring_force`` and ``spring_shape``.

    Returns
    -------
    PageRequest

    Raises
    ------
    ParameterError
        An unknown name, or an invalid value: the message of the API's own validation
        (:class:`qzs.IsolatorParameters`, :class:`qzs.Chirp`, ...), or a
        :class:`SizeLimitError`; a ``spring.*`` name the law has not, or the tanh's
        ``spring_force``, ``spring_shape`` with another law (the error names it).
    """
    values = dict(values or {})
    names = page_parameters(spring)
    model = {name: values.pop(name) for name in list(values) if name in ALL_PARAMETERS}
    if not isinstance(model.get(COMPENSATION), str) and model.get(COMPENSATION) == 0:
        del model[COMPENSATION]  # no compensation: no block (the kernels of PI + damping)
    for name in TANH_PARAMETERS:
        if name in model and name not in names:
            raise ParameterError(
                f"`{name}` is a parameter of the MagSpring's tanh, and the page's spring is "
                f"the {spring.kind!r} law it was started with (qzs app --spring); its "
                f"parameters are {', '.join(law_parameters(spring)) or 'none (a table)'}.",
                (name,))
    isolator, controller = update_parameters(_base_isolator(spring), ControllerParameters(),
                                             model)
    band = (values.pop("excitation.f0", parameter_info("excitation.f0", "chirp").default),
            values.pop("excitation.f1", parameter_info("excitation.f1", "chirp").default))
    options = {}
    for key in list(values):
        if key not in _REQUEST_FIELDS:
            others = ["excitation.f0", "excitation.f1", *_REQUEST_FIELDS]
            raise ParameterError(f"unknown page setting {key!r}; the page takes the model "
                                 f"parameters ({', '.join(names)}) and "
                                 f"{', '.join(others)}.")
        options[_REQUEST_FIELDS[key]] = values.pop(key)
    return PageRequest(isolator=isolator, controller=controller, band=band, spring=spring,
                       **options)


# ---------------------------------------------------------------- the step
def resolve_page_run(excitation, isolator, controller, sample_rate, duration=None,
                     tolerance_state=None):
    """A page run resolved as ``qzs simulate`` resolves it (:func:`qzs.engine.run_spec.resolve`).

    The step is chosen for the default accuracy (``step="chosen"``), or for
    ``tolerance_state`` [m] where given (the sine's, relative to its amplitude), with the
    one fallback and the step cache; so the page gives the step and the numbers that
    ``qzs simulate`` and ``qzs.simulate(..., tolerance=0.01)`` give for the same inputs.
    Kept per (excitation, parameters, rate): moving a slider back costs no new choice.

    Parameters
    ----------
    excitation : Chirp or Sine
        The run's excitation.
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    sample_rate : float
        Output rate [Hz].
    duration : float, optional
        Simulated time [s] (a sine's; a chirp: its length).
    tolerance_state : float, optional
        Tolerance on the relative position [m].

    Returns
    -------
    ResolvedRun
    """
    return _resolved(excitation, isolator, controller, float(sample_rate), duration,
                     tolerance_state)


@functools.lru_cache(maxsize=64)
def _resolved(excitation, isolator, controller, sample_rate, duration, tolerance_state):
    from qzs.engine.run_spec import resolve

    return resolve(excitation, isolator, controller, duration=duration, sample_rate=sample_rate,
                   tolerance_state=tolerance_state, step="chosen")


def _step_note(step):
    """The unmet tolerance's one sentence, for the page's notes (empty where it was met)."""
    return step.unmet_note


@functools.lru_cache(maxsize=64)
def _response_step(frequencies, amplitude, isolator, controller, sample_rate):
    from qzs.workflows.response import response_step

    return response_step(np.asarray(frequencies), amplitude, isolator, controller,
                         solver=defaults.SIMULATION["solver"], sample_rate=sample_rate)


def _check_steps(name, simulated_time, dt):
    steps = simulated_time / dt
    if steps > MAX_STEPS:
        raise SizeLimitError(f"integration steps of the {name}", steps, 0, MAX_STEPS, "1")


# ---------------------------------------------------------------- the figures' data
@dataclass(frozen=True, kw_only=True)
class PageData:
    """Everything the page draws for one request (arrays in SI units unless named).

    Attributes
    ----------
    request : PageRequest
        The setting computed.
    frequency : ndarray
        Frequencies of the transmissibility [Hz]: the trusted bins of the chirp's
        estimate, or the stepped sine's settled frequencies.
    transmissibility_db : ndarray
        Transmissibility there [dB] (payload over base acceleration).
    linear_frequency, linear_db : ndarray
        The linearised closed loop's ``|X/Y|`` [Hz], [dB] over the band (drawn dashed).
    traces : dict
        The sine run's time traces, name -> ``(time [s], values)``: ``base_displacement``,
        ``payload_displacement`` (from its rest position at t = 0), ``relative_position``
        [m], ``motor_force`` [N] (a min/max envelope of at most :data:`TRACE_POINTS` points
        each).
    stop_low, stop_high : float
        The hard stops in relative position [m].
    position_setpoint : float
        The PI loop's setpoint [m].
    motor_force_max : float
        The motor's force limit [N].
    locked_share : dict
        Share of the time the payload is locked [-]: ``sine`` (the sine run) and
        ``excitation`` (the chirp run, or the mean over the stepped sine's periods).
    summary : dict
        The excitation run's peak stroke [m] (``peak_stroke``, from the stops' centre),
        ``motor_force_peak`` [N] (chirp only), ``saturated_fraction`` [-],
        ``stop_contacts`` [-], and the sine run's ``sine_peak_stroke`` [m],
        ``sine_motor_force_peak`` [N].
    dt : float
        Integration step of the chirp or stepped sine [s].
    step_error : float
        Its estimated error [dB] (NaN when no step met the tolerance).
    sine_dt : float
        Integration step of the sine run [s].
    estimate : TransmissibilityEstimate or None
        The chirp's whole estimate (None for a stepped sine).
    response : SteadyStateResponse or None
        The stepped sine's response (None for a chirp).
    notes : tuple of str
        What the reader should know (a fallback step, unsettled frequencies, ...).
    elapsed : float
        Wall time of the computation [s].
    """

    request: PageRequest
    frequency: np.ndarray
    transmissibility_db: np.ndarray
    linear_frequency: np.ndarray
    linear_db: np.ndarray
    traces: dict
    stop_low: float
    stop_high: float
    position_setpoint: float
    motor_force_max: float
    locked_share: dict
    summary: dict
    dt: float
    step_error: float
    sine_dt: float
    estimate: object = None
    response: object = None
    notes: tuple = ()
    elapsed: float = 0.0


def welch_length(samples):
    """Welch segment length [samples] of a chirp run of ``samples`` samples.

    The largest power of two giving at least :data:`WELCH_SEGMENTS` half-overlapping
    segments, between 256 and the paper's 32768.

    Parameters
    ----------
    samples : int
        Samples of the run [-].

    Returns
    -------
    int
    """
    longest = 2 * samples / (WELCH_SEGMENTS + 1)
    length = 2 ** int(np.floor(np.log2(max(longest, 256))))
    return int(min(length, defaults.ANALYSIS["fft_length"]))


def _linear_curve(request):
    from qzs.analysis.linear import linearize

    low, high = min(request.band), max(request.band)
    if request.excitation == "stepped" and low == 0.0:
        low = high / request.frequency_count
    low = max(low, high / LINEAR_POINTS)
    frequency = np.geomspace(low, high, LINEAR_POINTS)  # even on the page's log axis
    return frequency, decibels(linearize(request.isolator, request.controller)
                               .transmissibility(frequency))


def _chirp(request):
    from qzs.analysis.spectral import transmissibility

    chirp = request.chirp()
    resolved = resolve_page_run(chirp, request.isolator, request.controller,
                                request.sample_rate)
    dt, error, note = resolved.dt, resolved.step.error, _step_note(resolved.step)
    _check_steps("chirp", chirp.duration, dt)
    result = resolved.simulate()
    estimate = transmissibility(result.base_acceleration, result.payload_acceleration,
                                request.sample_rate,
                                fft_length=welch_length(len(result)))
    keep = estimate.trusted
    statistics = result.statistics
    summary = {"peak_stroke": statistics["peak_stroke"],
               "motor_force_peak": statistics["motor_force_peak"],
               "saturated_fraction": statistics["saturated_fraction"],
               "stop_contacts": float(result.run["stop_contacts"])}
    notes = (note,) if note else ()
    if not keep.any():
        notes += ("no bin of the chirp's estimate is trusted (coherence below "
                  f"{estimate.coherence_min:g} everywhere): nothing to draw; raise the "
                  "amplitude or lengthen the chirp",)
    return dict(frequency=estimate.frequency[keep],
                transmissibility_db=decibels(estimate.magnitude[keep]), dt=dt, step_error=error,
                estimate=estimate, locked=statistics["locked_fraction"], summary=summary,
                notes=notes)


def _stepped(request):
    from qzs.workflows.response import settle_time_cap, steady_state_response

    frequencies = request.stepped_frequencies()
    low, high = float(frequencies[0]), float(frequencies[-1])
    # the step the workflow chooses (a chirp over the band), at the page's rate
    step = _response_step(tuple(frequencies), request.amplitude, request.isolator,
                          request.controller, max(request.sample_rate, 20.0 * high))
    dt, error, note = step.dt, step.error, _step_note(step)
    max_time = min(settle_time_cap(request.isolator, request.controller), STEPPED_MAX_TIME)
    _check_steps("stepped sine", frequencies.size * max_time, dt)
    response = steady_state_response(frequencies, request.amplitude, request.isolator,
                                     request.controller, direction="up", dt=dt,
                                     max_time=max_time, harmonic_balance=False, workers=1)
    branch = response.branch("up")
    keep = np.isfinite(branch["transmissibility"]) & (branch["transmissibility"] > 0)
    center = request.isolator.stop_center
    center = request.controller.position_setpoint if center is None else center
    peak = np.abs(branch["mean_relative_position"] - center) + branch["relative_peak"]
    summary = {"peak_stroke": float(np.nanmax(peak)) if np.isfinite(peak).any() else math.nan,
               "motor_force_peak": math.nan,
               "saturated_fraction": float(np.nanmax(branch["saturated_fraction"]))
               if np.isfinite(branch["saturated_fraction"]).any() else math.nan,
               "stop_contacts": float(np.nansum(branch["stop_contacts"]))}
    locked = branch["locked_fraction"]
    notes = ((note,) if note else ()) + tuple(response.notes)
    return dict(frequency=branch["frequency"][keep],
                transmissibility_db=decibels(branch["transmissibility"][keep]), dt=dt,
                step_error=error, response=response,
                locked=float(np.nanmean(locked)) if np.isfinite(locked).any() else math.nan,
                summary=summary, notes=notes)


def _sine(request):
    from qzs.viz.figures import envelope

    sine = request.sine()
    resolved = resolve_page_run(sine, request.isolator, request.controller, request.sample_rate,
                                duration=request.sine_duration,
                                tolerance_state=SINE_STATE_TOLERANCE * max(request.amplitude,
                                                                           1e-6))
    dt, note = resolved.dt, _step_note(resolved.step)
    _check_steps("sine", request.sine_duration, dt)
    result = resolved.simulate()
    time_ = result.time
    payload = result.payload_displacement
    traces = {name: envelope(time_, values, TRACE_POINTS) for name, values in (
        ("base_displacement", result.base_displacement),
        ("payload_displacement", payload - payload[0]),
        ("relative_position", result.relative_position),
        ("motor_force", result.motor_force))}
    return result, traces, dt, note


def compute_page(request):
    """Compute what the page draws for one request.

    The chirp (Welch estimate, trusted bins only) or the stepped sine (settled frequencies
    only), the linear model over the band, and the payload's response to the sine over
    ``sine_duration``; each run at the step :func:`resolve_page_run` picks for the
    transmissibility within ``qzs.defaults.ACCURACY['tolerance_db']`` (the sine: within
    :data:`SINE_STATE_TOLERANCE` of its amplitude in relative position).

    Parameters
    ----------
    request : PageRequest
        A validated setting (:func:`page_request`).

    Returns
    -------
    PageData

    Raises
    ------
    ParameterError
        A setting the runs refuse (the API's messages), or :class:`SizeLimitError` when
        the chosen step makes a run longer than :data:`MAX_STEPS`.
    SimulationError
        A run diverged.
    """
    if not isinstance(request, PageRequest):
        raise ParameterError(f"`request` must be a PageRequest (see page_request), got "
                             f"{type(request).__name__}.")
    start = time.perf_counter()
    main = _chirp(request) if request.excitation == "chirp" else _stepped(request)
    sine_result, traces, sine_dt, sine_note = _sine(request)
    linear_frequency, linear_db = _linear_curve(request)
    statistics = sine_result.statistics
    summary = {**main["summary"], "sine_peak_stroke": statistics["peak_stroke"],
               "sine_motor_force_peak": statistics["motor_force_peak"]}
    notes = main["notes"] + ((f"sine run: {sine_note}",) if sine_note else ())
    return PageData(
        request=request, frequency=main["frequency"],
        transmissibility_db=main["transmissibility_db"], linear_frequency=linear_frequency,
        linear_db=linear_db, traces=traces, stop_low=sine_result.run["stop_low"],
        stop_high=sine_result.run["stop_high"],
        position_setpoint=request.controller.position_setpoint,
        motor_force_max=request.isolator.motor_force_max,
        locked_share={"sine": statistics["locked_fraction"], "excitation": main["locked"]},
        summary=summary, dt=main["dt"], step_error=main["step_error"], sine_dt=sine_dt,
        estimate=main.get("estimate"), response=main.get("response"), notes=notes,
        elapsed=time.perf_counter() - start)


# ---------------------------------------------------------------- the TOML export
def config_text(request, dt=None):
    """The request as a TOML run configuration (``qzs simulate --config FILE`` reads it).

    ``[isolator]`` and ``[controller]`` hold every model parameter (as ``qzs params
    --toml`` writes them); ``[excitation]`` the chirp, or for a stepped sine the page's
    time-response sine (``qzs simulate`` has no stepped sine; ``qzs response --config`` takes
    the same file with ``--range``); ``[simulation]`` the output rate, the step and, for a
    sine, the duration. Nothing is written: the page hands the text to the browser.

    Parameters
    ----------
    request : PageRequest
        The setting.
    dt : float, optional
        The integration step [s] to record (the page's chosen one); none: omitted, so
        ``qzs simulate`` uses its default.

    Returns
    -------
    str
        UTF-8 TOML text.
    """
    from qzs.iotools.config import config_text as run_config_text

    simulation = {"sample_rate": request.sample_rate}
    if request.excitation == "chirp":
        chirp = request.chirp()
        excitation = {"kind": "chirp", "amplitude": chirp.amplitude, "f0": chirp.f0,
                      "f1": chirp.f1, "duration": chirp.duration}
        header = "the page's chirp"
    else:
        sine = request.sine()
        excitation = {"kind": "sine", "amplitude": sine.amplitude, "frequency": sine.frequency}
        simulation["duration"] = request.sine_duration
        low, high = request.stepped_frequencies()[[0, -1]]
        header = (f"the page's {request.sine_frequency:g} Hz time-response sine; the stepped "
                  f"sine: qzs response --config FILE --range {low:g},{high:g},"
                  f"{request.frequency_count} --direction up")
    if dt is not None:
        simulation["dt"] = float(dt)
    return run_config_text(request.isolator, request.controller, excitation, simulation,
                           note=f"Exported by `qzs app`: {header}. Run it with: qzs simulate "
                                "--config FILE")

