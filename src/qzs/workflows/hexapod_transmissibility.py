"""The simulated 6x6 transmissibility of a hexapod: one chirp per excited base axis.

Column ``j`` of the matrix comes from a run whose base moves along axis ``j`` alone
(x, y, z [m]; rx, ry, rz [rad]): each platform axis ``i`` is reduced against it by the
single axis's Welch estimator (:func:`qzs.analysis.spectral.transmissibility`, ``H1`` by
default), from the base point's velocity ``base_velocity[:, j]`` to the platform's twist
``platform_twist[:, i]`` (docs/hexapod.md §9.3). Both are taken at the top frame origin
(the cube's centre of a cubic geometry), the point :func:`qzs.analysis.hexapod_linear.
hexapod_linearize` calls ``frame="origin"``, so its transmissibility is the linear
overlay. A ratio of velocities is the ratio of displacements or accelerations; velocities
are used because a constant-displacement chirp's base velocity holds more of its power at
low frequency than its acceleration does.

**Trusted entries** (docs/hexapod.md §10.2). Each entry keeps its coherence and the single
axis's trusted bins (docs/model.md §10); bins below the frequency the chirp reaches a
quarter segment into the run are untrusted (:func:`sweep_trusted_from`: one segment holds
them, under its rising taper, so their coherence is 1 by construction); and an entry is
untrusted where its response is below a numerical floor (``floor_db``, -100 dB by
default) of the base motion. The floor is needed: the
cross-axis entries of a symmetric platform are zero in exact arithmetic, and what the
run gives there is rounding (1e-16 to 1e-7 of the base motion, amplified by the Stribeck
friction's negative slope), which is as deterministic as the chirp, so its coherence can
reach 0.99 in a few bins. The floor compares dimensionless magnitudes: a rotation is
turned into a length by the platform's size ``r`` (the top joints' RMS distance from their
centroid), so a rotation per translation counts as ``|T| r`` and a translation per
rotation as ``|T| / r``.

**Integration step.** Where ``dt`` is not given, each run's step is chosen by the method of
:func:`qzs.engine.accuracy.choose_step` (docs/model.md §7) applied to the hexapod: the
probe of :func:`~qzs.engine.accuracy.probe_excitation`, steps halved from the largest
stable one that divides the output period down to the set-up's ``dt``, the excited axis's
diagonal entry compared between successive steps over its trusted bins, the error
extrapolated with the observed ratio (capped at the scheme's order), a safety factor of 2
against the tolerance ``ACCURACY["tolerance_db"]``. Where no step coarser than the set-up's
meets it (stick-slip whose pattern changes with the step, so that the differences do not
shrink), the run takes the set-up's ``dt`` and its record says why.
"""
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from qzs import defaults
from qzs._format import decibels, number
from qzs._validation import as_float, choice, integer, positive, worker_count
from qzs.analysis.hexapod_linear import entry_unit
from qzs.defaults import AXES, AXIS_UNITS
from qzs.errors import ParameterError
from qzs.iotools.schema import Schema, Variable, to_dataset

__all__ = ["HexapodTransmissibility", "hexapod_transmissibility", "AMPLITUDE", "CHIRP",
           "FLOOR_DB", "ESTIMATORS", "transmissibility_summary", "transmissibility_dataset",
           "transmissibility_record", "choose_hexapod_step", "sweep_trusted_from",
           "platform_size", "entry_unit", "transmissibility_schema"]

#: Default chirp amplitude per base axis: 2 mm in translation [m], 0.01 rad in rotation
#: [rad] (1.2 mm at the top joints of the 0.15 m cube).
AMPLITUDE = MappingProxyType({"x": 0.002, "y": 0.002, "z": 0.002,
                              "rx": 0.01, "ry": 0.01, "rz": 0.01})
#: Default chirp: start and end frequency [Hz] and sweep time [s] (a linear sweep, as the
#: paper's, over its band; 200 s gives 11 half-overlapping Welch segments of 32768 samples
#: at 1 kHz).
CHIRP = MappingProxyType({"f0": 0.0, "f1": 20.0, "duration": 200.0})
#: Numerical floor of a trusted entry [dB]: the dimensionless response relative to the
#: base motion (see the module docstring).
FLOOR_DB = -100.0
#: Welch estimators with a phase (the matrix is complex).
ESTIMATORS = ("h1", "h2")
#: Welch segments a run averages at least when ``fft_length`` is not given.
MIN_SEGMENTS = 8


def platform_size(geometry):
    """The length [m] that makes a rotation comparable with a translation.

    The top joints' RMS distance from their centroid (what :class:`~qzs.model.hexapod.
    HexapodGeometry` scales its Jacobian's rotation columns by), or the mean leg length
    if the joints coincide.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform.

    Returns
    -------
    float
        [m].
    """
    joints = np.asarray(geometry.top_joints, dtype=float)
    spread = float(np.sqrt(np.mean(np.sum((joints - joints.mean(axis=0)) ** 2, axis=1))))
    return spread if spread > 0 else float(np.mean(geometry.home_lengths))


def _scale(size):
    """(6, 6) factors turning ``|T|`` into a dimensionless response (rotations times ``size``)."""
    length = np.array([1.0, 1.0, 1.0, size, size, size])
    return length[:, None] / length[None, :]


