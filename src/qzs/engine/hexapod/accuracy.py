"""The six-axis platform's accuracy-driven step: the largest fixed step meeting a tolerance.

The single axis's method (:func:`qzs.engine.accuracy.choose_step`, docs/model.md §7) with
the six-leg kernel: candidates ``dt_0 / 2**j`` from the largest step that is stable
(:func:`~qzs.engine.hexapod.prepare.hexapod_stability_test`), resolves the base motion and
divides the output period (:func:`~qzs.engine.accuracy.admissible_step`), each integrated
on a short probe of the excitation (:func:`~qzs.engine.accuracy.probe_excitation`) and
compared with the next finer one, the error extrapolated Richardson-style
(:func:`~qzs.engine.accuracy.halving_search`). Two measures (docs/hexapod.md §10.3):

``transmissibility_db``
    The driven axis's column of the 6x6 transmissibility (every platform axis ``i`` per the
    base axis ``j``, from the base point's velocity to the platform's twist) [dB]: the
    largest difference over the bins of the band that both runs trust and where the entry
    is above the numerical floor (``HEXAPOD["floor_db"]``, -100 dB of the base motion,
    rotations as arcs at the platform's size: rounding, not a response; docs/hexapod.md
    §10.2) (:func:`~qzs.engine.accuracy.estimate_difference_db`); a base moving along one
    axis. The column, not the diagonal alone: on the shipped platform an x chirp's diagonal
    at 1 ms is within 0.002 dB of 0.1 ms, its ry-per-x coupling 0.018 dB off.
``state_m``
    The platform's pose [m]: ``max |x_dt - x_ref|`` over the output samples and the six
    axes, a rotation counted as the arc it moves the joints through (radians times
    :func:`~qzs.model.hexapod.platform_size`): a tolerance ``tol`` [m] bounds the
    translations by ``tol`` [m] and the rotations by ``tol / platform_size`` [rad].

>>> from qzs.engine.hexapod.accuracy import choose_hexapod_step
>>> choice = choose_hexapod_step(geometry, platform, excitation={"x": Chirp(
...     amplitude=0.002, duration=200.0)}, tolerance_db=0.01)  # doctest: +SKIP
>>> choice.dt, choice.error  # doctest: +SKIP
(0.001, 0.0008...)
"""
import math

import numpy as np

from qzs import _validation, defaults
from qzs._validation import choice as _choice
from qzs.engine.accuracy import (MAX_HALVINGS, MEASURE_UNITS, PROBE_DURATION, SAFETY,
                                 StepChoice, error_band, excitation_range, probe_fft_length,
                                 tolerance_measure, admissible_step, estimate_difference_db,
                                 halving_search, probe_excitation)
from qzs.errors import ParameterError, ToleranceNotMetError

__all__ = ["choose_hexapod_step", "hexapod_probe", "hexapod_step_error"]


def hexapod_probe(excitation, band=None, probe_duration=None, duration=None,
                  sample_rate=defaults.SIMULATION["sample_rate"]):
    """The short stretch of a six-axis excitation the step is chosen on.

    A run no longer than the probe (60 s, or ``probe_duration``) is its own probe when no
    band is given (the state measure). Otherwise each moving axis's excitation becomes its
    probe (:func:`~qzs.engine.accuracy.probe_excitation`: a chirp a sweep over the band at
    its amplitude, a stationary excitation its first seconds); the probe lasts the longest
    of theirs, cut to the shortest probe with a length of its own and, unless a chirp
    moves, to ``duration``.

    Parameters
    ----------
    excitation : dict
        Axis name -> Chirp, Sine, RandomExcitation or DisplacementRecord (the moving axes).
    band : tuple of float, optional
        Frequency band [Hz] of a single moving axis (the transmissibility measure); default
        each excitation's frequencies.
    probe_duration : float, optional
        Length [s] asked of each probe (:func:`~qzs.engine.accuracy.probe_excitation`).
    duration : float, optional
        The run's length [s]: a probe of stationary excitations is not longer.
    sample_rate : float
        Output rate [Hz] (a record's frequencies stop at its Nyquist frequency).

    Returns
    -------
    probe : dict
        Axis name -> the probe's excitation.
    length : float
        The probe's length [s].
    """
    from qzs.model.excitation import Chirp

    if duration is not None and band is None and duration <= (probe_duration or PROBE_DURATION):
        return dict(excitation), float(duration)  # a short run is its own probe
    probes, lengths, limits = {}, [], []
    for axis, value in excitation.items():
        probe, length = probe_excitation(
            value, band or excitation_range(value, sample_rate), probe_duration)
        probes[axis] = probe
        lengths.append(length)
        if probe.duration is not None:
            limits.append(probe.duration)
    if duration is not None and not any(isinstance(v, Chirp) for v in excitation.values()):
        limits.append(duration)
    return probes, float(min([max(lengths), *limits]))


