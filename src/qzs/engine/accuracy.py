"""Accuracy-driven step: the largest fixed step that meets a stated tolerance (docs/model.md §7).

The paper integrates at dt = 1e-4 s; its answer (the transmissibility over 1-20 Hz) is
met to a few thousandths of a decibel by a step ten times larger. :func:`choose_step`
finds the largest admissible step for a tolerance on what the user cares about, by
step halving on a short representative stretch of the excitation (the *probe*):

>>> from qzs import Chirp
>>> from qzs.engine.accuracy import choose_step
>>> choice = choose_step(Chirp(), tolerance=0.01)  # doctest: +SKIP
>>> choice.dt, choice.error  # doctest: +SKIP
(0.001, 0.0004...)
"""
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from qzs import _validation, defaults
from qzs._format import decibels
from qzs._validation import choice as _choice
from qzs.engine.step_choice import (ADMISSIBLE_REFINEMENT, RATE_REFINEMENT_MAX,  # noqa: F401
                                    ProbeSettings, admissible_step, spectral_beside_probes)
from qzs.engine.step_search import (MAX_HALVINGS, MEASURE_UNITS, SAFETY, StepChoice,
                                    halving_search)
from qzs.errors import ParameterError
from qzs.model.excitation import Chirp, RandomExcitation, Sine

__all__ = ["StepChoice", "choose_step", "probe_excitation", "step_error",
           "halving_search", "admissible_step", "estimate_difference_db", "excitation_over",
           "MEASURE_UNITS", "frequency_range", "check_band", "probe_fft_length",
           "probe_settings", "spectral_beside_probes", "SingleProbe", "shortened_chirp"]

#: Default length [s] of the probe of a chirp, a random excitation or a record.
PROBE_DURATION = 60.0
#: A chirp's probe sweeps this far beyond the band's top [-], so no bin of the band lies on
#: the sweep's end (on a short probe the last segment alone holds those bins: 0.009 dB there
#: against 0.001 dB inside the band at dt = 1 ms on a 60 s probe of the paper's chirp).
OVERSHOOT = 1.1
#: Welch segments the probe's transmissibility averages at least.
PROBE_SEGMENTS = 8


# ---------------------------------------------------------------- the probe
def frequency_range(excitation, sample_rate):
    """Lowest and highest frequency [Hz] the excitation holds.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The excitation.
    sample_rate : float
        Output rate [Hz]; a record's content is taken up to its Nyquist frequency.

    Returns
    -------
    tuple of float
        ``(low, high)`` [Hz].
    """
    if isinstance(excitation, Chirp):
        return min(excitation.f0, excitation.f1), max(excitation.f0, excitation.f1)
    if isinstance(excitation, Sine):
        return excitation.frequency, excitation.frequency
    if isinstance(excitation, RandomExcitation):
        return excitation.f_low, excitation.f_high
    return 0.0, min(excitation.max_frequency, 0.5 * sample_rate)