@dataclass(frozen=True, kw_only=True, eq=False)
class HexapodTransmissibility:
    """The simulated 6x6 transmissibility of a hexapod (:func:`hexapod_transmissibility`).

    Entry ``[:, i, j]`` is platform axis ``i`` per base axis ``j`` (``x, y, z`` [m], ``rx,
    ry, rz`` [rad]) at the top frame origin: [-] on the diagonal blocks, [m/rad] for a
    translation per rotation, [rad/m] for a rotation per translation. Columns of base axes
    that were not excited are NaN (``trusted`` False). The object holds data; its methods
    delegate to this module's functions, :mod:`qzs.viz.hexapod_matrix` and
    :mod:`qzs.iotools.files`.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Welch bin frequencies [Hz], from 0 to the chirp's end ``f1`` (above it the base
        put no power).
    response : ndarray of complex, shape (n, 6, 6)
        The estimate (``H1`` or ``H2``) [1, m/rad, rad/m]; NaN in columns not excited.
    coherence : ndarray, shape (n, 6, 6)
        Magnitude-squared coherence of base axis ``j`` and platform axis ``i`` [-].
    trusted : ndarray of bool, shape (n, 6, 6)
        Bins that may be read: the single axis's trusted bins (docs/model.md §10), not
        ``below_floor``, and at or above ``settings["trusted_from"]`` (the sweep's start).
    below_floor : ndarray of bool, shape (n, 6, 6)
        Bins whose dimensionless response is below ``settings["floor_db"]`` of the base
        motion: rounding, not a response, whatever their coherence.
    linear_response : ndarray of complex, shape (n, 6, 6)
        :meth:`HexapodLinearModel.transmissibility` at ``frequency`` (NaN at 0 Hz), the
        linear model at the top frame origin, every column.
    linear_stable : bool
        Whether the linear model's closed loop is asymptotically stable; if not, its
        frequency response is not a steady state anything reaches.
    linear_natural_frequencies : ndarray, shape (6,)
        Its undamped natural frequencies [Hz]; NaN for a statically unstable direction.
    linear_notes : tuple of str
        What the linearisation says about unstable directions.
    excited_axes : tuple of str
        The base axes excited, in the order of :data:`AXES`.
    amplitude : mapping
        Chirp amplitude per excited axis [m, rad] (translations, rotations).
    energy_residual : mapping
        Per excited axis, the run's largest energy-ledger imbalance divided by its largest
        ``|base work|`` [-] (docs/hexapod.md §9.6).
    runs : mapping
        Per excited axis, the run's record: ``dt`` [s] and ``step`` (how it was chosen),
        ``step_error_db`` (the accuracy estimate, if any), ``steps``, ``events``,
        ``elapsed`` [s], ``locked_fraction`` [-] per leg, ``stop_contacts`` and
        ``stick_events`` per leg, ``stroke_used`` [m] per leg, ``energy_residual`` [J],
        ``base_work_max`` [J], ``n_averages``, ``seconds`` (wall time of the run and its
        reduction) [s].
    settings : mapping
        ``f0``, ``f1`` [Hz], ``duration`` [s], ``sample_rate`` [Hz], ``solver``,
        ``fft_length`` [samples], ``overlap`` [-], ``estimator``, ``coherence_min``,
        ``base_share_min`` [-], ``floor_db`` [dB], ``platform_size`` [m],
        ``trusted_from`` [Hz] (:func:`sweep_trusted_from`), ``tolerance_db`` [dB],
        ``setup_dt`` [s], ``dt`` [s] (None: chosen per run) and ``frame`` (where the
        axes are).
    setup : HexapodSetup
        The platform simulated.
    """

    frequency: np.ndarray
    response: np.ndarray
    coherence: np.ndarray
    trusted: np.ndarray
    below_floor: np.ndarray
    linear_response: np.ndarray
    linear_stable: bool
    linear_natural_frequencies: np.ndarray
    linear_notes: tuple
    excited_axes: tuple
    amplitude: MappingProxyType
    energy_residual: MappingProxyType
    runs: MappingProxyType
    settings: MappingProxyType
    setup: object = field(repr=False)

    @property
    def magnitude(self):
        """``|response|`` [1, m/rad, rad/m], shape (n, 6, 6); NaN in columns not excited."""
        return np.abs(self.response)

    @property
    def excited(self):
        """Which base axes were excited, one flag per axis of :data:`AXES` [-]."""
        return np.array([axis in self.excited_axes for axis in AXES])

    def to_xarray(self):
        """Repackage as an ``xarray.Dataset`` (:func:`transmissibility_dataset`).

        Dimensions ``frequency`` [Hz], ``output_dof`` and ``input_dof`` (``x … rz``);
        units in the attributes.

        Returns
        -------
        xarray.Dataset
        """
        return transmissibility_dataset(self)

    def plot(self, out=None, *, title=None):
        """The 6x6 grid with the linear model dashed (:func:`qzs.viz.hexapod_matrix.
        plot_transmissibility_matrix`); columns not excited are left empty.

        Parameters
        ----------
        out : str or Path, optional
            Write the figure there (atomically; format from the suffix).
        title : str, optional
            Figure title; default one naming the platform and the run settings.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.hexapod_matrix import plot_transmissibility_matrix

        return plot_transmissibility_matrix(
            self.frequency, linear=np.abs(self.linear_response), simulated=self.magnitude,
            trusted=self.trusted, excited=self.excited, frequency_range=_plot_range(self),
            title=title or default_title(self), out=out,
            linear_label=None if self.linear_stable else "linear model (UNSTABLE loop)",
            untrusted_below=self.settings["trusted_from"])

    def save(self, path):
        """Write :meth:`to_xarray` as NetCDF (h5netcdf), atomically.

        Parameters
        ----------
        path : str or Path
            The file; must end in ``.nc``.

        Returns
        -------
        Path
            ``path``.
        """
        from qzs.iotools.files import atomic_path

        path = Path(path)
        if path.suffix.lower() != ".nc":
            raise ParameterError(f"`path` must end in .nc (NetCDF), got {str(path)!r}.")
        with atomic_path(path) as tmp:
            self.to_xarray().to_netcdf(tmp, engine="h5netcdf")
        return path

    def summary(self):
        """One-screen text (:func:`transmissibility_summary`).

        Returns
        -------
        str
        """
        return transmissibility_summary(self)


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
        number = as_float(f"amplitude[{axis!r}]", value)
        if not number > 0:
            raise ParameterError(f"`amplitude[{axis!r}]` must be a positive amplitude [{unit}], "
                                 f"got {value!r}.")
        values[axis] = number
    return values


def _optional_positive(name, value):
    return None if value is None else positive(name, value)


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
          estimator, floor_db, workers, progress):
    """Check every argument; the runs' common settings and one task per axis."""
    from qzs.model.excitation import Chirp
    from qzs.workflows.hexapod import HexapodSetup

    if not isinstance(setup, HexapodSetup):
        raise ParameterError(f"`setup` must be a HexapodSetup (qzs.workflows.hexapod."
                             f"load_hexapod or hexapod_setup), got {type(setup).__name__}.")
    axes = _axes(axes)
    amplitudes = _amplitudes(amplitude, axes)
    f0 = as_float("f0", f0)
    f1 = as_float("f1", f1)
    if not 0 <= f0 < f1:
        raise ParameterError(f"the chirp must rise: 0 <= `f0` < `f1` [Hz], got f0={f0!r}, "
                             f"f1={f1!r}.")
    duration = positive("duration", duration)
    sample_rate = positive("sample_rate", sample_rate if sample_rate is not None else
                           setup.simulation.get("sample_rate",
                                                defaults.SIMULATION["sample_rate"]))
    if f1 >= 0.5 * sample_rate:
        raise ParameterError(f"`f1` ({f1:g} Hz) must lie below the output's Nyquist frequency "
                             f"{0.5 * sample_rate:g} Hz; raise `sample_rate` or lower `f1`.")
    solver = choice("solver", solver if solver is not None else
                    setup.simulation.get("solver", defaults.SIMULATION["solver"]),
                    ("ode3", "rk4", "euler"))
    setup_dt = positive("the set-up's [simulation] dt",
                        setup.simulation.get("dt", defaults.SIMULATION["dt"]))
    dt = _optional_positive("dt", dt)
    from qzs.engine.prepare import steps_per_sample

    for name, step in (("dt", dt), ("the set-up's [simulation] dt", setup_dt)):
        if step is not None:
            if step > duration:
                raise ParameterError(f"`{name}` ({step!r} s) must not exceed `duration` "
                                     f"({duration!r} s).")
            steps_per_sample(sample_rate, step, "sample_rate")  # a whole number of steps
    n_samples = int(round(duration * sample_rate)) + 1
    if fft_length is None:
        fft_length = _default_fft_length(n_samples, defaults.ANALYSIS["quick_fft_length"])
    fft_length = integer("fft_length", fft_length, 8)
    if fft_length > n_samples:
        raise ParameterError(f"`fft_length` ({fft_length} samples) exceeds the run's "
                             f"{n_samples} samples ({duration:g} s at {sample_rate:g} Hz); "
                             "lower it or lengthen `duration`.")
    estimator = choice("estimator", estimator, ESTIMATORS)
    floor_db = as_float("floor_db", floor_db)
    if not floor_db < 0:
        raise ParameterError(f"`floor_db` must be negative (a level below the base motion) "
                             f"[dB], got {floor_db!r}.")
    if workers is not None:
        workers = integer("workers", workers, 1)
    if not isinstance(progress, (bool, np.bool_)):
        raise ParameterError(f"`progress` must be True or False, got {progress!r}.")
    stable = _stable(setup, setup.controller, solver)
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
                  tolerance_db=defaults.ACCURACY["tolerance_db"], setup_dt=setup_dt,
                  dt=dt, frame="top frame origin (the cube's centre of a cubic geometry)")
    tasks = [dict(axis=axis, excitation=chirps[axis], geometry=setup.geometry,
                  platform=setup.platform, isolator=setup.isolator,
                  controller=setup.controller, cartesian=getattr(setup, "cartesian", None),
                  **common) for axis in axes]
    return axes, amplitudes, common, tasks, workers