def hexapod_step_error(coarse, fine, measure, *, axis=None, band=None, fft_length=None,
                       size=None, floor_db=defaults.HEXAPOD["floor_db"]):
    """The difference of two six-axis runs of one probe in a measure of accuracy.

    Parameters
    ----------
    coarse, fine : HexapodResult
        Two runs of the same excitation at the same output rate.
    measure : {"transmissibility_db", "state_m"}
        ``transmissibility_db``: max ``|20 log10(T_coarse/T_fine)|`` [dB] over the driven
        axis's column and the bins of ``band`` trusted in both and above ``floor_db`` in both;
        ``state_m``: max over samples and axes of ``|pose_coarse - pose_fine|`` [m],
        rotations times ``size``.
    axis : str, optional
        The driven base axis (``transmissibility_db``).
    band : tuple of float, optional
        Band [Hz] of the transmissibility measure.
    fft_length : int, optional
        Welch segment length [samples]; default a power of two giving at least 8
        half-overlapping segments.
    size : float, optional
        The length [m] a rotation is multiplied by; default the platform's
        (:func:`~qzs.model.hexapod.platform_size`).
    floor_db : float
        Numerical floor [dB] of an entry, relative to the base motion (dimensionless:
        rotations times ``size``); default ``HEXAPOD["floor_db"]``.

    Returns
    -------
    float
        The difference, in [dB] or [m]; ``nan`` if no bin of the band is trusted in both.
    """
    from qzs.model.hexapod import platform_size

    _choice("measure", measure, tuple(MEASURE_UNITS))
    size = platform_size(coarse.geometry) if size is None else size
    scale = np.array([1.0, 1.0, 1.0, size, size, size])
    if measure == "state_m":
        return float(np.max(np.abs(coarse["platform_pose"] - fine["platform_pose"]) * scale))
    from qzs.analysis.spectral import transmissibility

    j = defaults.AXES.index(axis)
    rate = coarse.run["sample_rate"]
    length = probe_fft_length(coarse["platform_pose"].shape[0], rate, band, fft_length)
    floor = 10 ** (floor_db / 20)
    differences = []
    for i in range(6):
        a, b = (transmissibility(run["base_velocity"][:, j], run["platform_twist"][:, i], rate,
                                 fft_length=length) for run in (coarse, fine))
        factor = scale[i] / scale[j]  # the entry as a dimensionless response
        above = (a.magnitude * factor >= floor) & (b.magnitude * factor >= floor)
        differences.append(estimate_difference_db(a, b, band, keep=above))
    differences = [d for d in differences if not math.isnan(d)]
    return max(differences) if differences else math.nan