def probe_excitation(excitation, band, probe_duration=None):
    """The short stretch on which :func:`choose_step` compares steps.

    A step's error grows with the frequencies the payload sees, so the probe must hold
    every frequency of the band, in the amplitudes of the full run; a few seconds of a
    long sweep hold only one frequency. A chirp becomes a chirp of the same amplitude and
    law over the band, to 1.1 times its top (:data:`OVERSHOOT`: the top bins then lie
    inside the sweep, not on its end, where a short probe's last Welch segment alone
    holds them), from the excitation's start frequency when the band begins within a
    fifth of the span of it (a chirp from 0 Hz keeps its gentle start), else from 0.8
    times the band's low edge with a fade-in of two periods there. A
    sine, a random excitation and a record are stationary in their content: the probe is
    their first ``probe_duration`` seconds.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The full run's excitation.
    band : tuple of float
        Frequency band of interest [Hz], ``(low, high)``.
    probe_duration : float, optional
        Length of the probe [s]; default 60 s (a sine: its fade-in and 40 periods, at
        least 10 s), never longer than the excitation.

    Returns
    -------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The probe's excitation.
    duration : float
        The probe's length [s].
    """
    low, high = band
    if isinstance(excitation, Chirp):
        duration = min(excitation.duration, probe_duration or PROBE_DURATION)
        rising = excitation.f1 >= excitation.f0
        start, end = (excitation.f0, excitation.f1) if rising else (excitation.f1, excitation.f0)
        fade = excitation.fade_in
        top = OVERSHOOT * high
        if low - start > 0.2 * (top - start):
            start, fade = 0.8 * low, min(2.0 / (0.8 * low), 0.25 * duration)
        if excitation.method == "logarithmic":
            start = max(start, 1e-3)
        f0, f1 = (start, top) if rising else (top, start)
        return Chirp(amplitude=excitation.amplitude, f0=f0, f1=f1, duration=duration,
                     method=excitation.method, fade_in=min(fade, duration)), duration
    if isinstance(excitation, Sine):
        if probe_duration is None:
            period = 1.0 / excitation.frequency if excitation.frequency > 0 else 1.0
            probe_duration = excitation.fade_in + max(10.0, 40 * period)
        return excitation, float(probe_duration)
    duration = min(excitation.duration, probe_duration or PROBE_DURATION)
    return excitation, duration


def shortened_chirp(excitation, duration, sample_rate):
    """Whether a chirp's probe is shorter than the run: its state error is then measured on
    part of the sweep (a note says so; a probe as long as the chirp is no stand-in).

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The run's excitation.
    duration : float
        The probe's length [s] (whole output periods).
    sample_rate : float
        Output rate [Hz].

    Returns
    -------
    bool
    """
    return isinstance(excitation, Chirp) and duration < excitation.duration - 0.5 / sample_rate


def excitation_over(excitation, duration):
    """The excitation a run of ``duration`` seconds covers: what its step is chosen for.

    A run shorter than its chirp sees only the start of the sweep: the first 60 s of the
    paper's 0-20 Hz, 2000 s chirp hold 0-0.6 Hz. The chirp it covers is the same sweep law
    ended there (``f1`` the frequency reached at ``duration``, the same sweep rate), so the
    step search probes the band the run holds, not the whole sweep's. Every other excitation
    (a sine, a random excitation, a record, a run as long as its chirp or longer) is its own.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The run's excitation.
    duration : float or None
        The simulated time [s] (None: the excitation's length).

    Returns
    -------
    Chirp, Sine, RandomExcitation or DisplacementRecord
    """
    if (not isinstance(excitation, Chirp) or duration is None
            or duration >= excitation.duration):
        return excitation
    import dataclasses

    return dataclasses.replace(excitation, f1=float(excitation.frequency_at(duration)),
                               duration=float(duration),
                               fade_in=min(excitation.fade_in, float(duration)))


# ---------------------------------------------------------------- the measures
def probe_fft_length(n_samples, sample_rate, band, fft_length):
    """The Welch segment length [samples] of a probe's transmissibility.

    Parameters
    ----------
    n_samples : int
        The probe's output samples [-].
    sample_rate : float
        Output rate [Hz].
    band : tuple of float or None
        The measure's band [Hz] (unused: the length follows the probe).
    fft_length : int or None
        A length asked for [samples]; None: a power of two giving at least
        :data:`PROBE_SEGMENTS` half-overlapping segments, at most the paper's 32768.

    Returns
    -------
    int
    """
    if fft_length is not None:
        return int(fft_length)
    # a power of two with at least PROBE_SEGMENTS half-overlapping segments in the probe
    longest = 2 * n_samples / (PROBE_SEGMENTS + 1)
    length = 2 ** int(np.floor(np.log2(max(longest, 64))))
    return int(min(length, defaults.ANALYSIS["fft_length"]))