def _dry_run(task):
    """One step of the first run: the engine checks the set-up before any long run."""
    from qzs.engine.hexapod import simulate_hexapod

    step = task["dt"] or task["setup_dt"]
    simulate_hexapod(task["geometry"], task["platform"], task["isolator"], task["controller"],
                     excitation={task["axis"]: task["excitation"]}, duration=step, dt=step,
                     sample_rate=task["sample_rate"], solver=task["solver"],
                     **_control(task))


def _control(task):
    """The centralised controller keyword, where the set-up has one."""
    return {} if task.get("cartesian") is None else {"cartesian": task["cartesian"]}


# ---------------------------------------------------------------- one run
def _estimate(result, axis, task, outputs=range(6)):
    """Welch estimates of platform axes ``outputs`` per base axis ``axis`` of a run."""
    from qzs.analysis.spectral import transmissibility

    j = AXES.index(axis)
    base = result["base_velocity"][:, j]
    twist = result["platform_twist"]
    return {i: transmissibility(base, twist[:, i], task["sample_rate"],
                                fft_length=task["fft_length"], overlap=task["overlap"],
                                estimator=task["estimator"],
                                coherence_min=task["coherence_min"],
                                base_share_min=task["base_share_min"])
            for i in outputs}


def _simulate(task, excitation, dt, duration):
    from qzs.engine.hexapod import simulate_hexapod

    return simulate_hexapod(task["geometry"], task["platform"], task["isolator"],
                            task["controller"], excitation={task["axis"]: excitation},
                            duration=duration, dt=dt, sample_rate=task["sample_rate"],
                            solver=task["solver"], **_control(task))


