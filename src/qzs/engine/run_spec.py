"""A run resolved once: inputs validated, defaults and duration put in, the step chosen, its record made.

Every single-axis run of qzs goes through :func:`resolve`: :func:`qzs.simulate`, the
streaming writer (:func:`qzs.workflows.run.simulate_to_file`), ``qzs simulate`` and the
tuning page. It is the one place where a run's defaults are decided (docs/model.md §7,
"one step decision"): a literal ``dt``, or the largest step meeting a tolerance over the band
the run covers (``tolerance`` [dB] on the transmissibility, ``tolerance_state`` [m] on the
relative position); given neither, ``step`` says which (the Python functions: the paper's
literal step; the commands and the page: the default accuracy), so that the API, the command
line and the page give the same step and the same numbers for the same inputs.
Values flow down only: what a caller needs of the step (its record, its notes) is in the
:class:`ResolvedRun`, never asked again.

>>> import qzs
>>> run = qzs.resolve(qzs.Chirp(duration=60.0, f1=5.0), tolerance=0.01)  # doctest: +SKIP
>>> run.step.line()  # doctest: +SKIP
'0.001 s (chosen for 0.01 dB, estimated error 0.0011 dB)'
>>> result = run.simulate()  # doctest: +SKIP
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from qzs import _validation, defaults
from qzs.errors import ParameterError

if TYPE_CHECKING:
    from qzs.engine.result import SimulationResult
    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.isolator import InitialState, IsolatorParameters

__all__ = ["ResolvedRun", "resolve", "ResolvedHexapodRun", "resolve_hexapod", "MAX_SAMPLES",
           "check_output_rate", "check_length"]

#: Output samples a run may ask for at most [-] (past this, counts lose their integers).
MAX_SAMPLES = 1e15


@dataclass(frozen=True, kw_only=True)
class ResolvedRun:
    """A single-axis run with every input resolved: what :func:`resolve` returns.

    Attributes
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base motion.
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    initial_state : InitialState or None
        The initial state (None: at rest at the setpoint).
    duration : float
        Simulated time [s].
    dt : float
        Integration step [s].
    sample_rate : float
        Output rate [Hz].
    solver : str
        The integrator.
    step : StepChoice
        How ``dt`` was chosen, or that it was given (:class:`~qzs.engine.step_search.StepChoice`):
        the one record the console, JSON, files and reports show.
    """

    excitation: Any
    isolator: Any
    controller: Any
    initial_state: Any
    duration: float
    dt: float
    sample_rate: float
    solver: str
    step: Any

    def arguments(self) -> dict[str, Any]:
        """The keywords of the run for :func:`qzs.engine.simulate.simulate` and its kin.

        Returns
        -------
        dict
            ``excitation``, ``isolator``, ``controller``, ``duration`` [s], ``dt`` [s],
            ``sample_rate`` [Hz], ``solver`` and ``initial_state``.
        """
        return dict(excitation=self.excitation, isolator=self.isolator,
                    controller=self.controller, duration=self.duration, dt=self.dt,
                    sample_rate=self.sample_rate, solver=self.solver,
                    initial_state=self.initial_state)

    def simulate(self, *, progress: bool = False, interruptible: bool = False,
                 sink: Callable[[Any, Any], Any] | None = None) -> SimulationResult:
        """Integrate the run (:func:`qzs.engine.single.integrate`).

        Parameters
        ----------
        progress : bool
            Show a progress bar.
        interruptible : bool
            Ctrl-C ends the run early and returns what was simulated.
        sink : callable, optional
            As for :func:`qzs.simulate`.

        Returns
        -------
        SimulationResult
        """
        from qzs.engine.single import integrate

        return integrate(**self.arguments(), progress=progress, interruptible=interruptible,
                         sink=sink, step=self.step)


def _one_step_request(**asked):
    """The names of the step requests given (``dt`` or a tolerance); more than one is refused."""
    given = [name for name, value in asked.items() if value is not None]
    if len(given) > 1:
        names = list(asked)
        raise ParameterError(f"give one of `{names[0]}`, `{names[1]}` and `{names[2]}`, got "
                             f"{' and '.join(f'`{n}`' for n in given)}; a literal step has no "
                             "tolerance to meet.")
    return given


def resolve(excitation: Excitation | None = None, isolator: IsolatorParameters | None = None,
            controller: ControllerParameters | None = None, *, duration: float | None = None,
            dt: float | None = None, tolerance: float | None = None,
            tolerance_state: float | None = None,
            sample_rate: float = defaults.SIMULATION["sample_rate"],
            solver: str = defaults.SIMULATION["solver"],
            initial_state: InitialState | None = None, step: str = "literal",
            progress: bool = False, cache: bool = True) -> ResolvedRun:
    """Resolve a single-axis run once: validate, put in defaults, choose the step.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default the paper's 10 mm, 0-20 Hz, 2000 s chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    duration : float, optional
        Simulated time [s]; default the excitation's length (required for a sine).
    dt : float, optional
        A literal integration step [s] (the paper's: 1e-4). Give it or a tolerance, not
        both.
    tolerance : float, optional
        Choose the largest step whose transmissibility stays within this many [dB] of a
        finer one over the band the run covers (docs/model.md §7).
    tolerance_state : float, optional
        Choose the largest step whose relative position stays within this many [m] of a
        finer one.
    sample_rate : float
        Output rate [Hz].
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    initial_state : InitialState, optional
        Default: at rest at the setpoint.
    step : {"literal", "chosen"}
        The step given neither a ``dt`` nor a tolerance (docs/model.md §7, the one step
        decision): ``"literal"``, the paper's ``defaults.SIMULATION["dt"]`` (the Python
        functions': a script's numbers never depend on a search or a cache), or
        ``"chosen"``, the largest step meeting ``defaults.ACCURACY`` (the transmissibility
        within 0.01 dB; a sine's relative position within 1e-5 m), as the commands and the
        page ask. Either way the same inputs give the same step everywhere.
    progress : bool
        Show a progress bar while the step is chosen.
    cache : bool
        Read the step from, and keep it in, the step cache on disk
        (:mod:`qzs.engine.step_cache`): a repeated question skips the probe, with the same
        answer.

    Returns
    -------
    ResolvedRun

    Raises
    ------
    ParameterError
        An invalid input (named with its value and the fix), both a ``dt`` and a
        tolerance, a transmissibility tolerance for a sine; as :func:`qzs.simulate`.
    """
    from qzs.engine.accuracy import SingleProbe, excitation_over, probe_excitation
    from qzs.engine.prepare import pack_model, run_duration, run_inputs
    from qzs.engine.step_choice import choose, step_request
    from qzs.model.excitation import Sine

    excitation, isolator, controller = run_inputs(excitation, isolator, controller)
    _validation.choice("step", step, ("literal", "chosen"))
    duration = run_duration(excitation, duration)
    sample_rate = _validation.positive_real("sample_rate", sample_rate)
    if not duration * sample_rate <= MAX_SAMPLES:
        raise ParameterError(
            f"`duration` {duration:g} s at `sample_rate` {sample_rate:g} Hz asks for "
            f"{duration * sample_rate:.3g} output samples, more than any run can hold "
            f"({MAX_SAMPLES:.0e}); shorten the run or lower the rate.",
            ("duration", "sample_rate"))
    given = _one_step_request(dt=dt, tolerance=tolerance, tolerance_state=tolerance_state)
    if dt is None and not given and step == "literal":
        dt = defaults.SIMULATION["dt"]
    check_length(duration, sample_rate, None if dt is None else
                 _validation.positive_real("dt", dt))
    if tolerance is not None and isinstance(excitation, Sine):
        raise ParameterError(
            f"`tolerance` ({tolerance!r} dB) is on the transmissibility, which a sine "
            "has no band to estimate; give `tolerance_state` [m] or a literal `dt`.",
            ("tolerance", "tolerance_state", "dt"))
    request = step_request(dt=dt, tolerance=tolerance, tolerance_state=tolerance_state)
    covered = excitation_over(excitation, duration)
    probe_duration = None
    if not request.literal and not math.isclose(duration, covered.duration or math.inf):
        # a stationary excitation's probe is its start: never longer than the run
        default = probe_excitation(covered, (0.0, 0.0))[1]
        probe_duration = duration if duration < default else None
    choice = choose(request, SingleProbe(excitation=covered, isolator=isolator,
                                         controller=controller, solver=solver,
                                         sample_rate=sample_rate, probe_duration=probe_duration,
                                         initial_state=initial_state),
                    fallback=True, progress=progress, cache=cache)
    if request.literal:
        pack_model(isolator, controller, choice.dt)  # a discrete linear controller's steps
    return ResolvedRun(excitation=excitation, isolator=isolator, controller=controller,
                       initial_state=initial_state, duration=duration, dt=choice.dt,
                       sample_rate=sample_rate, solver=solver, step=choice)


def check_output_rate(excitation, duration, sample_rate):
    """Refuse an excitation at or above half the output rate, where a time series is shown.

    Its samples could not show the excitation: they would alias it to a lower frequency.
    :func:`resolve` does not check this (a script may sample a run coarsely on purpose: the
    final state, the statistics); the commands that write or draw the time series do
    (``qzs simulate``).

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The base motion (a record's bound is its own samples', not checked here).
    duration : float
        Simulated time [s] (a chirp reaches its ``f1`` only at its end).
    sample_rate : float
        Output rate [Hz].

    Raises
    ------
    ParameterError
        The excitation's highest frequency at or above ``sample_rate / 2``; its ``options``
        name the excitation's frequency field and ``sample_rate``.
    """
    from qzs.model.excitation import Chirp, RandomExcitation, Sine, highest_frequency

    if not isinstance(excitation, (Sine, Chirp, RandomExcitation)):
        return
    numbers = [v for v in (duration, sample_rate) if v is not None]
    if not all(isinstance(v, (int, float)) and 0 < v < math.inf for v in numbers):
        return  # not a duration or a rate at all: resolve() says what is wrong
    top = highest_frequency(excitation, duration)
    if top >= sample_rate / 2:
        name = {Sine: "frequency", Chirp: "f1", RandomExcitation: "f_high"}[type(excitation)]
        raise ParameterError(
            f"`{name}` {top:g} Hz is at or above half the output rate (`sample_rate` "
            f"{sample_rate:g} Hz shows at most {sample_rate / 2:g} Hz; the samples would alias "
            f"it): raise `sample_rate` above {2 * top:g} Hz ({5 * top:g} Hz resolves it well) "
            f"or lower `{name}`.", (name, "sample_rate"))


def check_length(duration, sample_rate, dt, kernel="single"):
    """Refuse, before any step is chosen, a run that would take absurdly long.

    A given ``dt`` is checked as the driver would (:class:`~qzs.errors.RunTooLongError`); a
    step still to be chosen is never longer than the output period, so counting steps at
    that period is a lower bound, and the refusal certain.

    Parameters
    ----------
    duration : float
        Simulated time [s].
    sample_rate : float
        Output rate [Hz].
    dt : float or None
        The integration step [s]; None: still to be chosen.
    kernel : {"single", "lanes", "hexapod"}
        Which kernel steps (:data:`qzs.engine.driver.BEST_STEP_SECONDS`).

    Raises
    ------
    RunTooLongError
        ``dt`` given, and the run would take more than a day at the kernel's best speed.
    ParameterError
        ``dt`` to be chosen, and even at the output period the same; its ``options`` are
        ``duration`` and ``sample_rate``.
    """
    from qzs.engine.driver import plan_run
    from qzs.errors import RunTooLongError

    bound = dt if dt is not None else 1.0 / sample_rate
    fix = ("a shorter `duration` or a larger `dt`" if dt is not None else
           "a shorter `duration` or a lower `sample_rate` (the step is at most its period)")
    options = ("duration", "dt") if dt is not None else ("duration", "sample_rate")
    if not math.isfinite(duration / bound):
        raise ParameterError(f"`duration` {duration:g} s at dt = {bound:g} s is more "
                             f"integration steps than a number holds; choose {fix}.", options)
    if dt is not None:
        plan_run(float(duration), float(dt), 1, kernel=kernel)  # RunTooLongError, its data
        return
    try:
        plan_run(float(duration), float(bound), 1, kernel=kernel)
    except RunTooLongError as error:
        raise ParameterError(
            f"`duration` {duration:g} s is at least {error.steps:.3g} integration steps "
            f"(dt <= {error.dt:g} s): more than the day of computing qzs starts at most; "
            f"choose {fix}.", options) from None


@dataclass(frozen=True, kw_only=True)
class ResolvedHexapodRun:
    """A six-leg platform run with its step resolved: what :func:`resolve_hexapod` returns.

    Attributes
    ----------
    excitation : dict
        Axis name -> excitation.
    duration : float or None
        Simulated time [s] (None: the shortest excitation's length).
    dt : float
        Integration step [s].
    sample_rate : float
        Output rate [Hz].
    solver : str
        The integrator.
    step : StepChoice
        How ``dt`` was chosen, or that it was given: the one record.
    """

    excitation: Any
    duration: Any
    dt: float
    sample_rate: float
    solver: str
    step: Any

    def arguments(self):
        """The keywords of :func:`~qzs.engine.hexapod.simulate.simulate_hexapod` it fixes.

        Returns
        -------
        dict
            ``excitation``, ``duration`` [s], ``dt`` [s], ``sample_rate`` [Hz], ``solver``.
        """
        return dict(excitation=self.excitation, duration=self.duration, dt=self.dt,
                    sample_rate=self.sample_rate, solver=self.solver)


def resolve_hexapod(geometry, platform, isolator=None, controller=None, *, excitation,
                    duration=None, dt=None, tolerance=None, tolerance_state=None,
                    sample_rate=defaults.SIMULATION["sample_rate"],
                    solver=defaults.SIMULATION["solver"], cartesian=None, finest=None,
                    step="literal", progress=False, tolerance_db=None):
    """Resolve a six-leg platform run once: validate its settings, choose its step.

    The step is literal (``dt``), or the largest meeting a tolerance
    (:func:`qzs.engine.hexapod.accuracy.choose_hexapod_step`, with the one fallback): the
    driven axis's transmissibility within ``tolerance`` [dB] (one moving axis), or the pose
    within ``tolerance_state`` [m]; given neither, ``step`` decides as for :func:`resolve`
    (``"chosen"``: ``defaults.ACCURACY``, the transmissibility for one chirp, else the pose).

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Its mass and inertia.
    isolator, controller : IsolatorParameters, ControllerParameters or sequences of six
        The legs.
    excitation : dict
        Axis name -> built excitation.
    duration : float, optional
        Simulated time [s].
    dt : float, optional
        A literal step [s].
    tolerance : float, optional
        Tolerance [dB] on the driven axis's column of the transmissibility.
    tolerance_state : float, optional
        Tolerance [m] on the pose.
    sample_rate : float
        Output rate [Hz].
    solver : str
        The integrator.
    cartesian : CartesianController, optional
        Centralised loops.
    finest : float, optional
        The finest candidate of the search and its fallback [s] (default the paper's step).
    step : {"literal", "chosen"}
        The step given neither ``dt`` nor a tolerance, as for :func:`resolve`.
    progress : bool
        Show the probes' progress.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    ResolvedHexapodRun

    Raises
    ------
    ParameterError
        Invalid settings (before any probe), both a ``dt`` and a tolerance.
    """
    from qzs.engine.hexapod.accuracy import HexapodProbe
    from qzs.engine.hexapod.prepare import check_hexapod_run
    from qzs.engine.step_choice import choose, step_request

    _validation.choice("step", step, ("literal", "chosen"))
    tolerance = _validation.renamed_keyword("tolerance", tolerance, "tolerance_db",
                                            tolerance_db)
    given = _one_step_request(dt=dt, tolerance=tolerance, tolerance_state=tolerance_state)
    finest = defaults.SIMULATION["dt"] if finest is None else finest
    if dt is None and not given and step == "literal":
        dt = finest
    # bad settings fail before any probe (at the finest step, which any choice is above)
    check_hexapod_run(geometry, platform, isolator, controller, excitation=excitation,
                      duration=duration, dt=finest if dt is None else dt,
                      sample_rate=sample_rate, solver=solver, cartesian=cartesian)
    request = step_request(dt=dt, tolerance=tolerance, tolerance_state=tolerance_state)
    choice = choose(request, HexapodProbe(
        geometry=geometry, platform=platform, isolator=isolator, controller=controller,
        excitation=excitation, solver=solver,
        sample_rate=sample_rate, duration=duration, cartesian=cartesian),
        finest=None if request.literal else finest, fallback=True, progress=progress)
    return ResolvedHexapodRun(excitation=excitation, duration=duration, dt=choice.dt,
                              sample_rate=sample_rate, solver=solver, step=choice)