def choose_hexapod_step(geometry, platform, isolator=None, controller=None, *, excitation,
                        tolerance_db=None, tolerance_state=None,
                        solver=defaults.SIMULATION["solver"],
                        sample_rate=defaults.SIMULATION["sample_rate"], band=None,
                        duration=None, finest=None, fallback=None, probe_duration=None,
                        cartesian=None, max_halvings=MAX_HALVINGS, safety=SAFETY,
                        progress=False):
    """The largest fixed step of a six-axis run whose error stays within a tolerance.

    The method of :func:`qzs.engine.accuracy.choose_step` (module docstring): candidates
    ``dt_j = dt_0 / 2**j``, each run on the probe (:func:`hexapod_probe`) and compared with
    the next finer one in the measure, the error extrapolated with the observed ratio
    (capped at the scheme's order); the chosen step is the coarsest whose estimate times
    ``safety`` meets the tolerance.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Its mass and inertia.
    isolator, controller : IsolatorParameters, ControllerParameters or sequences of six
        The legs; defaults if omitted.
    excitation : dict
        Axis name -> excitation, as :func:`~qzs.engine.hexapod.simulate.simulate_hexapod`'s.
    tolerance_db : float, optional
        Tolerance on the driven axis's column of the transmissibility [dB] (one moving
        axis).
    tolerance_state : float, optional
        Tolerance on the pose [m] (rotations as arcs at the platform's size). Give exactly
        one of the two.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    sample_rate : float
        Output rate [Hz] of the run; the step divides its period.
    band : tuple of float, optional
        Band [Hz] of the transmissibility measure; default the excitation's frequencies (a
        chirp from 0 Hz: from 1 Hz).
    duration : float, optional
        The run's length [s]; a probe of a stationary excitation is not longer.
    finest : float, optional
        The finest candidate [s]: halvings stop above it (default :data:`~qzs.engine.
        accuracy.MAX_HALVINGS` halvings).
    fallback : float, optional
        The step [s] taken when no candidate meets the tolerance (its ``error`` is then
        ``nan`` and a note says why); default: :class:`~qzs.errors.ToleranceNotMetError`.
    probe_duration : float, optional
        Length of the probe [s]; default 60 s (a sine: its fade-in and 40 periods).
    cartesian : CartesianController, optional
        Centralised loops, as :func:`~qzs.engine.hexapod.simulate.simulate_hexapod`'s.
    max_halvings : int
        Halvings of ``dt_0`` tried at most [-].
    safety : float
        Factor [-] (>= 1) between the estimate and the tolerance.
    progress : bool
        Show a progress bar over the probe runs.

    Returns
    -------
    StepChoice
        As :func:`qzs.engine.accuracy.choose_step`'s (``probe`` the dict of probes).

    Raises
    ------
    ParameterError
        Both or neither tolerance, a non-positive one, no base motion, the transmissibility
        measure with several moving axes, a band outside the excitation, a bad ``finest``
        or ``fallback``.
    ToleranceNotMetError
        No candidate meets the tolerance and no ``fallback`` was given.
    """
    from qzs.engine.hexapod.prepare import (_excitations, _per_leg, _stability_limit,
                                            hexapod_stability_test)
    from qzs.engine.hexapod.simulate import simulate_hexapod
    from qzs.engine.prepare import resolving_step
    from qzs.engine.stability import SOLVERS
    from qzs.model.controller import ControllerParameters
    from qzs.model.hexapod import platform_size
    from qzs.model.isolator import IsolatorParameters

    measure, tolerance = tolerance_measure(tolerance_db, tolerance_state)
    moving = _excitations(excitation)
    if not moving:
        raise ParameterError("`excitation` moves no base axis: there is nothing to choose a "
                             "step for; give e.g. excitation={'z': Chirp(duration=20.0)}.")
    _, order = SOLVERS[_choice("solver", solver, tuple(SOLVERS))]
    sample_rate = _validation.positive_real("sample_rate", sample_rate)
    for name, value in (("duration", duration), ("finest", finest), ("fallback", fallback),
                        ("probe_duration", probe_duration)):
        if value is not None:
            _validation.positive_real(name, value)
    _validation.real("safety", safety, minimum=1.0)
    _validation.integer("max_halvings", max_halvings, 2)
    axis = None
    if measure == "transmissibility_db":
        if len(moving) != 1:
            raise ParameterError(
                f"`tolerance_db` measures the driven axis's transmissibility, which needs the "
                f"base moving along one axis; it moves along {sorted(moving)}. Give "
                "`tolerance_state` [m] (the pose) instead, or excite one axis.")
        axis, = moving
        band = error_band(band, moving[axis], sample_rate)
    isolators = _per_leg("isolator", IsolatorParameters() if isolator is None else isolator,
                         IsolatorParameters)
    controllers = _per_leg("controller",
                           ControllerParameters() if controller is None else controller,
                           ControllerParameters)
    probe, length = hexapod_probe(moving, band, probe_duration, duration, sample_rate)
    stable = hexapod_stability_test(geometry, platform, isolators, controllers, solver)
    limit = _stability_limit(geometry, platform, isolators, controllers, solver)
    resolving = min(resolving_step(value, length) for value in probe.values())
    dt0, k0 = admissible_step(sample_rate, controllers[0].controller_rate,
                              lambda dt: dt <= resolving and stable(dt))
    if finest is not None:
        count = sum(1 for j in range(64) if dt0 / 2 ** j >= finest * (1 - 1e-9))
        max_halvings = min(max_halvings, count - 1)
    notes = [f"dt_0 = 1/({sample_rate:g}*{k0}) = {dt0:.3g} s: the largest step that divides "
             f"the output period, is stable (<= {limit:.3g} s) and resolves the base motion"]
    size = platform_size(geometry)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=max_halvings + 1, unit="run", desc="choosing dt", leave=False)
    runs, differences = {}, {}

    def run(j):
        if j not in runs:
            runs[j] = simulate_hexapod(geometry, platform, isolators, controllers,
                                       excitation=probe, duration=length, dt=dt0 / 2 ** j,
                                       sample_rate=sample_rate, solver=solver,
                                       cartesian=cartesian)
            if bar is not None:
                bar.update(1)
        return runs[j]

    def difference(j):
        if j not in differences:
            differences[j] = hexapod_step_error(run(j), run(j + 1), measure, axis=axis,
                                                band=band, size=size)
            if j > 0:
                runs.pop(j - 1, None)  # a six-axis run holds 99 channels: keep two
        return differences[j]

    try:
        chosen, history = (None, []) if max_halvings < 2 else halving_search(
            difference, order, tolerance, dt0, max_halvings, safety)
    finally:
        if bar is not None:
            bar.close()
    unit = MEASURE_UNITS[measure]
    common = dict(measure=measure, tolerance=tolerance, stability_limit=float(limit),
                  sample_rate=sample_rate, solver=solver, probe=probe,
                  probe_duration=float(length), band=band, history=tuple(history))
    if chosen is None:
        untrusted = any(math.isnan(d) for d in differences.values())
        if untrusted:
            reason = (f"no bin of the band ({band[0]:g}, {band[1]:g}) Hz is trusted in both "
                      f"runs of the {length:g} s probe")
            if fallback is None:
                raise ParameterError(reason + "; lengthen `probe_duration` or narrow the band.")
        elif history:
            shown = ", ".join(f"{d:.3g}" for _, d, _ in history)
            reason = (f"no step down to {dt0 / 2 ** max_halvings:.3g} s met {tolerance:g} "
                      f"{unit} (with safety {safety:g}): the differences between successive "
                      f"halvings ({shown} {unit}) do not shrink as the scheme's order predicts "
                      "(a stick-slip pattern that each refinement redraws)")
        else:
            reason = (f"fewer than three candidate steps between {dt0:.3g} s and the finest, "
                      f"{finest:.3g} s, to compare")
        if fallback is None:
            best = min((h[2] for h in history), default=math.inf)
            raise ToleranceNotMetError(tolerance, unit, dt0 / 2 ** max_halvings, best, safety)
        return StepChoice(dt=float(fallback), error=math.nan,
                          reference_dt=dt0 / 2 ** max_halvings,
                          notes=tuple(notes + [reason + f"; taking {fallback:g} s"]), met=False,
                          **common)
    return StepChoice(dt=dt0 / 2 ** chosen, error=float(history[-1][2]),
                      reference_dt=dt0 / 2 ** (chosen + 2), notes=tuple(notes), **common)