def choose_hexapod_step(task):
    """The accuracy-driven step of one run (see the module docstring), or the set-up's.

    Parameters
    ----------
    task : dict
        One run's task (:func:`hexapod_transmissibility` builds them).

    Returns
    -------
    dt : float
        The step [s].
    record : dict
        ``step`` (``"accuracy-driven"`` or ``"set-up"``), ``step_error_db`` (the
        estimate at the chosen step, NaN for the set-up's), ``step_history``
        (``(dt, difference to the next finer step [dB])`` per step tried) and
        ``step_reason``.
    """
    from qzs.engine.accuracy import SAFETY, admissible_step, halving_search, probe_excitation
    from qzs.engine.stability import SOLVERS

    excitation = task["excitation"]
    rate, solver = task["sample_rate"], task["solver"]
    order = SOLVERS[solver][1]
    band = (min(1.0, 0.5 * task["f1"]) if task["f0"] == 0 else task["f0"], task["f1"])
    probe, duration = probe_excitation(excitation, band)
    finest = task["setup_dt"]
    try:
        dt0, _ = admissible_step(rate, task["controller"].controller_rate,
                                 _stable_from_task(task))
    except ParameterError:
        dt0 = finest
    candidates = [dt0 / 2 ** j for j in range(12) if dt0 / 2 ** j >= finest * (1 - 1e-9)]
    j_axis = AXES.index(task["axis"])
    probe_task = dict(task, fft_length=_default_fft_length(int(round(duration * rate)) + 1))
    estimates = {}

    def estimate(j):
        if j not in estimates:
            run = _simulate(task, probe, candidates[j], duration)
            estimates[j] = _estimate(run, task["axis"], probe_task, (j_axis,))[j_axis]
        return estimates[j]

    def difference(j):
        a, b = estimate(j), estimate(j + 1)
        keep = ((a.frequency >= band[0]) & (a.frequency <= band[1]) & a.trusted & b.trusted
                & (a.magnitude > 0) & (b.magnitude > 0))
        if not keep.any():
            return math.nan
        return float(np.max(np.abs(decibels(a.magnitude[keep] / b.magnitude[keep]))))

    chosen, searched = (None, []) if len(candidates) < 3 else halving_search(
        difference, order, task["tolerance_db"], dt0, len(candidates) - 1, SAFETY)
    history = tuple((dt, d) for dt, d, _ in searched)
    if chosen is not None:
        error = searched[chosen][2]
        return candidates[chosen], dict(
            step="accuracy-driven", step_error_db=error, step_history=history,
            step_reason=f"estimated error {error:.3g} dB <= {task['tolerance_db']:g} dB / "
                        f"{SAFETY:g} on a {duration:g} s probe")
    if len(candidates) < 3:
        reason = (f"fewer than three steps between the largest stable one and the set-up's "
                  f"({finest:g} s) to compare")
    elif len(searched) < len(candidates) - 2 and not np.isfinite(difference(len(searched))):
        reason = "no bin of the probe's band is trusted in both runs"
    else:
        shown = ", ".join(f"{d:.3g}" for _, d in history)
        reason = (f"no step coarser than the set-up's met {task['tolerance_db']:g} dB: the "
                  f"differences between successive halvings ({shown} dB) do not shrink as the "
                  "scheme's order predicts (the stick-slip pattern changes with the step)")
    return finest, dict(step="set-up", step_error_db=math.nan, step_history=history,
                        step_reason=reason)


def _stable_from_task(task):
    from qzs.workflows.hexapod import HexapodSetup

    setup = HexapodSetup(geometry=task["geometry"], platform=task["platform"],
                         isolator=task["isolator"], controller=task["controller"])
    return _stable(setup, task["controller"], task["solver"])


