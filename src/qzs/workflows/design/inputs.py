"""The design's inputs checked, in order, before any simulation: the validated settings.

:func:`_design_settings` checks every argument of :func:`~qzs.workflows.design.design_controller`
(a bad one is a :class:`~qzs.errors.ParameterError` naming it, before any simulation), fills
the defaults, and chooses the integration steps (the accuracy-driven step by short probe
runs, and the coarser step of the PI search's runs).
"""
import dataclasses
import math

from qzs._validation import interval, real, worker_count
from qzs.analysis import control_design as cd
from qzs.errors import ParameterError
from qzs.model.excitation import Chirp, DisplacementRecord, RandomExcitation
from qzs.model.registry import model_inputs
from qzs.workflows.design.cases import DesignCase
from qzs.engine.prepare import divides
from qzs.workflows.design.integration_step import _stroke_step, choose_dt
from qzs.workflows.design.settings import (COSTS, FFT_LENGTH, QUICK_CHIRP, SAMPLE_RATE,
                                           DesignSettings)


def _design_settings(isolator, controller, *, excitation, stiction_range, mass_range,
                    force_steps, band, cost, controller_rate, delay, quick, dt,
                    damping_gain_max, gain_margin_min, phase_margin_min, workers, progress):
    """Every argument of ``design_controller`` checked, the defaults filled, the steps chosen.

    The arguments are those of :func:`~qzs.workflows.design.design_controller`, checked in
    its order; the accuracy-driven step is the one part that simulates (short probe runs),
    after every other check.

    Returns
    -------
    DesignSettings
        The validated inputs every stage shares, with the chosen steps.
    """
    isolator, controller = model_inputs(isolator, controller)
    _check_ratio(controller)
    excitation, duration = _excitation(excitation, bool(quick))
    stiction_range, mass_range = _ranges(isolator, stiction_range, mass_range)
    steps = _force_steps(force_steps)
    band = _band(band, excitation)
    if cost not in COSTS:
        raise ParameterError(f"`cost` must be one of {', '.join(COSTS)}, got {cost!r}.")
    rate = controller.controller_rate if controller_rate is None else real(
        "controller_rate", controller_rate, minimum=0.0, fix="in Hz; 0 for continuous")
    delay = real("delay", delay, minimum=0.0, fix="in seconds, e.g. 0.002")
    damping_gain_max = real("damping_gain_max", damping_gain_max, minimum=0.0, strict=True)
    gain_margin_min = real("gain_margin_min", gain_margin_min, minimum=0.0)
    phase_margin_min = real("phase_margin_min", phase_margin_min, minimum=0.0)
    workers = worker_count(workers)
    sample_rate = SAMPLE_RATE if band[1] <= SAMPLE_RATE / 5 else float(
        100 * math.ceil(band[1] * 5 / 100))
    stroke_band = cd.constant_force_band(isolator, controller)
    for fs in stiction_range:  # the case parameters must be valid before anything runs
        for m in mass_range:
            DesignCase("base", fs, m).isolator(isolator)
    settings = DesignSettings(
        isolator=isolator, controller=controller, excitation=excitation, duration=duration,
        stiction_range=stiction_range, mass_range=mass_range, force_steps=steps, band=band,
        cost=cost, controller_rate=rate, delay=delay, quick=bool(quick), dt=math.nan,
        dt_note="", sample_rate=sample_rate, fft_length=FFT_LENGTH[bool(quick)],
        ratio=controller.pi_ki / controller.pi_kp, stroke_band=stroke_band,
        damping_gain_max=damping_gain_max, gain_margin_min=gain_margin_min,
        phase_margin_min=phase_margin_min, workers=workers, progress=bool(progress),
        stroke_dt=math.nan)
    if rate > 0:
        cd.sampled_loop(isolator, controller, rate, delay)  # validates the rate
    _check_duration(settings)
    return _with_steps(settings, dt)


def _check_ratio(controller):
    """The search keeps ``Ki/Kp``: both gains must be positive."""
    if controller.pi_kp <= 0 or controller.pi_ki <= 0:
        raise ParameterError(
            f"the search keeps the controller's ratio Ki/Kp; `pi_kp` ({controller.pi_kp:g} N/m) "
            f"and `pi_ki` ({controller.pi_ki:g} N/(m*s)) must both be positive (e.g. pi_kp=50, "
            "pi_ki=20: a PI zero at 0.064 Hz).")