def step_error(coarse, fine, measure, *, band=None, fft_length=None):
    """The difference of two runs of one probe in a measure of accuracy.

    Parameters
    ----------
    coarse, fine : SimulationResult
        Two runs of the same excitation at the same output rate.
    measure : {"transmissibility_db", "state_m"}
        ``transmissibility_db``: max ``|20 log10(T_coarse/T_fine)|`` [dB] over the bins of
        ``band`` trusted in both estimates; ``state_m``: max ``|z_coarse - z_fine|`` [m]
        over the output samples.
    band : tuple of float, optional
        Band [Hz] of the transmissibility measure.
    fft_length : int, optional
        Welch segment length [samples]; default: a power of two giving at least 8
        half-overlapping segments (at most the paper's 32768).

    Returns
    -------
    float
        The difference, in [dB] or [m]; ``nan`` if no bin of the band is trusted in both.
    """
    _choice("measure", measure, tuple(MEASURE_UNITS))
    if measure == "state_m":
        return float(np.max(np.abs(coarse.relative_position - fine.relative_position)))

    rate = coarse.run["sample_rate"]
    length = probe_fft_length(coarse.relative_position.size, rate, band, fft_length)
    a, b = (_probe_transmissibility(run, rate, length) for run in (coarse, fine))
    return estimate_difference_db(a, b, band)


def estimate_difference_db(coarse, fine, band, keep=None):
    """The largest difference [dB] of two transmissibility estimates over a band.

    The measure of :func:`step_error` (and of the six-axis step,
    :func:`qzs.engine.hexapod.accuracy.choose_hexapod_step`): max ``|20 log10(|T_coarse| /
    |T_fine|)|`` over the bins of ``band`` above 0 Hz that both estimates trust and where
    both magnitudes are positive.

    Parameters
    ----------
    coarse, fine : TransferEstimate
        Two estimates on the same bins (:func:`qzs.analysis.spectral.transmissibility`).
    band : tuple of float
        ``(low, high)`` [Hz].
    keep : ndarray of bool, optional
        Bins the caller keeps besides (default all).

    Returns
    -------
    float
        The difference [dB]; ``nan`` if no bin of the band is trusted in both.
    """
    f = coarse.frequency
    keep = np.ones(f.shape, dtype=bool) if keep is None else np.asarray(keep, dtype=bool)
    keep = keep & (f > 0) & (f >= band[0]) & (f <= band[1]) & coarse.trusted & fine.trusted
    keep &= (coarse.magnitude > 0) & (fine.magnitude > 0)
    if not keep.any():
        return float("nan")
    return float(np.max(np.abs(decibels(coarse.magnitude[keep] / fine.magnitude[keep]))))


# ---------------------------------------------------------------- validation
def check_band(band, excitation, sample_rate):
    """The band [Hz] a transmissibility error is measured over, checked.

    Parameters
    ----------
    band : tuple of float or None
        ``(low, high)`` [Hz]; None: the excitation's frequencies (a chirp from 0 Hz: from
        1 Hz, or half its top if lower).
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The excitation the band must lie in.
    sample_rate : float
        Output rate [Hz]; the band must lie below its Nyquist frequency.

    Returns
    -------
    tuple of float
        ``(low, high)`` [Hz].

    Raises
    ------
    ParameterError
        Not two finite frequencies with ``0 <= low <= high``, above the Nyquist frequency,
        or outside the excitation's frequencies.
    """
    lowest, highest = frequency_range(excitation, sample_rate)
    if band is None:
        low, high = lowest, highest
        if isinstance(excitation, Chirp) and low == 0.0:
            low = min(1.0, 0.5 * high)  # the paper's band starts at 1 Hz: below, trust is thin
        return (float(low), float(high))
    try:
        low, high = (float(x) for x in band)
    except (TypeError, ValueError):
        raise ParameterError(f"`band` must be two frequencies (low, high) in Hz, got {band!r}.")
    if not (np.isfinite(low) and np.isfinite(high) and 0 <= low <= high):
        raise ParameterError(f"`band` must satisfy 0 <= low <= high (finite, Hz), got {band!r}.")
    nyquist = 0.5 * sample_rate
    if high > nyquist:
        raise ParameterError(f"`band` ({low:g}, {high:g}) Hz reaches above the output's Nyquist "
                             f"frequency {nyquist:g} Hz; raise `sample_rate` or lower the band.")
    slack = 1e-9 * max(highest, 1.0)
    if low < lowest - slack or high > highest + slack:
        raise ParameterError(
            f"`band` ({low:g}, {high:g}) Hz lies outside the excitation's frequencies "
            f"[{lowest:g}, {highest:g}] Hz: nothing there is excited; choose a band inside it.")
    return (low, high)