def run_axis(task):
    """Run one axis's chirp and reduce it to its column (top level: process pools call it).

    Parameters
    ----------
    task : dict
        One run's task.

    Returns
    -------
    dict
        ``axis``, ``frequency`` [Hz], ``response`` (6, n) complex, ``coherence`` (6, n),
        ``trusted`` (6, n), ``record`` (the run's record, see
        :attr:`HexapodTransmissibility.runs`).
    """
    start = time.perf_counter()
    if task["dt"] is not None:
        dt, record = task["dt"], dict(step="given", step_error_db=math.nan, step_history=(),
                                      step_reason="given by the caller")
    else:
        dt, record = choose_hexapod_step(task)
    result = _simulate(task, task["excitation"], dt, task["duration"])
    estimates = _estimate(result, task["axis"], task)
    first = estimates[0]
    response = np.array([e.magnitude * np.exp(1j * e.phase) for e in estimates.values()])
    residual = result.energy_residual()
    work = float(np.max(np.abs(result["base_work"])))
    z = result["relative_position"]
    center = np.array([0.5 * (low + high) for low, high in result.run["stops"]])
    record.update(dt=float(dt), steps=int(result.run["steps"]),
                  events=int(result.run["events"]), elapsed=float(result.run["elapsed"]),
                  locked_fraction=np.mean(result["locked"], axis=0),
                  stop_contacts=np.array(result.run["stop_contacts"]),
                  stick_events=np.array(result.run["stick_events"]),
                  stroke_used=np.max(np.abs(z - center), axis=0),
                  stroke_half=float(task["geometry"].stroke_half),
                  energy_residual=float(np.max(np.abs(residual))), base_work_max=work,
                  n_averages=int(first.n_averages),
                  relative_pose_max=np.max(np.abs(result["platform_pose"]
                                                  - result["base_pose"]), axis=0))
    record["seconds"] = time.perf_counter() - start
    return dict(axis=task["axis"], frequency=first.frequency, response=response,
                coherence=np.array([e.coherence for e in estimates.values()]),
                trusted=np.array([e.trusted for e in estimates.values()]), record=record)


# ---------------------------------------------------------------- the matrix
def hexapod_transmissibility(setup, *, axes=AXES, amplitude=None, f0=CHIRP["f0"],
                             f1=CHIRP["f1"], duration=CHIRP["duration"], dt=None,
                             sample_rate=None, solver=None, fft_length=None, estimator="h1",
                             floor_db=FLOOR_DB, workers=None, progress=True):
    """Simulate one chirp per base axis and estimate the 6x6 transmissibility matrix.

    Each axis of ``axes`` is one run of :func:`qzs.engine.hexapod.simulate_hexapod` with
    the base moving along that axis alone (a linear chirp of constant displacement
    amplitude from ``f0`` to ``f1``); column ``j`` of the matrix is the single-axis Welch
    estimate from ``base_velocity[:, j]`` to ``platform_twist[:, i]`` for every platform
    axis ``i``, with its coherence and trusted bins (see the module docstring for the
    numerical floor). The runs go in parallel processes, one per axis. Every argument is
    checked before any run; then one integration step of the first run lets the engine
    check the set-up itself.

    Parameters
    ----------
    setup : HexapodSetup
        The platform (:func:`qzs.workflows.hexapod.load_hexapod`, ``hexapod_setup``).
    axes : sequence of str or str
        Base axes to excite (``"x", "y", "z"`` [m], ``"rx", "ry", "rz"`` [rad]), or one
        comma-separated string (``"z,x"``); each is one run. Default all six.
    amplitude : float or mapping, optional
        Chirp displacement amplitude: one number for every excited axis (all translations
        [m] or all rotations [rad]), or ``{axis: amplitude}``. Default per axis
        :data:`AMPLITUDE`: 0.002 m in translation, 0.01 rad in rotation.
    f0, f1 : float
        Chirp start and end frequency [Hz], ``0 <= f0 < f1`` below the Nyquist frequency;
        default 0 and 20 (the paper's band).
    duration : float
        Sweep time and run length [s]; default 200.
    dt : float, optional
        Integration step [s]. Default: accuracy-driven per run (module docstring),
        falling back to the set-up's ``[simulation] dt`` (1e-4 s if it gives none); each
        run's record says which.
    sample_rate : float, optional
        Output rate [Hz]; default the set-up's, else 1000.
    solver : {"ode3", "rk4", "euler"}, optional
        Integrator; default the set-up's, else ode3.
    fft_length : int, optional
        Welch segment length [samples]; default the power of two giving at least 8
        half-overlapping segments, at most 16384 (bins of 0.061 Hz at 1 kHz).
    estimator : {"h1", "h2"}
        ``H1 = S_bp/S_bb`` (default; unbiased by noise on the platform's motion) or
        ``H2 = S_pp/S_pb``.
    floor_db : float
        Numerical floor [dB] below which an entry is untrusted whatever its coherence
        (negative; default -100).
    workers : int, optional
        Processes running the axes at once; default the machine's cores. 1 runs them
        one after another in this process.
    progress : bool
        Show a progress bar over the runs.

    Returns
    -------
    HexapodTransmissibility

    Raises
    ------
    ParameterError
        An invalid argument (named, with its value and the fix), before any run; the
        engine's own errors for the set-up after one step.
    StabilityError
        ``dt`` (or the set-up's) beyond the largest stable step.
    SimulationError
        A run diverged.
    """
    axes, amplitudes, common, tasks, workers = _plan(
        setup, axes, amplitude, f0, f1, duration, dt, sample_rate, solver, fft_length,
        estimator, floor_db, workers, progress)
    from tqdm.auto import tqdm

    _dry_run(tasks[0])
    workers = worker_count(workers, len(tasks))
    columns = {}
    bar = tqdm(total=len(tasks), unit="run", desc="hexapod chirps", disable=not progress)
    try:
        if workers == 1:
            for task in tasks:
                columns[task["axis"]] = run_axis(task)
                bar.update()
        else:
            from concurrent.futures import ProcessPoolExecutor, as_completed

            with ProcessPoolExecutor(max_workers=workers) as pool:
                futures = [pool.submit(run_axis, task) for task in tasks]
                try:
                    for future in as_completed(futures):
                        column = future.result()
                        columns[column["axis"]] = column
                        bar.update()
                except BaseException:
                    for future in futures:
                        future.cancel()
                    raise
    finally:
        bar.close()
    return _assemble(setup, axes, amplitudes, common, columns)


