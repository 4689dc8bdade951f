"""Accuracy-driven step: the largest fixed step that meets a stated tolerance (docs/model.md §7).

The paper integrates at dt = 1e-4 s; its answer (the transmissibility over 1-20 Hz) is
met to a few thousandths of a decibel by a step ten times larger. :func:`choose_step`
finds the largest admissible step for a tolerance on what the user cares about, by
step halving on a short representative stretch of the excitation (the *probe*):

>>> from qzs import Chirp
>>> from qzs.engine.accuracy import choose_step
>>> choice = choose_step(Chirp(), tolerance_db=0.01)  # doctest: +SKIP
>>> choice.dt, choice.error  # doctest: +SKIP
(0.001, 0.0004...)
"""
import math
from dataclasses import dataclass, field

import numpy as np

from qzs import _validation, defaults
from qzs._format import decibels
from qzs._lazy import import_in_background
from qzs._validation import choice as _choice
from qzs.errors import ControllerRateError, ParameterError, ToleranceNotMetError
from qzs.model.excitation import Chirp, RandomExcitation, Sine

__all__ = ["StepChoice", "choose_step", "choose_step_or_finest", "default_tolerance",
           "probe_excitation", "step_error", "halving_search", "admissible_step",
           "step_run_entries", "estimate_difference_db", "MEASURE_UNITS"]

#: Default length [s] of the probe of a chirp, a random excitation or a record.
PROBE_DURATION = 60.0
#: Halvings below the largest admissible step tried at most before giving up.
MAX_HALVINGS = 8
#: A chirp's probe sweeps this far beyond the band's top [-], so no bin of the band lies on
#: the sweep's end (on a short probe the last segment alone holds those bins: 0.009 dB there
#: against 0.001 dB inside the band at dt = 1 ms on a 60 s probe of the paper's chirp).
OVERSHOOT = 1.1
#: Factor between the estimated error and the tolerance (see :func:`choose_step`).
SAFETY = 2.0
#: Welch segments the probe's transmissibility averages at least.
PROBE_SEGMENTS = 8
#: A sampled controller may make the step at most this much finer than the largest stable
#: one [-]: its period and the output's must both be whole numbers of steps, and a rate
#: such as 333 Hz against a 1000 Hz output meets that only at 1/333000 s, a run hundreds
#: of times longer (:class:`~qzs.errors.ControllerRateError`).
RATE_REFINEMENT_MAX = 32
#: The measures of a step's accuracy and their units: the transmissibility [dB], the state [m].
MEASURE_UNITS = {"transmissibility_db": "dB", "state_m": "m"}
#: Steps per output sample a candidate takes at most [-] (:func:`admissible_step`).
ADMISSIBLE_REFINEMENT = 1_000_000


