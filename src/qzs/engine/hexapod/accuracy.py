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
...     amplitude=0.002, duration=200.0)}, tolerance=0.01)  # doctest: +SKIP
>>> choice.dt, choice.error  # doctest: +SKIP
(0.001, 0.0008...)
"""
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from qzs import _validation, defaults
from qzs._validation import choice as _choice
from qzs.engine.accuracy import (PROBE_DURATION, check_band, estimate_difference_db,
                                 frequency_range, probe_excitation, probe_fft_length)
from qzs.engine.step_choice import ProbeSettings, admissible_step
from qzs.engine.step_search import MAX_HALVINGS, MEASURE_UNITS, SAFETY
from qzs.errors import ParameterError

__all__ = ["choose_hexapod_step", "hexapod_probe", "hexapod_step_error", "HexapodProbe"]


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
            value, band or frequency_range(value, sample_rate), probe_duration)
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
                        tolerance=None, tolerance_state=None,
                        solver=defaults.SIMULATION["solver"],
                        sample_rate=defaults.SIMULATION["sample_rate"], band=None,
                        duration=None, finest=None, fallback=False, probe_duration=None,
                        cartesian=None, max_halvings=MAX_HALVINGS, safety=SAFETY,
                        progress=False, tolerance_db=None):
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
    tolerance : float, optional
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
    fallback : bool
        Where no candidate meets the tolerance, return the one fallback of
        :func:`~qzs.engine.step_search.search_step` (``finest``, default the paper's step;
        ``error`` NaN and a note why) instead of raising
        :class:`~qzs.errors.ToleranceNotMetError`.
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
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

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
    from qzs.engine.step_choice import choose, step_request

    request = step_request(tolerance=tolerance, tolerance_state=tolerance_state,
                           tolerance_db=tolerance_db, required=True)
    return choose(request, HexapodProbe(
        geometry=geometry, platform=platform, isolator=isolator, controller=controller,
        excitation=excitation, solver=solver,
        sample_rate=sample_rate, band=band, duration=duration, probe_duration=probe_duration,
        cartesian=cartesian, max_halvings=max_halvings, safety=safety),
        fallback=fallback, finest=finest, progress=progress)


@dataclass(frozen=True, kw_only=True)
class HexapodProbe(ProbeSettings):
    """The probe of the six-leg platform: the inputs of :func:`choose_hexapod_step` but the
    tolerance; nothing computed until :func:`qzs.engine.step_choice.choose` calls
    :meth:`build` for a chosen step. Not cached (no key).

    Attributes
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Its mass and inertia.
    isolator : IsolatorParameters or sequence of six or None
        The legs' plants (None: the defaults).
    controller : ControllerParameters or sequence of six or None
        The legs' loops (None: the defaults).
    excitation : dict
        Axis name -> excitation (the moving axes).
    solver : str
        The integrator.
    sample_rate : float
        Output rate [Hz] of the run the step is for.
    band : tuple of float or None
        Band [Hz] of the transmissibility measure (None: the excitation's).
    probe_duration : float or None
        Length of the probe [s] (None: the default).
    duration : float or None
        The run's length [s]; a probe of a stationary excitation is not longer.
    cartesian : CartesianController or None
        Centralised loops.
    max_halvings : int
        Halvings of the admissible start tried at most [-].
    safety : float
        Factor [-] between the estimate and the tolerance.
    """

    geometry: Any
    platform: Any
    isolator: Any = None
    controller: Any = None
    duration: float | None = None
    cartesian: Any = None

    @property
    def default_measure(self) -> str:
        """The default request's measure: one chirping axis, its transmissibility; else the
        pose."""
        from qzs.model.excitation import Chirp

        moving = dict(self.excitation or {})
        one_chirp = len(moving) == 1 and isinstance(next(iter(moving.values())), Chirp)
        return "transmissibility_db" if one_chirp else "state_m"

    def _build(self, measure):
        from qzs.engine.hexapod.prepare import _excitations
        from qzs.engine.step_choice import Probe
        from qzs.model.hexapod import platform_size

        moving = _excitations(self.excitation)
        if not moving:
            raise ParameterError("`excitation` moves no base axis: there is nothing to choose "
                                 "a step for; give e.g. excitation={'z': Chirp(duration=20.0)}.")
        order, sample_rate, axis, band = self._settings(measure, moving)
        isolators, controllers = self._legs()
        probe, length = hexapod_probe(moving, band, self.probe_duration, self.duration,
                                      sample_rate)
        size = platform_size(self.geometry)
        return Probe(
            measure=measure, order=order, sample_rate=sample_rate, solver=self.solver,
            excitation=probe, duration=length, band=band, shortened=True,
            start=lambda: self._start(isolators, controllers, probe, length, sample_rate),
            run=lambda dt, cases: [_probe_run(self, isolators, controllers, probe,
                                                          length, dt, sample_rate)],
            compare=lambda coarse, fine: hexapod_step_error(coarse, fine, measure, axis=axis,
                                                            band=band, size=size),
            max_halvings=self.max_halvings, safety=self.safety)

    def _settings(self, measure, moving):
        """The checked order [-], output rate [Hz], driven axis and band [Hz]."""
        from qzs.engine.stability import SOLVERS

        _, order = SOLVERS[_choice("solver", self.solver, tuple(SOLVERS))]
        sample_rate = _validation.positive_real("sample_rate", self.sample_rate)
        for name, value in (("duration", self.duration), ("probe_duration", self.probe_duration)):
            if value is not None:
                _validation.positive_real(name, value)
        _validation.real("safety", self.safety, minimum=1.0)
        _validation.integer("max_halvings", self.max_halvings, 2)
        axis, band = None, self.band
        if measure == "transmissibility_db":
            if len(moving) != 1:
                raise ParameterError(
                    f"`tolerance` measures the driven axis's transmissibility, which needs the "
                    f"base moving along one axis; it moves along {sorted(moving)}. Give "
                    "`tolerance_state` [m] (the pose) instead, or excite one axis.",
                    ("tolerance", "tolerance_state"))
            axis, = moving
            band = check_band(band, moving[axis], sample_rate)
        return order, sample_rate, axis, band

    def _legs(self):
        """The six legs' isolators and controllers (defaults if omitted)."""
        from qzs.engine.hexapod.prepare import _per_leg
        from qzs.model.controller import ControllerParameters
        from qzs.model.isolator import IsolatorParameters

        isolators = _per_leg("isolator", IsolatorParameters() if self.isolator is None
                             else self.isolator, IsolatorParameters)
        controllers = _per_leg("controller", ControllerParameters() if self.controller is None
                               else self.controller, ControllerParameters)
        return isolators, controllers

    def _start(self, isolators, controllers, probe, length, sample_rate):
        """The stability limit, resolving step and admissible start (``Probe.start``)."""
        from qzs.engine.hexapod.prepare import _stability_limit, hexapod_stability_test
        from qzs.engine.prepare import resolving_step

        stable = hexapod_stability_test(self.geometry, self.platform, isolators, controllers,
                                        self.solver)
        limit = _stability_limit(self.geometry, self.platform, isolators, controllers,
                                 self.solver)
        resolving = min(resolving_step(value, length) for value in probe.values())
        dt0, k0 = admissible_step(sample_rate, controllers[0].controller_rate,
                                  lambda dt: dt <= resolving and stable(dt))
        return limit, resolving, dt0, k0


def _probe_run(probe_of, isolators, controllers, probe, length, dt, sample_rate):
    """One probe run of the six-leg platform at step ``dt`` [s] (``Probe.run``).

    Parameters
    ----------
    probe_of : HexapodProbe
        The builder (geometry, platform, solver, centralised loops).
    isolators, controllers : list
        The six legs.
    probe : dict
        Axis name -> the probe's excitation.
    length : float
        The probe's length [s].
    dt : float
        The step [s].
    sample_rate : float
        Output rate [Hz].

    Returns
    -------
    HexapodResult
    """
    from qzs.engine.hexapod.simulate import simulate_hexapod

    return simulate_hexapod(probe_of.geometry, probe_of.platform, isolators, controllers,
                            excitation=probe, duration=length, dt=dt, sample_rate=sample_rate,
                            solver=probe_of.solver, cartesian=probe_of.cartesian)