def _assemble(setup, axes, amplitudes, common, columns):
    """The result object from the columns of the runs."""
    from qzs.analysis.hexapod_linear import hexapod_linearize

    frequency = columns[axes[0]]["frequency"]
    keep = frequency <= common["f1"]  # above the sweep the base put no power
    frequency = frequency[keep]
    n = frequency.size
    response = np.full((n, 6, 6), np.nan + 0j)
    coherence = np.full((n, 6, 6), np.nan)
    trusted = np.zeros((n, 6, 6), dtype=bool)
    for axis, column in columns.items():
        j = AXES.index(axis)
        response[:, :, j] = column["response"].T[keep]
        coherence[:, :, j] = column["coherence"].T[keep]
        trusted[:, :, j] = column["trusted"].T[keep]
    floor = 10 ** (common["floor_db"] / 20)
    with np.errstate(invalid="ignore"):
        below = (np.abs(response) * _scale(common["platform_size"])[None] < floor) & np.isfinite(
            np.abs(response))
    trusted &= ~below
    trusted &= (frequency >= common["trusted_from"])[:, None, None]
    cartesian = getattr(setup, "cartesian", None)
    model = hexapod_linearize(setup.geometry, setup.platform, setup.isolator, setup.controller,
                              frame="origin",
                              **({} if cartesian is None else {"cartesian": cartesian}))
    linear = np.full((n, 6, 6), np.nan + 0j)
    positive_bins = frequency > 0
    linear[positive_bins] = model.transmissibility(frequency[positive_bins])
    runs = {axis: MappingProxyType(columns[axis]["record"]) for axis in axes}
    residual = {axis: columns[axis]["record"]["energy_residual"]
                / max(columns[axis]["record"]["base_work_max"], 1e-300) for axis in axes}
    for array in (frequency, response, coherence, trusted, below, linear):
        array.setflags(write=False)
    return HexapodTransmissibility(
        frequency=frequency, response=response, coherence=coherence, trusted=trusted,
        below_floor=below, linear_response=linear, linear_stable=bool(model.stable),
        linear_natural_frequencies=np.asarray(model.natural_frequencies, dtype=float),
        linear_notes=tuple(model.notes), excited_axes=axes,
        amplitude=MappingProxyType(dict(amplitudes)),
        energy_residual=MappingProxyType(residual), runs=MappingProxyType(runs),
        settings=MappingProxyType(dict(common)), setup=setup)


# ---------------------------------------------------------------- views
def _plot_range(result):
    low = max(result.settings["f0"], 0.05, float(result.frequency[1]))
    return (low, result.settings["f1"])


def default_title(result):
    """The grid's default title: platform, chirps, where the step came from.

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    str
    """
    setup, s = result.setup, result.settings
    steps = sorted({f"{r['dt']:g} s ({r['step']})" for r in result.runs.values()})
    loop = ("centralised loops" if getattr(setup, "cartesian", None) is not None else
            f"Kp {setup.controller.pi_kp:g} N/m, Ki {setup.controller.pi_ki:g} N/(m s)")
    return (f"Simulated transmissibility of the {setup.kind} hexapod, platform "
            f"{setup.platform.mass:.3g} kg, {loop}: chirps {s['f0']:g}-{s['f1']:g} Hz over "
            f"{s['duration']:g} s in {', '.join(result.excited_axes)}; dt {', '.join(steps)}\n"
            "platform axis per base axis at the top frame origin, |T| in dB of its unit; "
            "solid: trusted bins, faint: untrusted, dashed: linear model; grey band: the "
            "sweep's start, untrusted")