@dataclass(frozen=True)
class StepChoice:
    """The outcome of :func:`choose_step`.

    Attributes
    ----------
    dt : float
        The chosen integration step [s]: the largest candidate meeting the tolerance.
    error : float
        Estimated error of a run at ``dt`` in the requested measure ([dB] or [m]).
    measure : str
        ``"transmissibility_db"`` (max ``|20 log10(T_dt/T_ref)|`` over the trusted bins of
        ``band``) or ``"state_m"`` (max ``|z_dt - z_ref|`` over the output samples).
    tolerance : float
        The tolerance asked for, in the unit of ``measure``.
    reference_dt : float
        The finest step integrated on the probe [s] (the estimate's reference).
    stability_limit : float
        The solver's largest stable step for this model [s].
    sample_rate : float
        Output rate [Hz]; ``dt`` divides its period.
    solver : str
        The integrator.
    probe : object
        The excitation integrated to choose the step.
    probe_duration : float
        Length of the probe [s].
    band : tuple of float
        Frequency band [Hz] of the transmissibility measure (None for the state).
    history : tuple
        ``(dt, difference to the next finer step, estimated error)`` per step tried,
        coarsest first; the difference and estimate are in the unit of ``measure``.
    notes : tuple of str
        What the caller should know (the limit that bound the step, caveats).
    met : bool
        Whether ``dt`` meets the tolerance; False only for the fallback of
        :func:`choose_step_or_finest` (``error`` is then NaN: no estimate holds for it).
    cached : bool
        Whether the choice was read from the step cache (:mod:`qzs.engine.step_cache`).
    """

    dt: float
    error: float
    measure: str
    tolerance: float
    reference_dt: float
    stability_limit: float
    sample_rate: float
    solver: str
    probe: object
    probe_duration: float
    band: tuple
    history: tuple
    notes: tuple
    met: bool = True
    cached: bool = False

    @property
    def steps_per_sample(self):
        """Integration steps per output sample [-]."""
        return int(round(1.0 / (self.sample_rate * self.dt)))

    def summary(self):
        """One paragraph for people: the step, its error and why.

        Returns
        -------
        str
        """
        unit = MEASURE_UNITS[self.measure]
        if not self.met:
            return "\n".join([f"dt = {self.dt:.6g} s ({self.solver}): no step tried meets the "
                              f"tolerance {self.tolerance:g} {unit}"]
                             + [f"  note: {note}" for note in self.notes])
        lines = [f"dt = {self.dt:.6g} s ({self.solver}, {self.steps_per_sample} step(s) per "
                 f"{self.sample_rate:g} Hz sample): estimated error {self.error:.3g} {unit} "
                 f"(tolerance {self.tolerance:g} {unit}, reference dt = {self.reference_dt:.3g} s, "
                 f"probe {self.probe_duration:g} s, stability limit {self.stability_limit:.3g} s)"]
        lines += [f"  note: {note}" for note in self.notes]
        return "\n".join(lines)


# ---------------------------------------------------------------- the probe
def _frequency_range(excitation, sample_rate):
    """Lowest and highest frequency [Hz] the excitation holds."""
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


# ---------------------------------------------------------------- the measures
def _probe_fft_length(n_samples, sample_rate, band, fft_length):
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
    length = _probe_fft_length(coarse.relative_position.size, rate, band, fft_length)
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
def _tolerance(tolerance_db, tolerance_state):
    given = [(name, value) for name, value in (("tolerance_db", tolerance_db),
                                               ("tolerance_state", tolerance_state))
             if value is not None]
    if len(given) != 1:
        raise ParameterError(
            "give exactly one of `tolerance_db` (transmissibility, dB) and `tolerance_state` "
            f"(relative position, m); got {' and '.join(n for n, _ in given) or 'neither'}.")
    name, value = given[0]
    measure = "transmissibility_db" if name == "tolerance_db" else "state_m"
    return measure, _validation.positive_real(name, value)


def _band(band, excitation, sample_rate):
    lowest, highest = _frequency_range(excitation, sample_rate)
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


def admissible_step(sample_rate, controller_rate, stable):
    """The largest admissible step: ``1/(sample_rate*k)``, smallest k that is stable and
    divides the controller's period too.

    Parameters
    ----------
    sample_rate : float
        Output rate [Hz]; the step divides its period.
    controller_rate : float
        A sampled controller's rate [Hz] (0: continuous); the step divides its period too.
    stable : callable
        ``stable(dt)``: whether the step ``dt`` [s] is linearly stable.

    Returns
    -------
    dt : float
        The step [s].
    k : int
        Steps per output sample [-].

    Raises
    ------
    ControllerRateError
        The controller's period is a whole number of steps only at a step more than
        :data:`RATE_REFINEMENT_MAX` times finer than the stable one (before any run).
    """
    from qzs.engine.prepare import steps_per_sample

    first = next((k for k in range(1, ADMISSIBLE_REFINEMENT)
                  if stable(1.0 / (sample_rate * k))), None)
    if first is None:
        raise ParameterError(f"no step 1/(sample_rate*k) with k < {ADMISSIBLE_REFINEMENT:.0e} "
                             "is stable; check the model's stiffness and the `sample_rate`.")
    if controller_rate <= 0:
        return 1.0 / (sample_rate * first), first
    for k in range(first, RATE_REFINEMENT_MAX * first + 1):
        dt = 1.0 / (sample_rate * k)
        if not stable(dt):
            continue
        try:
            steps_per_sample(controller_rate, dt, "controller_rate")
        except ParameterError:
            continue
        return dt, k
    multiples = [sample_rate * n for n in range(1, 9)] + [sample_rate / n for n in range(2, 9)]
    near = sorted(multiples, key=lambda f: abs(f - controller_rate))[:2]
    raise ControllerRateError(controller_rate=controller_rate, sample_rate=sample_rate,
                              step=1.0 / (sample_rate * first), refinement=RATE_REFINEMENT_MAX,
                              suggestions=sorted(near))