@dataclass(frozen=True, kw_only=True)
class SingleProbe(ProbeSettings):
    """The probe of one axis: the inputs of :func:`choose_step` but the tolerance; nothing
    computed until :meth:`build`, which :func:`qzs.engine.step_choice.choose` calls only for
    a chosen step.

    Attributes
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord or None
        The run's excitation (None: the paper's chirp).
    isolator : IsolatorParameters or None
        Plant parameters (None: Table 1's).
    controller : ControllerParameters or None
        PI and damping loops (None: the defaults).
    solver : str
        The integrator.
    sample_rate : float
        Output rate [Hz] of the run the step is for.
    band : tuple of float or None
        Band [Hz] of the transmissibility measure (None: the excitation's).
    probe_duration : float or None
        Length of the probe [s] (None: the default).
    fft_length : int or None
        Welch segment length [samples] of the probe's transmissibility.
    initial_state : InitialState or None
        As for :func:`qzs.simulate`.
    max_halvings : int
        Halvings of the admissible start tried at most [-].
    safety : float
        Factor [-] between the estimate and the tolerance.
    """

    isolator: Any = None
    controller: Any = None
    fft_length: int | None = None
    initial_state: Any = None

    def _build(self, measure):
        from qzs.engine.prepare import run_inputs
        from qzs.engine.step_choice import Probe

        excitation, isolator, controller = run_inputs(self.excitation, self.isolator,
                                                      self.controller)
        order, sample_rate, band, probe, duration = probe_settings(
            excitation, measure, self.solver, self.sample_rate, self.band, self.probe_duration,
            self.fft_length, self.safety, self.max_halvings)
        solver, initial_state, fft_length = self.solver, self.initial_state, self.fft_length

        def run(dt, cases):
            from qzs.engine.single import integrate

            return [integrate(probe, isolator, controller, duration=duration, dt=dt,
                              sample_rate=sample_rate, solver=solver,
                              initial_state=initial_state)]

        return Probe(
            measure=measure, order=order, sample_rate=sample_rate, solver=solver,
            excitation=probe, duration=duration, band=band,
            shortened=shortened_chirp(excitation, duration, sample_rate),
            start=lambda: _single_start(probe, duration, isolator, controller, solver,
                                        sample_rate),
            run=run, compare=lambda coarse, fine: step_error(coarse, fine, measure, band=band,
                                                             fft_length=fft_length),
            key=dict(excitation=excitation, isolator=isolator, controller=controller,
                     initial_state=initial_state, solver=solver, sample_rate=sample_rate,
                     band=band, probe_duration=self.probe_duration, fft_length=fft_length),
            max_halvings=self.max_halvings, safety=self.safety)


def _single_start(probe, duration, isolator, controller, solver, sample_rate):
    """One axis's stability limit, resolving step and admissible start (``Probe.start``)."""
    from qzs.engine.prepare import check_resolution, divides, resolving_step
    from qzs.engine.stability import largest_stable_step, stability_test

    stable = stability_test(isolator, controller, solver)
    limit = largest_stable_step(isolator, controller, solver)
    resolving = resolving_step(probe, duration)  # the step must follow the base motion too
    # no candidate below 1/(sample_rate * ADMISSIBLE_REFINEMENT): an excitation only a finer
    # step follows is refused as a literal step too coarse for it would be, naming it
    check_resolution(probe, 1.0 / (sample_rate * ADMISSIBLE_REFINEMENT), duration)
    rates = controller.sample_rates  # each sampled period a whole number of steps
    single = rates[0] if len(rates) == 1 else 0.0
    dt0, k0 = admissible_step(sample_rate, single,
                              lambda dt: dt <= resolving and stable(dt)
                              and (single or all(divides(rate, dt) for rate in rates)))
    return limit, resolving, dt0, k0


