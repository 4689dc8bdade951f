"""Validation and the plan of the runs: axes, amplitudes, step, segments, trusted band."""
from types import MappingProxyType

import numpy as np

from qzs import defaults
from qzs._validation import choice, integer, positive_real, real
from qzs.defaults import AXES, AXIS_UNITS
from qzs.errors import ParameterError
from qzs.workflows.hexapod.transmissibility.runs import AxisRun
from qzs.workflows.hexapod.transmissibility.settings import (AMPLITUDE, ESTIMATORS,
                                                             MIN_SEGMENTS, platform_size)


# ---------------------------------------------------------------- validation
def _axes(axes):
    if isinstance(axes, str):
        axes = tuple(a.strip() for a in axes.split(",") if a.strip())
    try:
        axes = tuple(axes)
    except TypeError:
        raise ParameterError(f"`axes` must be a sequence of base axes among {AXES}, got "
                             f"{axes!r}.") from None
    unknown = [a for a in axes if a not in AXES]
    if unknown or not axes:
        raise ParameterError(f"`axes` must name at least one base axis among {AXES}, got "
                             f"{axes!r}" + (f" (unknown: {unknown})" if unknown else "")
                             + "; e.g. axes=('z', 'x').")
    twice = sorted({a for a in axes if axes.count(a) > 1})
    if twice:
        raise ParameterError(f"`axes` names {twice} more than once ({axes!r}); each axis is "
                             "one run.")
    return tuple(a for a in AXES if a in axes)


def _amplitudes(amplitude, axes):
    values = {axis: AMPLITUDE[axis] for axis in axes}
    if amplitude is None:
        return values
    if isinstance(amplitude, dict) or isinstance(amplitude, MappingProxyType):
        extra = [a for a in amplitude if a not in axes]
        if extra:
            raise ParameterError(f"`amplitude` gives {extra}, which are not among the excited "
                                 f"`axes` {axes}; add them to `axes` or drop them.")
        given = dict(amplitude)
    else:
        kinds = {axis in AXES[3:] for axis in axes}
        if len(kinds) > 1:
            raise ParameterError(
                f"`amplitude` {amplitude!r} is one number, but the `axes` {axes} mix "
                "translations [m] and rotations [rad]; give a mapping, e.g. "
                "amplitude={'z': 0.002, 'rx': 0.01} (on the command line "
                "--amplitude z=0.002,rx=0.01).")
        given = dict.fromkeys(axes, amplitude)
    for axis, value in given.items():
        unit = AXIS_UNITS[AXES.index(axis)]
        number = real(f"amplitude[{axis!r}]", value)
        if not number > 0:
            raise ParameterError(f"`amplitude[{axis!r}]` must be a positive amplitude [{unit}], "
                                 f"got {value!r}.")
        values[axis] = number
    return values


def _tolerance_db(tolerance_db, dt):
    """The tolerance [dB] of the accuracy-driven step (None with a given ``dt``)."""
    if tolerance_db is None:
        return None if dt is not None else defaults.ACCURACY["tolerance_db"]
    if dt is not None:
        raise ParameterError(f"give either `dt` ({dt!r} s, a literal step) or `tolerance` "
                             f"({tolerance_db!r} dB, the step chosen to meet it), not both.",
                             ("dt", "tolerance"))
    return positive_real("tolerance", tolerance_db,
                         fix="a tolerance on the transmissibility in dB, e.g. 0.01")


def _optional_positive(name, value):
    return None if value is None else positive_real(name, value)


def _stable(setup, controller, solver):
    """``stable(dt)`` of the set-up's legs, the engine's own check."""
    from qzs.engine.hexapod import hexapod_stability_test

    return hexapod_stability_test(setup.geometry, setup.platform, setup.isolator, controller,
                                  solver)


def _default_fft_length(n_samples, longest=defaults.ANALYSIS["fft_length"]):
    """A power of two giving at least :data:`MIN_SEGMENTS` half-overlapping segments."""
    fitting = 2 * n_samples / (MIN_SEGMENTS + 1)
    length = 2 ** int(np.floor(np.log2(max(fitting, 64))))
    return int(min(length, longest))


def sweep_trusted_from(f0, f1, duration, fft_length, sample_rate):
    """Lowest frequency [Hz] a linear chirp's estimate may be trusted at.

    The chirp crosses the bins below ``f0 + (f1 - f0) * T/(4 * duration)`` (``T`` the
    Welch segment's length) in the first quarter of the first segment: under its rising
    Hann taper and in no other segment. There a single windowed stretch, dominated by the
    motions' slow trends (the constant detrend removes only the mean), carries the bin,
    and its coherence is 1 by construction, whatever caused the platform's motion.

    Parameters
    ----------
    f0, f1 : float
        The chirp's start and end frequency [Hz].
    duration : float
        Its sweep time [s].
    fft_length : int
        Welch segment length [samples].
    sample_rate : float
        Sample rate [Hz].

    Returns
    -------
    float
        [Hz].
    """
    return f0 + (f1 - f0) * (fft_length / sample_rate) / (4.0 * duration)