# ---------------------------------------------------------------- the search
def halving_search(difference, order, tolerance, dt0, max_halvings, safety=SAFETY):
    """Richardson-style search over ``dt_j = dt0 / 2**j``: the coarsest step that meets a
    tolerance (the method of :func:`choose_step`, for any model and any measure).

    Parameters
    ----------
    difference : callable
        ``difference(j)``: the measured difference between the runs at ``dt_j`` and
        ``dt_{j+1}`` (in the tolerance's unit; NaN: no measure, the search stops).
    order : int
        The scheme's order of accuracy [-]; the observed ratio ``d_j/d_{j+1}`` is capped at
        ``2**order``.
    tolerance : float
        What the error estimate times ``safety`` must not exceed (its unit).
    dt0 : float
        The coarsest candidate [s].
    max_halvings : int
        Candidates ``dt_0 .. dt_{max_halvings}`` [-].
    safety : float
        Factor [-] between the estimate and the tolerance.

    Returns
    -------
    chosen : int or None
        ``j`` of the chosen step, None if no candidate met the tolerance.
    history : list of tuple
        ``(dt_j [s], d_j, estimate_j)`` per candidate compared; the estimate is
        ``d_j r/(r - 1)``, 0 where ``d_j = 0`` and inf where the differences do not shrink.
    """
    history = []
    for j in range(max_halvings - 1):
        d, d_next = difference(j), difference(j + 1)
        if not (np.isfinite(d) and np.isfinite(d_next)):
            break
        estimate = _estimate(d, d_next, order)
        history.append((dt0 / 2 ** j, d, estimate))
        if safety * estimate <= tolerance:
            return j, history
    return None, history


