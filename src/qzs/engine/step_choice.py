"""Step choice as one call: what is asked (:class:`StepRequest`), of what (:class:`Probe`), by
:func:`choose` (docs/model.md §7).

Every step of qzs that is not given literally is chosen here: a request (a literal ``dt``
[s], a ``tolerance`` on the transmissibility [dB] or on the state [m], or the default of
:data:`qzs.defaults.ACCURACY`) and a probe of a model (one axis,
:class:`qzs.engine.accuracy.SingleProbe`; lanes of a lockstep batch,
:class:`qzs.engine.accuracy_batch.BatchProbe`; the six legs,
:class:`qzs.engine.hexapod.accuracy.HexapodProbe`) go to :func:`choose`, which owns the
step cache (:mod:`qzs.engine.step_cache`), the one search
(:func:`qzs.engine.step_search.search_step`), the one fallback step (:func:`fallback_step`)
and the one meaning of an unmet tolerance (:func:`unmet_sentence`, shown by every caller as
:attr:`~qzs.engine.step_search.StepChoice.unmet_note`); those two are written beside the
record, in :mod:`qzs.engine.step_search`, and read here.

>>> from qzs import Chirp
>>> from qzs.engine.accuracy import SingleProbe
>>> from qzs.engine.step_choice import StepRequest, choose
>>> choice = choose(StepRequest(tolerance=0.01), SingleProbe(excitation=Chirp()))  # doctest: +SKIP
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from qzs import _validation, defaults
from qzs._lazy import import_in_background
from qzs.engine.step_search import (MAX_HALVINGS, SAFETY, StepChoice, fallback_step,
                                    search_step, unmet_sentence)
from qzs.errors import ControllerRateError, ParameterError

__all__ = ["StepRequest", "Probe", "choose", "fallback_step", "unmet_sentence",
           "DEFAULT_KEYS", "step_request", "spectral_beside_probes", "admissible_step",
           "bound_notes", "RATE_REFINEMENT_MAX", "ADMISSIBLE_REFINEMENT", "ProbeSettings",
           "excitation_measure"]

#: Each measure's key of its default tolerance in :data:`qzs.defaults.ACCURACY`.
DEFAULT_KEYS = {"transmissibility_db": "tolerance_db", "state_m": "tolerance_state"}


#: A sampled controller may make the step at most this much finer than the largest stable
#: one [-]: its period and the output's must both be whole numbers of steps, and a rate
#: such as 333 Hz against a 1000 Hz output meets that only at 1/333000 s, a run hundreds
#: of times longer (:class:`~qzs.errors.ControllerRateError`).
RATE_REFINEMENT_MAX = 32
#: Steps per output sample a candidate takes at most [-] (:func:`admissible_step`).
ADMISSIBLE_REFINEMENT = 1_000_000


# ---------------------------------------------------------------- the admissible start
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


def bound_notes(dt0, k0, sample_rate, limit, resolving, measure, shortened):
    """What bounds the coarsest candidate ``dt0 = 1/(sample_rate*k0)`` [s], for people.

    Parameters
    ----------
    dt0 : float
        The coarsest candidate [s].
    k0 : int
        Its steps per output sample [-].
    sample_rate : float
        Output rate [Hz].
    limit : float
        The solver's largest stable step [s].
    resolving : float
        The largest step that resolves the base motion [s].
    measure : str
        The accuracy measure.
    shortened : bool
        Whether the probe is a shortened stand-in for the run's excitation.

    Returns
    -------
    list of str
    """
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


# ---------------------------------------------------------------- the request
@dataclass(frozen=True, kw_only=True)
class StepRequest:
    """What a run asks of its step: a literal ``dt``, a ``tolerance``, or the default.

    Checked once, here: a bad request is a :class:`~qzs.errors.ParameterError` naming the
    argument, its value and the fix, before any probe.

    Attributes
    ----------
    dt : float, optional
        A literal step [s]: nothing is chosen, nothing probed.
    tolerance : float, optional
        The tolerance, in the unit of ``measure``.
    measure : {"transmissibility_db", "state_m"}, optional
        What ``tolerance`` bounds: the transmissibility [dB] (the default with a tolerance) or
        the relative position [m]. Neither ``dt`` nor ``tolerance``: the default tolerance
        of this measure (of the probe's default measure if None too).
    """

    dt: float | None = None
    tolerance: float | None = None
    measure: str | None = None

    def __post_init__(self):
        if self.dt is not None and (self.tolerance is not None or self.measure is not None):
            raise ParameterError(
                f"give a literal `dt` ({self.dt!r} s) or a `tolerance` "
                f"({self.tolerance!r}, measure {self.measure!r}), not both: a literal step has "
                "no tolerance to meet; drop one.", ("dt", "tolerance"))
        if self.dt is not None:
            _validation.positive_real("dt", self.dt, fix="in seconds, e.g. 1e-3")
        if self.measure is not None:
            _validation.choice("measure", self.measure, tuple(DEFAULT_KEYS))
        if self.tolerance is not None:
            name = "tolerance_state" if self.measure == "state_m" else "tolerance"
            unit = "m" if self.measure == "state_m" else "dB"
            _validation.positive_real(name, self.tolerance, fix=f"in {unit}, e.g. "
                                      + ("1e-5" if unit == "m" else "0.01"))

    @property
    def literal(self) -> bool:
        """Whether the step is given literally (nothing to choose)."""
        return self.dt is not None

    def resolved(self, default_measure: str) -> tuple[str, float]:
        """The measure and tolerance asked: ``(measure, tolerance)``.

        Parameters
        ----------
        default_measure : str
            The probe's measure where the request names none (:meth:`Probe`'s builder).

        Returns
        -------
        measure : str
        tolerance : float
            In the measure's unit; the default is ``qzs.defaults.ACCURACY``'s.
        """
        measure = self.measure or ("transmissibility_db" if self.tolerance is not None
                                   else default_measure)
        if self.tolerance is not None:
            return measure, float(self.tolerance)
        return measure, float(defaults.ACCURACY[DEFAULT_KEYS[measure]])


def step_request(*, dt=None, tolerance=None, tolerance_state=None, tolerance_db=None,
                 required=False, stacklevel=4):
    """The :class:`StepRequest` of the API's keywords (one spelling: ``tolerance`` [dB]).

    Parameters
    ----------
    dt : float, optional
        A literal step [s].
    tolerance : float, optional
        On the transmissibility [dB].
    tolerance_state : float, optional
        On the relative position (or pose) [m].
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns).
    required : bool
        Exactly one tolerance must be given (a chooser's call): neither is refused too.
    stacklevel : int
        Where the deprecation warning points.

    Returns
    -------
    StepRequest

    Raises
    ------
    ParameterError
        Both tolerances (or neither where ``required``), a tolerance and a ``dt``, or a
        non-positive value.
    """
    tolerance = _validation.renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db,
                                            stacklevel=stacklevel)
    given = [name for name, value in (("tolerance", tolerance),
                                      ("tolerance_state", tolerance_state)) if value is not None]
    if len(given) == 2 or (required and not given):
        raise ParameterError(
            "give exactly one of `tolerance` (transmissibility, dB) and `tolerance_state` "
            f"(relative position, m); got {' and '.join(given) or 'neither'}.",
            ("tolerance", "tolerance_state"))
    if tolerance_state is not None:
        return StepRequest(dt=dt, tolerance=tolerance_state, measure="state_m")
    return StepRequest(dt=dt, tolerance=tolerance,
                       measure=None if tolerance is None else "transmissibility_db")


# ---------------------------------------------------------------- the probe
def excitation_measure(excitation):
    """The measure a run of ``excitation`` is judged by when it asks for no tolerance.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation, DisplacementRecord or None
        The run's excitation (None: the paper's chirp).

    Returns
    -------
    str
        ``"state_m"`` for a sine (one frequency, no band to estimate a transmissibility
        over), else ``"transmissibility_db"``.
    """
    from qzs.model.excitation import Sine

    return "state_m" if isinstance(excitation, Sine) else "transmissibility_db"


@dataclass(frozen=True, kw_only=True)
class ProbeSettings:
    """What every model's probe is given besides its model: the base of
    :class:`~qzs.engine.accuracy.SingleProbe`, :class:`~qzs.engine.accuracy_batch.BatchProbe`
    and :class:`~qzs.engine.hexapod.accuracy.HexapodProbe`. Nothing is computed until
    :meth:`build`, which :func:`choose` calls only for a chosen step.

    Attributes
    ----------
    excitation : object
        The run's excitation (None: the paper's chirp; the six legs: axis name -> excitation).
    solver : str
        The integrator.
    sample_rate : float
        Output rate [Hz] of the run the step is for.
    band : tuple of float or None
        Band [Hz] of the transmissibility measure (None: the excitation's).
    probe_duration : float or None
        Length of the probe [s] (None: the default).
    max_halvings : int
        Halvings of the admissible start tried at most [-].
    safety : float
        Factor [-] between the estimate and the tolerance.
    """

    excitation: Any = None
    solver: str = defaults.SIMULATION["solver"]
    sample_rate: float = defaults.SIMULATION["sample_rate"]
    band: tuple | None = None
    probe_duration: float | None = None
    max_halvings: int = MAX_HALVINGS
    safety: float = SAFETY

    @property
    def default_measure(self) -> str:
        """The default request's measure (:func:`excitation_measure`)."""
        return excitation_measure(self.excitation)

    def build(self, measure):
        """The probe for ``measure``: the inputs checked, the probe's excitation made.

        Parameters
        ----------
        measure : str
            The accuracy measure.

        Returns
        -------
        Probe
        """
        return self._build(measure)

    def _build(self, measure):
        raise NotImplementedError


@dataclass(frozen=True, kw_only=True)
class Probe:
    """A model's probe, built for one measure: what :func:`choose` needs to search a step.

    The probe is built only for a chosen step (a literal request builds none); its
    stability limit and admissible start (:attr:`start`) are computed only where the
    step cache has no answer.

    Attributes
    ----------
    measure : str
        The accuracy measure.
    order : int
        The scheme's order [-].
    sample_rate : float
        Output rate [Hz].
    solver : str
        The integrator.
    excitation : object
        The probe's excitation (for the record).
    duration : float
        The probe's length [s].
    band : tuple of float or None
        The transmissibility measure's band [Hz].
    shortened : bool
        Whether the probe is a shortened stand-in for the run's excitation.
    start : callable
        ``start()``: ``(stability_limit [s], resolving step [s], dt0 [s], k0 [-])``, the
        largest stable step, the largest resolving the base motion, and the admissible start
        (:func:`admissible_step`).
    run : callable
        ``run(dt, members)``: one probe run per listed case at step ``dt`` [s].
    compare : callable
        ``compare(coarse, fine)``: their difference in the measure's unit (NaN: none).
    cases : int
        Cases (lanes) sharing the step [-].
    labels : tuple of str or None
        Their names in the notes.
    key : mapping or None
        The cache-key parts (the model, the probe's settings); None: not cached.
    max_halvings : int
        Halvings of ``dt0`` tried at most [-].
    safety : float
        Factor [-] between the estimate and the tolerance.
    search : mapping
        How :func:`~qzs.engine.step_search.search_step` treats the cases:
        ``give_up_early``, ``per_case``, ``unit_name`` (each optional).
    """

    measure: str
    order: int
    sample_rate: float
    solver: str
    excitation: Any
    duration: float
    band: tuple | None
    shortened: bool
    start: Callable[[], tuple]
    run: Callable
    compare: Callable
    cases: int = 1
    labels: tuple | None = None
    key: Mapping | None = None
    max_halvings: int = MAX_HALVINGS
    safety: float = SAFETY
    search: Mapping = field(default_factory=dict)


# ---------------------------------------------------------------- the one call
def choose(request, probe, *, fallback=False, finest=None, progress=False, cache=False):
    """The step of a request on a probe: literal, from the cache, or searched.

    Parameters
    ----------
    request : StepRequest
        What is asked.
    probe : object
        A model's probe (:class:`qzs.engine.accuracy.SingleProbe`,
        :class:`qzs.engine.accuracy_batch.BatchProbe`,
        :class:`qzs.engine.hexapod.accuracy.HexapodProbe`): ``sample_rate``,
        ``solver``, ``default_measure`` and ``build(measure)`` -> :class:`Probe`.
    fallback : bool
        Where no candidate meets the tolerance (or no bin is trusted), return the fallback
        (:func:`fallback_step`, ``met`` False, :func:`unmet_sentence` as the last note)
        instead of raising.
    finest : float, optional
        The finest candidate [s]: halvings stop above it; the fallback step too.
    progress : bool
        Show a progress bar over the probe runs.
    cache : bool
        Read the choice from, and keep it in, the step cache (probes with cache-key parts).

    Returns
    -------
    StepChoice
        ``chosen`` False for a literal request (no probe work at all).

    Raises
    ------
    ParameterError
        A bad ``finest``, or as the probe's build and the search raise.
    ToleranceNotMetError
        No candidate meets the tolerance (without ``fallback``).
    """
    if request.literal:
        return StepChoice.literal(request.dt, sample_rate=probe.sample_rate, solver=probe.solver)
    if finest is not None:
        _validation.positive_real("finest", finest)
    measure, tolerance = request.resolved(probe.default_measure)
    legs = probe.build(measure)
    key = _cache_key(legs, tolerance, finest, fallback) if cache else None
    if key is not None:
        from qzs.engine import step_cache

        hit = step_cache.load_choice(key, legs.excitation, legs.duration,
                                     cases=legs.cases if legs.search.get("per_case") else None)
        if hit is not None:
            return hit
    choice = _search(legs, tolerance, fallback, finest, progress)
    if key is not None:
        from qzs.engine import step_cache

        step_cache.store_choice(key, choice)
    return choice


def _cache_key(legs, tolerance, finest, fallback):
    """The step cache's key of a choice (None: the probe is not cached)."""
    if legs.key is None:
        return None
    from qzs.engine import step_cache

    return step_cache.cache_key(**legs.key, measure=legs.measure, tolerance=tolerance,
                                max_halvings=legs.max_halvings, safety=legs.safety,
                                finest=finest, fallback=bool(fallback))


def spectral_beside_probes(measure):
    """Start loading what a step choice's estimates need, beside its first probe runs.

    For ``measure`` ``"transmissibility_db"``: the spectral analysis and scipy.signal (0.9 s
    of imports, loaded by the first estimate, not by :mod:`qzs.analysis.spectral` itself)
    load in a thread while the probe's first runs integrate in a kernel that holds no GIL.
    Called once a choice is known to need its probes (not read from the step cache).

    Parameters
    ----------
    measure : str
        The choice's measure, a key of :data:`DEFAULT_KEYS`.
    """
    if measure == "transmissibility_db":
        import_in_background("scipy.signal", "qzs.analysis.spectral")


def _search(legs, tolerance, fallback, finest, progress):
    """The one search on a built probe (:func:`~qzs.engine.step_search.search_step`)."""
    spectral_beside_probes(legs.measure)
    limit, resolving, dt0, k0 = legs.start()
    return search_step(
        legs, tolerance=tolerance, dt0=dt0, stability_limit=limit,
        notes=bound_notes(dt0, k0, legs.sample_rate, limit, resolving, legs.measure,
                          legs.shortened),
        finest=finest, fallback=fallback, progress=progress)