def _plan(setup, axes, amplitude, f0, f1, duration, dt, sample_rate, solver, fft_length,
          estimator, floor_db, workers, progress, tolerance_db=None):
    """Check every argument; the runs' common settings and one :class:`AxisRun` per axis."""
    from qzs.model.excitation import Chirp
    from qzs.workflows.hexapod.setups import HexapodSetup

    if not isinstance(setup, HexapodSetup):
        raise ParameterError(f"`setup` must be a HexapodSetup (qzs.workflows.hexapod.setups."
                             f"load_hexapod or hexapod_setup), got {type(setup).__name__}.")
    axes = _axes(axes)
    amplitudes = _amplitudes(amplitude, axes)
    f0 = real("f0", f0)
    f1 = real("f1", f1)
    if not 0 <= f0 < f1:
        raise ParameterError(f"the chirp must rise: 0 <= `f0` < `f1` [Hz], got f0={f0!r}, "
                             f"f1={f1!r}.")
    duration = positive_real("duration", duration)
    sample_rate = positive_real("sample_rate", sample_rate if sample_rate is not None else
                           setup.simulation.get("sample_rate",
                                                defaults.SIMULATION["sample_rate"]))
    if f1 >= 0.5 * sample_rate:
        raise ParameterError(f"`f1` ({f1:g} Hz) must lie below the output's Nyquist frequency "
                             f"{0.5 * sample_rate:g} Hz; raise `sample_rate` or lower `f1`.")
    solver = choice("solver", solver if solver is not None else
                    setup.simulation.get("solver", defaults.SIMULATION["solver"]),
                    ("ode3", "rk4", "euler"))
    setup_dt = positive_real("the set-up's [simulation] dt",
                        setup.simulation.get("dt", defaults.SIMULATION["dt"]))
    dt = _optional_positive("dt", dt)
    tolerance_db = _tolerance_db(tolerance_db, dt)
    from qzs.engine.prepare import steps_per_sample

    for name, step in (("dt", dt), ("the set-up's [simulation] dt", setup_dt)):
        if step is not None:
            if step > duration:
                raise ParameterError(f"`{name}` ({step!r} s) must not exceed `duration` "
                                     f"({duration!r} s).")
            steps_per_sample(sample_rate, step, "sample_rate")  # a whole number of steps
    from qzs.engine.run_spec import check_length

    check_length(duration, sample_rate, dt, kernel="hexapod")  # before any process starts
    n_samples = int(round(duration * sample_rate)) + 1
    if fft_length is None:
        fft_length = _default_fft_length(n_samples, defaults.ANALYSIS["quick_fft_length"])
    fft_length = integer("fft_length", fft_length, 8)
    if fft_length > n_samples:
        raise ParameterError(f"`fft_length` ({fft_length} samples) exceeds the run's "
                             f"{n_samples} samples ({duration:g} s at {sample_rate:g} Hz); "
                             "lower it or lengthen `duration`.")
    estimator = choice("estimator", estimator, ESTIMATORS)
    floor_db = real("floor_db", floor_db)
    if not floor_db < 0:
        raise ParameterError(f"`floor_db` must be negative (a level below the base motion) "
                             f"[dB], got {floor_db!r}.")
    if workers is not None:
        workers = integer("workers", workers, 1)
    if not isinstance(progress, (bool, np.bool_)):
        raise ParameterError(f"`progress` must be True or False, got {progress!r}.")
    from qzs.model.controller import refuse_blocks

    controllers = getattr(setup, "controllers", setup.controller)
    refuse_blocks(controllers, "the transmissibility matrix's linear overlay "
                  "(hexapod_linearize)", "simulate a platform whose legs have blocks with "
                  "`qzs hexapod simulate` (docs/hexapod.md §9.5a), or leave the blocks out of "
                  "[controller] and [legs.N.controller]")
    stable = _stable(setup, controllers, solver)
    step = dt if dt is not None else setup_dt
    if not stable(step):
        from qzs.errors import StabilityError

        which = "`dt`" if dt is not None else "the set-up's [simulation] dt"
        raise StabilityError(f"{which} ({step!r} s) is too large for a stable {solver} "
                             "integration of this hexapod (a leg's stop contact or loop on "
                             "the lightest mass the legs move); reduce it.")
    chirps = {}
    for axis in axes:
        try:
            chirps[axis] = Chirp(amplitude=amplitudes[axis], f0=f0, f1=f1, duration=duration)
        except ValueError as error:
            raise ParameterError(f"the chirp of axis {axis!r}: {error}") from None
    common = dict(f0=f0, f1=f1, duration=duration, sample_rate=sample_rate, solver=solver,
                  fft_length=fft_length, overlap=defaults.ANALYSIS["overlap"],
                  estimator=estimator, coherence_min=defaults.ANALYSIS["coherence_min"],
                  base_share_min=defaults.ANALYSIS["base_share_min"], floor_db=floor_db,
                  platform_size=platform_size(setup.geometry),
                  trusted_from=sweep_trusted_from(f0, f1, duration, fft_length, sample_rate),
                  tolerance_db=tolerance_db, setup_dt=setup_dt,
                  dt=dt, frame="top frame origin (the cube's centre of a cubic geometry)")
    fields = {name: common[name] for name in _RUN_SETTINGS}
    runs = [AxisRun(axis=axis, excitation=chirps[axis], geometry=setup.geometry,
                    platform=setup.platform, isolator=setup.isolator, controller=controllers,
                    cartesian=getattr(setup, "cartesian", None), **fields) for axis in axes]
    return axes, amplitudes, common, runs, workers


#: The runs' common settings each :class:`AxisRun` carries.
_RUN_SETTINGS = ("f0", "f1", "duration", "sample_rate", "solver", "fft_length", "overlap",
                 "estimator", "coherence_min", "base_share_min", "tolerance_db", "setup_dt",
                 "dt")


def _dry_run(run):
    """One step of the first run: the engine checks the set-up before any long run."""
    from qzs.engine.hexapod import simulate_hexapod

    step = run.dt or run.setup_dt
    simulate_hexapod(run.geometry, run.platform, run.isolator, run.controller,
                     excitation={run.axis: run.excitation}, duration=step, dt=step,
                     sample_rate=run.sample_rate, solver=run.solver, **run.control)