def choose_step(excitation=None, isolator=None, controller=None, *, tolerance_db=None,
                tolerance_state=None, solver=defaults.SIMULATION["solver"],
                sample_rate=defaults.SIMULATION["sample_rate"], band=None, probe_duration=None,
                fft_length=None, initial_state=None, max_halvings=MAX_HALVINGS,
                safety=SAFETY, progress=False, cache=False):
    """The largest fixed step whose error stays within a tolerance (docs/model.md §7).

    Candidates are ``dt_j = dt_0 / 2**j`` with ``dt_0 = 1/(sample_rate*k)`` the largest
    step that is linearly stable (:func:`~qzs.engine.stability.largest_stable_step`) and
    divides the output period (and a sampled controller's). Each is integrated on the
    probe (:func:`probe_excitation`) and compared with the next finer one: the difference
    ``d_j`` is measured, and the observed ratio ``r_j = d_j/d_{j+1}`` (``2**order`` in the
    asymptotic range; stick-slip events lower it), capped at the scheme's ``2**order``,
    extrapolates the error of ``dt_j`` Richardson-style: ``d_j * r_j/(r_j - 1)``. Where the
    differences do not shrink (``r_j <= 1``) there is no estimate. The chosen step is the
    coarsest whose estimate times ``safety`` meets the tolerance.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        The full run's excitation; default the paper's chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    tolerance_db : float, optional
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
    progress : bool
        Show a progress bar over the probe runs.
    cache : bool
        Read the choice from, and keep it in, the step cache on disk
        (:mod:`qzs.engine.step_cache`, keyed by every input above and by the code that
        chooses): a repeated command skips the probe. The command line uses it.

    Returns
    -------
    StepChoice

    Raises
    ------
    ParameterError
        Both or neither tolerance, a non-positive one, a band outside the excitation, no
        trusted bin in the band on the probe, or a tolerance no candidate meets.
    """
    from qzs.engine.prepare import check_resolution, resolving_step, run_inputs
    from qzs.engine.simulate import simulate
    from qzs.engine.stability import largest_stable_step, stability_test

    measure, tolerance = _tolerance(tolerance_db, tolerance_state)
    excitation, isolator, controller = run_inputs(excitation, isolator, controller)
    order, sample_rate, band, probe, duration = _probe_settings(
        excitation, measure, solver, sample_rate, band, probe_duration, fft_length, safety,
        max_halvings)

    key = None
    if cache:
        from qzs.engine import step_cache

        key = step_cache.cache_key(
            excitation=excitation, isolator=isolator, controller=controller,
            initial_state=initial_state, measure=measure, tolerance=tolerance, solver=solver,
            sample_rate=sample_rate, band=band, probe_duration=probe_duration,
            fft_length=fft_length, max_halvings=max_halvings, safety=safety)
        hit = _from_record(step_cache.load(key), probe, duration)
        if hit is not None:
            return hit
    if measure == "transmissibility_db":
        # the spectral analysis (scipy.signal: about 0.5 s to import) loads in a thread
        # while the probe's first runs integrate, in a kernel that holds no GIL
        import_in_background("qzs.analysis.spectral")

    stable = stability_test(isolator, controller, solver)
    limit = largest_stable_step(isolator, controller, solver)
    resolving = resolving_step(probe, duration)  # the step must follow the base motion too
    # no candidate below 1/(sample_rate * ADMISSIBLE_REFINEMENT): an excitation only a finer
    # step follows is refused as a literal step too coarse for it would be, naming it
    check_resolution(probe, 1.0 / (sample_rate * ADMISSIBLE_REFINEMENT), duration)
    dt0, k0 = admissible_step(sample_rate, controller.controller_rate,
                              lambda dt: dt <= resolving and stable(dt))
    notes = _bound_notes(dt0, k0, sample_rate, limit, resolving, measure,
                         probe is not excitation)

    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=max_halvings + 1, unit="run", desc="choosing dt", leave=False)
    runs = {}

    def run(j):
        if j not in runs:
            runs[j] = simulate(probe, isolator, controller, duration=duration, dt=dt0 / 2 ** j,
                               sample_rate=sample_rate, solver=solver,
                               initial_state=initial_state)
            if bar is not None:
                bar.update(1)
        return runs[j]

    differences = {}

    def difference(j):
        if j not in differences:
            differences[j] = step_error(run(j), run(j + 1), measure, band=band,
                                        fft_length=fft_length)
            if measure == "transmissibility_db" and np.isnan(differences[j]):
                raise ParameterError(
                    f"no bin of the band ({band[0]:g}, {band[1]:g}) Hz is trusted on the "
                    f"{duration:g} s probe; lengthen `probe_duration` or narrow the band.")
        return differences[j]

    try:
        chosen, history = halving_search(difference, order, tolerance, dt0, max_halvings,
                                         safety)
    finally:
        if bar is not None:
            bar.close()
    if chosen is None:
        raise ToleranceNotMetError(tolerance, MEASURE_UNITS[measure], dt0 / 2 ** (max_halvings - 1),
                                   min(h[2] for h in history), safety)
    j = chosen
    notes += _order_notes(differences[j], differences[j + 1], order)
    choice = StepChoice(dt=dt0 / 2 ** j, error=float(history[-1][2]), measure=measure,
                        tolerance=tolerance, reference_dt=dt0 / 2 ** (j + 2),
                        stability_limit=float(limit), sample_rate=sample_rate, solver=solver,
                        probe=probe, probe_duration=float(duration), band=band,
                        history=tuple(history), notes=tuple(notes))
    if key is not None:
        from qzs.engine import step_cache

        step_cache.store(key, _to_record(choice))
    return choice