def transmissibility_summary(result):
    """The text of :meth:`HexapodTransmissibility.summary`.

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    str
    """
    s = result.settings
    lines = [f"Hexapod transmissibility: {result.setup.kind} platform "
             f"{result.setup.platform.mass:.4g} kg; chirps {s['f0']:g}-{s['f1']:g} Hz, "
             f"{s['duration']:g} s, in {', '.join(result.excited_axes)}; {s['estimator'].upper()} "
             f"Welch estimate, {s['fft_length']} samples per segment at {s['sample_rate']:g} Hz",
             "  linear model: natural frequencies "
             + ", ".join(number(f, undefined="unstable") for f in result.linear_natural_frequencies)
             + " Hz" + ("" if result.linear_stable else "; the loop is UNSTABLE"),
             "",
             "run  amplitude      dt [s]   step             locked [%]  stop contacts  "
             "stroke used [mm]  ledger closure [-]"]
    for axis in result.excited_axes:
        r = result.runs[axis]
        unit = AXIS_UNITS[AXES.index(axis)]
        lines.append(f"{axis:<4} {result.amplitude[axis]:8.3g} {unit:<4} {r['dt']:9.3g}   "
                     f"{r['step']:<16} {100 * float(np.mean(r['locked_fraction'])):10.1f}  "
                     f"{int(np.sum(r['stop_contacts'])):13d}  "
                     f"{1e3 * float(np.max(r['stroke_used'])):16.2f}  "
                     f"{result.energy_residual[axis]:18.2g}")
    lines += ["", "entry (platform/base)  trusted bins  coherence median  peak |T| (trusted) "
                  "at [Hz]   linear there"]
    magnitude = result.magnitude
    for axis in result.excited_axes:
        j = AXES.index(axis)
        for i in range(6):
            ok = result.trusted[:, i, j]
            head = f"  {AXES[i]:>2} / {axis:<2} [{entry_unit(i, j)}]"
            median = float(np.nanmedian(result.coherence[1:, i, j]))
            if not ok.any():
                lines.append(f"{head:<24}{0:>10}  {median:16.3g}  untrusted everywhere")
                continue
            k = int(np.flatnonzero(ok)[np.argmax(magnitude[ok, i, j])])
            lines.append(f"{head:<24}{int(ok.sum()):>10}  {median:16.3g}  "
                         f"{magnitude[k, i, j]:10.3g} at {result.frequency[k]:6.3g}   "
                         f"{abs(result.linear_response[k, i, j]):10.3g}")
    for note in result.linear_notes:
        lines.append(f"  note: {note}")
    for axis in result.excited_axes:
        r = result.runs[axis]
        if r["step"] != "given":
            lines.append(f"  step of the {axis} run: {r['step']} ({r['step_reason']})")
    return "\n".join(lines)


def transmissibility_record(result):
    """The matrix's summary as data (``qzs hexapod transmissibility --json``).

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    dict
        ``summary`` (text), ``excited_axes``, ``amplitude`` [m or rad], ``settings``,
        ``runs`` (per axis: ``dt`` [s], ``step``, ledger, legs), ``energy_residual`` [-],
        ``linear_stable``, ``linear_natural_frequencies`` [Hz], ``trusted_bins`` (count
        per entry ``"output/input"`` of the excited columns), ``source`` (the set-up's
        file).
    """
    return {"summary": transmissibility_summary(result),
            "excited_axes": list(result.excited_axes), "amplitude": dict(result.amplitude),
            "settings": dict(result.settings),
            "runs": {axis: dict(run) for axis, run in result.runs.items()},
            "energy_residual": dict(result.energy_residual),
            "linear_stable": result.linear_stable,
            "linear_natural_frequencies": result.linear_natural_frequencies,
            "trusted_bins": {f"{AXES[i]}/{axis}": int(result.trusted[:, i, AXES.index(axis)]
                                                      .sum())
                             for axis in result.excited_axes for i in range(6)},
            "source": result.setup.source}


def transmissibility_schema(estimator="h1"):
    """The CF-1.10 layout (a ``Schema``) of :func:`transmissibility_dataset`.

    Parameters
    ----------
    estimator : str
        The estimator, named in the magnitude's ``long_name``.
    """
    mixed = ("1 on the diagonal blocks, m/rad for a translation per rotation, rad/m for a "
             "rotation per translation (see entry_units)")
    on = ("frequency", "output_dof", "input_dof")
    flag = ("units", "long_name", "flag_meanings", "flag_values")
    dof_doc = "degree of freedom: translations x, y, z [m], rotations rx, ry, rz [rad]"
    variables = (
        Variable(name="magnitude", dims=on, units=mixed,
                 long_name=f"|{estimator.upper()}| platform motion per base motion"),
        Variable(name="phase", dims=on, units="rad",
                 long_name="phase of the platform motion relative to the base's"),
        Variable(name="coherence", dims=on, units="1",
                 long_name="magnitude-squared coherence of base and platform axis"),
        Variable(name="trusted", dims=on, units="1", dtype="int8", order=flag,
                 long_name="1 where the bin may be read (docs/model.md section 10 and the "
                           "numerical floor)", flag_meanings="untrusted trusted"),
        Variable(name="below_floor", dims=on, units="1", dtype="int8", order=flag,
                 long_name="1 where the dimensionless response is below the numerical floor "
                           "(rounding, not response)", flag_meanings="above below"),
        Variable(name="linear_magnitude", dims=on, units=mixed,
                 long_name="|T| of the linear model at the top frame origin"),
        Variable(name="linear_phase", dims=on, units="rad", long_name="phase of the linear model"),
        Variable(name="entry_units", dims=on[1:], dtype="str",
                 long_name="unit of each matrix entry"),
        Variable(name="excited", dims=on[2:], units="1", dtype="int8", order=flag, long_name=(
            "1 where the base axis was excited"), flag_meanings="not_excited excited"),
        Variable(name="amplitude", dims=on[2:], units=", ".join(AXIS_UNITS),
                 long_name="chirp displacement amplitude",
                 attributes={"units_by_dof": "; ".join(
                     f"{a}: {u}" for a, u in zip(AXES, AXIS_UNITS))}),
        Variable(name="energy_residual", dims=on[2:], units="1",
                 long_name="largest energy-ledger imbalance over the largest |base work| of the "
                           "run"))
    coordinates = (
        Variable(name="frequency", dims=on[:1], units="Hz", long_name="frequency"),
        *(Variable(name=name, dims=(name,), units="1", long_name=f"{side} {dof_doc}",
                   dtype="str", order=("long_name", "units"))
          for name, side in (("output_dof", "platform"), ("input_dof", "base"))))
    return Schema(kind="a 6x6 transmissibility", coordinates=coordinates, variables=variables,
                  dimensions={"frequency": None, "output_dof": 6, "input_dof": 6})