def _excitation(excitation, quick):
    if excitation is None:
        excitation = Chirp()
    if not isinstance(excitation, (Chirp, RandomExcitation, DisplacementRecord)):
        raise ParameterError(f"`excitation` must be a Chirp, RandomExcitation or "
                             f"DisplacementRecord (a base motion of finite length), got "
                             f"{type(excitation).__name__}; a sine has no band to judge a "
                             "transmissibility over.")
    duration = excitation.duration
    if quick and isinstance(excitation, Chirp) and excitation.duration > QUICK_CHIRP:
        excitation = dataclasses.replace(excitation, duration=QUICK_CHIRP)
        duration = QUICK_CHIRP
    elif quick:
        duration = min(duration, QUICK_CHIRP)
    return excitation, float(duration)


def _ranges(isolator, stiction_range, mass_range):
    """The stiction [N, N] and mass [kg, kg] ranges, checked; defaults about the isolator's."""
    stiction_range = ((0.5 * isolator.stiction_force, 1.5 * isolator.stiction_force)
                      if stiction_range is None else interval("stiction_range", stiction_range,
                                                              "N", example="(5, 15)"))
    if stiction_range[0] < isolator.coulomb_force:
        raise ParameterError(
            f"`stiction_range` starts at {stiction_range[0]:g} N, below the Coulomb friction "
            f"({isolator.coulomb_force:g} N); the breakaway force cannot be below it: start the "
            f"range at {isolator.coulomb_force:g} N or more.")
    mass_range = ((max(0.1, isolator.mass - 0.2), isolator.mass + 0.2) if mass_range is None
                  else interval("mass_range", mass_range, "kg", minimum=1e-9,
                                example="(6.2, 6.6)"))
    if mass_range[0] <= 0:
        raise ParameterError(f"`mass_range` must be positive masses in kg, got {mass_range!r}.")
    return stiction_range, mass_range


def _force_steps(force_steps):
    """The payload force steps [N] as a tuple of floats."""
    try:
        return tuple(real("force_steps", s) for s in force_steps)
    except TypeError:
        raise ParameterError(f"`force_steps` must be a sequence of forces in N, got "
                             f"{force_steps!r}; e.g. (-2, 2).") from None


def _band(band, excitation):
    """The cost's band [Hz, Hz], checked against what the base motion excites."""
    band = interval("band", band, "Hz", example="(1, 20)")
    if band[0] <= 0:
        raise ParameterError(f"`band` must start above 0 Hz, got {band!r}; e.g. (1, 20).")
    top = excitation.max_frequency if not isinstance(excitation, RandomExcitation) else \
        excitation.f_high
    if band[1] > top * (1 + 1e-9):
        raise ParameterError(f"`band` ({band[0]:g}, {band[1]:g}) Hz reaches above the base "
                             f"motion's highest frequency ({top:g} Hz): nothing there is "
                             "excited; lower the band's top.")
    return band


def _check_duration(settings):
    """The base motion must be long enough for two of the cost's Welch segments."""
    duration, sample_rate = settings.duration, settings.sample_rate
    n_fft = int(round(duration * sample_rate))
    if n_fft < 2 * settings.fft_length:
        raise ParameterError(
            f"the base motion ({duration:g} s at {sample_rate:g} Hz) is too short for the "
            f"cost's Welch segments of {settings.fft_length} samples; give at least "
            f"{2 * settings.fft_length / sample_rate:g} s.")


def _with_steps(settings, dt):
    """The settings with their steps: ``dt`` (given, or accuracy-driven), its note, and the
    PI search's ``stroke_dt`` (a new frozen plan; ``settings`` is not changed)."""
    rate = settings.controller_rate
    if dt is None:
        if rate > 0:  # a rate that shares no step with the output fails here, not after probes
            from qzs import defaults
            from qzs.engine.stability import stability_test
            from qzs.engine.step_choice import admissible_step

            stiffest = settings.controller_at(settings.controller.pi_kp, settings.damping_gain_max)
            admissible_step(settings.sample_rate, rate, stability_test(
                settings.isolator, stiffest, defaults.SIMULATION["solver"]))
        step, note = choose_dt(settings, settings.controller.pi_kp)
    else:
        step = real("dt", dt, minimum=0.0, strict=True, fix="in seconds, e.g. 0.001")
        note = "given"
    if rate > 0 and not divides(rate, step):
        raise ParameterError(f"`controller_rate` ({rate:g} Hz) must divide 1/dt "
                             f"({1 / step:g} Hz); choose e.g. {1 / step:g} Hz or "
                             "a whole fraction of it.")
    settings = dataclasses.replace(settings, dt=step, dt_note=note)
    return dataclasses.replace(settings, stroke_dt=step if dt is not None
                               else _stroke_step(settings))