#: The fields of a :class:`StepChoice` a cache record keeps (the probe is made again).
_RECORD_FIELDS = ("dt", "error", "measure", "tolerance", "reference_dt", "stability_limit",
                  "sample_rate", "solver", "probe_duration", "band", "history", "notes")


def _to_record(choice):
    """A :class:`StepChoice` as the JSON-able record of the step cache."""
    return {name: getattr(choice, name) for name in _RECORD_FIELDS}


def _from_record(record, probe, duration):
    """The :class:`StepChoice` of a cache record (None for none or a damaged one)."""
    if record is None:
        return None
    try:
        values = {name: record[name] for name in _RECORD_FIELDS}
        band = values["band"]
        values.update(band=None if band is None else (float(band[0]), float(band[1])),
                      history=tuple(tuple(float(x) for x in row) for row in values["history"]),
                      notes=tuple(str(note) for note in values["notes"]))
        choice = StepChoice(probe=probe, cached=True, **values)
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    if not (isinstance(choice.dt, float) and choice.dt > 0 and choice.measure in MEASURE_UNITS
            and math.isclose(choice.probe_duration, duration)):
        return None
    return choice


def default_tolerance(excitation):
    """The accuracy a command asks for when given no step and no tolerance.

    The transmissibility within ``defaults.ACCURACY["tolerance_db"]`` where the excitation
    has a band to estimate it over (a chirp, a random excitation, a record); a sine has one
    frequency and no Welch estimate, so its relative position within
    ``defaults.ACCURACY["tolerance_state"]``.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The run's excitation.

    Returns
    -------
    dict
        One keyword of :func:`choose_step`: ``{"tolerance_db": ...}`` [dB] or
        ``{"tolerance_state": ...}`` [m].
    """
    if isinstance(excitation, Sine):
        return {"tolerance_state": float(defaults.ACCURACY["tolerance_state"])}
    return {"tolerance_db": float(defaults.ACCURACY["tolerance_db"])}


def choose_step_or_finest(excitation=None, isolator=None, controller=None, **options):
    """:func:`choose_step`, or, where no step tried meets the tolerance, a fallback that says so.

    Stick-slip and stop contacts can redraw a response at every step, so that the
    differences between steps stop shrinking; a command must still run. The fallback is
    the finer of the paper's step (``defaults.SIMULATION["dt"]``) and the finest step
    tried, with ``met`` False, ``error`` NaN (no estimate holds for it) and a note giving
    the smallest estimate found.

    Parameters
    ----------
    excitation, isolator, controller
        As for :func:`choose_step`.
    **options
        Every keyword of :func:`choose_step`.

    Returns
    -------
    StepChoice
    """
    try:
        return choose_step(excitation, isolator, controller, **options)
    except ToleranceNotMetError as error:
        from qzs.engine.prepare import run_inputs

        excitation = run_inputs(excitation, isolator, controller)[0]
        measure, tolerance = _tolerance(options.get("tolerance_db"),
                                        options.get("tolerance_state"))
        solver = options.get("solver", defaults.SIMULATION["solver"])
        _, sample_rate, band, probe, duration = _probe_settings(
            excitation, measure, solver,
            options.get("sample_rate", defaults.SIMULATION["sample_rate"]), options.get("band"),
            options.get("probe_duration"), options.get("fft_length"),
            options.get("safety", SAFETY), options.get("max_halvings", MAX_HALVINGS))
        dt = min(defaults.SIMULATION["dt"], error.smallest_step)
        note = (f"no step down to {error.smallest_step:.3g} s met {tolerance:g} {error.unit} "
                f"(smallest estimate {error.smallest_error:.3g} {error.unit}: stick-slip or stop "
                f"contacts redraw the response at every step); running at dt = {dt:.3g} s, "
                "whose error is not estimated")
        return StepChoice(dt=dt, error=math.nan, measure=measure, tolerance=tolerance,
                          reference_dt=error.smallest_step, stability_limit=math.nan,
                          sample_rate=sample_rate, solver=solver, probe=probe,
                          probe_duration=float(duration), band=band, history=(),
                          notes=(note,), met=False)