def choose_step(excitation=None, isolator=None, controller=None, *, tolerance=None,
                tolerance_state=None, solver=defaults.SIMULATION["solver"],
                sample_rate=defaults.SIMULATION["sample_rate"], band=None, probe_duration=None,
                fft_length=None, initial_state=None, max_halvings=MAX_HALVINGS,
                safety=SAFETY, finest=None, fallback=False, progress=False, cache=False,
                tolerance_db=None):
    """The largest fixed step whose error stays within a tolerance (docs/model.md §7).

    Candidates are ``dt_j = dt_0 / 2**j`` with ``dt_0 = 1/(sample_rate*k)`` the largest
    step that is linearly stable (:func:`~qzs.engine.stability.largest_stable_step`) and
    divides the output period (and a sampled controller's). Each is integrated on the
    probe (:func:`probe_excitation`) and compared with the next finer one: the difference
    ``d_j`` is measured, and the observed ratio ``r_j = d_j/d_{j+1}`` (``2**order`` in the
    asymptotic range; stick-slip events lower it), capped at the scheme's ``2**order``,
    extrapolates the error of ``dt_j`` Richardson-style: ``d_j * r_j/(r_j - 1)``. Where the
    differences do not shrink (``r_j <= 1``) there is no estimate. The chosen step is the
    coarsest whose estimate times ``safety`` meets the tolerance. The one call
    :func:`qzs.engine.step_choice.choose` on a :class:`SingleProbe`.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        The full run's excitation; default the paper's chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    tolerance : float, optional
        Tolerance on the transmissibility [dB]: max ``|20 log10(T_dt/T_ref)|`` over the
        trusted bins of ``band``.
    tolerance_state : float, optional
        Tolerance on the state [m]: max ``|z_dt - z_ref|`` of the relative position over
        the output samples. Give exactly one of the two tolerances.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    sample_rate : float
        Output rate [Hz] of the run the step is for; the step divides its period.
    band : tuple of float, optional
        Band of interest [Hz]; default the excitation's frequencies (a chirp from 0 Hz:
        from 1 Hz). Must lie inside them and below the Nyquist frequency.
    probe_duration : float, optional
        Length of the probe [s] (see :func:`probe_excitation`).
    fft_length : int, optional
        Welch segment length [samples] of the probe's transmissibility; default a power
        of two giving at least 8 half-overlapping segments.
    initial_state : InitialState, optional
        As for :func:`qzs.simulate`.
    max_halvings : int
        Halvings of ``dt_0`` tried at most [-]; if none meets the tolerance,
        :class:`~qzs.errors.ParameterError`.
    safety : float
        Factor [-] (>= 1) between the estimate and the tolerance; default 2: the probe's
        Welch bins are coarser than a long run's, and the maximum over the finer bins of
        the paper's 2000 s run was 1.9 times the probe's (docs/model.md §7).
    finest : float, optional
        The finest candidate [s]: halvings stop above it; the fallback step too.
    fallback : bool
        Where no candidate meets the tolerance (or no bin of the band is trusted on the
        probe), return the one fallback (:mod:`qzs.engine.step_choice`: ``finest``, default
        the paper's step; ``met`` False, ``error`` NaN, the unmet sentence) instead of
        raising: what a run that must go on asks for.
    progress : bool
        Show a progress bar over the probe runs.
    cache : bool
        Read the choice from, and keep it in, the step cache on disk
        (:mod:`qzs.engine.step_cache`, keyed by every input above and by the code that
        chooses): a repeated command skips the probe. The command line uses it.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    StepChoice

    Raises
    ------
    ParameterError
        Both or neither tolerance, a non-positive one, a band outside the excitation, no
        trusted bin in the band on the probe, or a tolerance no candidate meets.
    """
    from qzs.engine.step_choice import choose, step_request

    request = step_request(tolerance=tolerance, tolerance_state=tolerance_state,
                           tolerance_db=tolerance_db, required=True)
    return choose(request, SingleProbe(
        excitation=excitation, isolator=isolator, controller=controller, solver=solver,
        sample_rate=sample_rate, band=band,
        probe_duration=probe_duration, fft_length=fft_length, initial_state=initial_state,
        max_halvings=max_halvings, safety=safety),
        fallback=fallback, finest=finest, progress=progress, cache=cache)