def transmissibility_dataset(result):
    """:meth:`HexapodTransmissibility.to_xarray`: the matrix as an ``xarray.Dataset``.

    Dimensions ``frequency`` [Hz], ``output_dof`` (platform axis) and ``input_dof`` (base
    axis). A matrix entry's unit depends on both axes, so each matrix variable's
    ``units`` attribute says so in words and the string variable ``entry_units`` gives
    it per entry; ``magnitude`` and ``phase`` [rad] carry the complex estimate (NetCDF has
    no complex type), likewise ``linear_magnitude`` and ``linear_phase``. Flags are int8
    with ``flag_values``/``flag_meanings``; settings, the runs' records and the set-up's
    parameters are global attributes with their units in ``<key>_units``.

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    xarray.Dataset
    """
    import datetime

    from qzs._version import __version__
    from qzs.model.registry import unit_of

    values = {
        "magnitude": result.magnitude, "phase": np.angle(result.response),
        "coherence": result.coherence, "trusted": result.trusted,
        "below_floor": result.below_floor, "linear_magnitude": np.abs(result.linear_response),
        "linear_phase": np.angle(result.linear_response), "excited": result.excited,
        "entry_units": [[entry_unit(i, j) for j in range(6)] for i in range(6)],
        "amplitude": [result.amplitude.get(a, np.nan) for a in AXES],
        "energy_residual": [result.energy_residual.get(a, np.nan) for a in AXES],
        "frequency": result.frequency, "output_dof": list(AXES), "input_dof": list(AXES)}
    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    attrs = {"title": "qzs simulated 6x6 transmissibility of a six-leg platform",
             "source": f"qzs {__version__}: one chirp per base axis through "
                       "simulate_hexapod, single-axis Welch estimates (docs/hexapod.md)",
             "history": f"{now} qzs {__version__}: qzs.hexapod_transmissibility (Python)",
             "qzs_version": __version__, "excited_axes": ", ".join(result.excited_axes),
             "linear_stable": int(result.linear_stable),
             "linear_natural_frequencies": result.linear_natural_frequencies,
             "linear_natural_frequencies_units": "Hz",
             "linear_notes": "; ".join(result.linear_notes) or "none"}
    units = {"f0": "Hz", "f1": "Hz", "duration": "s", "sample_rate": "Hz",
             "fft_length": "samples", "overlap": "1", "coherence_min": "1",
             "base_share_min": "1", "floor_db": "dB", "platform_size": "m",
             "tolerance_db": "dB", "setup_dt": "s", "dt": "s"}
    for key, value in result.settings.items():
        attrs[f"settings.{key}"] = _attribute(value)
        if key in units:
            attrs[f"settings.{key}_units"] = units[key]
    run_units = {"dt": "s", "elapsed": "s", "seconds": "s", "energy_residual": "J",
                 "base_work_max": "J", "stroke_used": "m", "stroke_half": "m",
                 "step_error_db": "dB", "locked_fraction": "1"}
    for axis, record in result.runs.items():
        for key, value in record.items():
            if key == "step_history":
                value = np.array([v for pair in value for v in pair], dtype=float)
            attrs[f"run.{axis}.{key}"] = _attribute(value)
            if key in run_units:
                attrs[f"run.{axis}.{key}_units"] = run_units[key]
    import dataclasses

    setup = result.setup
    for section, obj in (("isolator", setup.isolator), ("controller", setup.controller)):
        for item in dataclasses.fields(obj):
            attrs[f"{section}.{item.name}"] = _attribute(getattr(obj, item.name))
            unit = unit_of(item.name)
            if unit:
                attrs[f"{section}.{item.name}_units"] = unit
    platform = setup.platform
    attrs.update({"platform.mass": platform.mass, "platform.mass_units": "kg",
                  "platform.inertia": np.asarray(platform.inertia, dtype=float).ravel(),
                  "platform.inertia_units": "kg*m^2",
                  "platform.center_of_mass": np.asarray(platform.center_of_mass, dtype=float),
                  "platform.center_of_mass_units": "m",
                  "platform.gravity": platform.gravity, "platform.gravity_units": "m/s^2",
                  "geometry.kind": setup.kind,
                  "geometry.base_joints": np.asarray(setup.geometry.base_joints).ravel(),
                  "geometry.top_joints": np.asarray(setup.geometry.top_joints).ravel(),
                  "geometry.home_position": np.asarray(setup.geometry.home_position),
                  "geometry.stroke_half": setup.geometry.stroke_half,
                  "geometry.base_joints_units": "m", "geometry.top_joints_units": "m",
                  "geometry.home_position_units": "m", "geometry.stroke_half_units": "m",
                  "source_file": setup.source or "none"})
    return to_dataset(transmissibility_schema(result.settings["estimator"]), values, attrs)


def _attribute(value):
    """A value as a NetCDF attribute (None -> "none", booleans -> 0/1, sequences -> arrays)."""
    if value is None:
        return "none"
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        array = np.asarray(value)
        if array.dtype.kind in "iub":
            return array.astype(np.int64).ravel()
        if array.dtype.kind == "f":
            return array.astype(float).ravel()
        return ", ".join(str(v) for v in np.ravel(array))
    if isinstance(value, float) and not math.isfinite(value):
        return "nan"
    return value