def step_run_entries(choice):
    """What a run records of its chosen step: tolerance and estimated error, in units.

    Parameters
    ----------
    choice : StepChoice
        The step the run was made at.

    Returns
    -------
    dict
        ``step_tolerance_db`` and ``step_error_db`` [dB] (or ``_m`` [m] for the state
        measure; the error NaN where no step met the tolerance), for
        :attr:`SimulationResult.run <qzs.engine.result.SimulationResult.run>` and the
        file's ``run.*`` attributes.
    """
    suffix = MEASURE_UNITS[choice.measure].lower()
    return {f"step_tolerance_{suffix}": float(choice.tolerance),
            f"step_error_{suffix}": float(choice.error)}


# ---------------------------------------------------------------- shared by the searches

def _estimate(d, d_next, order):
    """The Richardson estimate of the error of ``dt_j`` from ``d_j`` and ``d_{j+1}``
    (:func:`halving_search`): 0 where ``d_j = 0``, inf where the differences do not shrink."""
    ratio = d / d_next if d_next > 0 else math.inf
    if d == 0.0:
        return 0.0
    if ratio <= 1.0:  # not converging yet: no estimate
        return math.inf
    r = min(ratio, 2.0 ** order)
    return d * r / (r - 1)


def _probe_settings(excitation, measure, solver, sample_rate, band, probe_duration, fft_length,
                    safety, max_halvings):
    """Check a step search's settings; ``(order, sample_rate, band, probe, probe duration)``."""
    from qzs.engine.stability import SOLVERS

    _, order = SOLVERS[_choice("solver", solver, tuple(SOLVERS))]
    sample_rate = _validation.positive_real("sample_rate", sample_rate)
    if probe_duration is not None:
        _validation.positive_real("probe_duration", probe_duration)
    _validation.real("safety", safety, minimum=1.0)
    _validation.integer("max_halvings", max_halvings, 2)
    band = _band(band, excitation, sample_rate) if measure == "transmissibility_db" else None
    probe, duration = probe_excitation(
        excitation, band or _frequency_range(excitation, sample_rate), probe_duration)
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


def _bound_notes(dt0, k0, sample_rate, limit, resolving, measure, shortened):
    """What bounds the coarsest candidate ``dt0 = 1/(sample_rate*k0)`` [s], for people."""
    from qzs.engine.prepare import MIN_STEPS_PER_PERIOD

    notes = []
    if k0 == 1:
        notes.append(f"the output rate bounds the step: dt_0 = 1/sample_rate = {dt0:.3g} s "
                     f"(a lower sample_rate would allow larger steps; stability allows "
                     f"{limit:.3g} s)")
    elif resolving < limit:
        notes.append(f"the base motion bounds the step: dt_0 = 1/({sample_rate:g}*{k0}) = "
                     f"{dt0:.3g} s <= {resolving:.3g} s, {MIN_STEPS_PER_PERIOD} steps per period "
                     f"of its highest frequency (stability allows {limit:.3g} s)")
    else:
        notes.append(f"stability bounds the step: dt_0 = 1/({sample_rate:g}*{k0}) = {dt0:.3g} s "
                     f"<= {limit:.3g} s")
    if measure == "state_m" and shortened:
        notes.append("the state error is measured on a shortened chirp; on the full sweep "
                     "phase errors accumulate over a longer time")
    return notes


def _order_notes(d, d_next, order):
    """A note when the observed order of the chosen step lies below the scheme's."""
    if d > 0 and d_next > 0:
        observed = math.log2(d / d_next)
        if observed < order - 0.5:
            return [f"observed order {observed:.2f} below the scheme's {order} (stick-slip "
                    "events lower it): the estimate extrapolates with the observed ratio"]
    return []


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