# ---------------------------------------------------------------- shared by the searches

def probe_settings(excitation, measure, solver, sample_rate, band, probe_duration, fft_length,
                   safety, max_halvings):
    """Check a step search's settings and make its probe.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The run's excitation.
    measure : {"transmissibility_db", "state_m"}
        The accuracy measure.
    solver : str
        The integrator.
    sample_rate : float
        Output rate [Hz].
    band : tuple of float or None
        The transmissibility measure's band [Hz] (:func:`check_band`).
    probe_duration : float or None
        The probe's length [s] (:func:`probe_excitation`).
    fft_length : int or None
        Welch segment length [samples].
    safety : float
        Factor [-] (>= 1) between the estimate and the tolerance.
    max_halvings : int
        Halvings tried at most [-] (>= 2).

    Returns
    -------
    order : int
        The scheme's order [-].
    sample_rate : float
        Output rate [Hz].
    band : tuple of float or None
        The checked band [Hz] (None for the state measure).
    probe : object
        The probe's excitation.
    duration : float
        The probe's length [s], a whole number of output periods.
    """
    from qzs.engine.stability import SOLVERS

    _, order = SOLVERS[_choice("solver", solver, tuple(SOLVERS))]
    sample_rate = _validation.positive_real("sample_rate", sample_rate)
    if probe_duration is not None:
        _validation.positive_real("probe_duration", probe_duration)
    _validation.real("safety", safety, minimum=1.0)
    _validation.integer("max_halvings", max_halvings, 2)
    band = check_band(band, excitation, sample_rate) if measure == "transmissibility_db" else None
    probe, duration = probe_excitation(
        excitation, band or frequency_range(excitation, sample_rate), probe_duration)
    # a whole number of output periods: every candidate step then records the same samples
    # (a sine's probe of 40 periods need not be; its runs at dt and dt/2 differed by one)
    duration = math.floor(duration * sample_rate * (1 + 1e-12)) / sample_rate
    if duration <= 0:
        raise ParameterError(f"the probe ({duration:g} s) holds no output sample at "
                             f"`sample_rate` {sample_rate:g} Hz; lengthen `probe_duration`.")
    if fft_length is not None and measure == "transmissibility_db":
        n = int(round(duration * sample_rate)) + 1
        if (isinstance(fft_length, bool) or not isinstance(fft_length, (int, np.integer))
                or not 8 <= fft_length <= n):
            raise ParameterError(f"`fft_length` must be an integer in [8, {n}] (the probe's "
                                 f"samples), got {fft_length!r}.")
    return order, sample_rate, band, probe, duration


def _probe_transmissibility(run, rate, fft_length):
    """A probe run's transmissibility estimate; a batch probe's run keeps it (each run is
    the fine one of one comparison and the coarse one of the next)."""
    from qzs.analysis.spectral import transmissibility

    cache = getattr(run, "estimates", None)
    if cache is not None and fft_length in cache:
        return cache[fft_length]
    estimate = transmissibility(run.base_acceleration, run.payload_acceleration, rate,
                                fft_length=fft_length)
    if cache is not None:
        cache[fft_length] = estimate
    return estimate
