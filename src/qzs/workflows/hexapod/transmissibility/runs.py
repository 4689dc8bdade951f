"""One run per excited base axis: its step, its simulation and its column of estimates."""
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from qzs.defaults import AXES
from qzs.engine.step_search import StepChoice

__all__ = ["AxisRun", "axis_step", "run_axis"]


@dataclass(frozen=True, kw_only=True)
class AxisRun:
    """One run of the matrix, resolved: one base axis's chirp, the platform, the analysis
    (:func:`~qzs.workflows.hexapod.transmissibility.hexapod_transmissibility` plans them).

    Attributes
    ----------
    axis : str
        The base axis excited (one of :data:`qzs.defaults.AXES`).
    excitation : Chirp
        Its chirp (amplitude [m] or [rad], ``f0`` and ``f1`` [Hz], duration [s]).
    geometry : HexapodGeometry
        The legs' attachment points.
    platform : RigidBody
        The platform's mass and inertia.
    isolator : IsolatorParameters or tuple
        Every leg's isolator, or each leg's.
    controller : ControllerParameters or tuple
        Every leg's loop, or each leg's.
    cartesian : object or None
        The centralised controller, where the set-up has one.
    f0 : float
        The chirp's start frequency [Hz].
    f1 : float
        The chirp's end frequency [Hz].
    duration : float
        The run's length [s].
    sample_rate : float
        Output rate [Hz].
    solver : str
        The integration scheme.
    fft_length : int
        Welch segment length [samples].
    overlap : float
        Welch segment overlap [-].
    estimator : str
        The transmissibility estimator (``"h1"``, ...).
    coherence_min : float
        Least coherence of a trusted bin [-].
    base_share_min : float
        Least base power share of a trusted bin [-].
    tolerance_db : float or None
        Tolerance on the transmissibility [dB] the chosen step meets; None with ``dt``.
    setup_dt : float
        The set-up's step [s]: the finest probed, and the fallback.
    dt : float or None
        A literal step [s]; None: chosen by :func:`axis_step`.
    """

    axis: str
    excitation: Any
    geometry: Any
    platform: Any
    isolator: Any
    controller: Any
    cartesian: Any = None
    f0: float
    f1: float
    duration: float
    sample_rate: float
    solver: str
    fft_length: int
    overlap: float
    estimator: str
    coherence_min: float
    base_share_min: float
    tolerance_db: float | None
    setup_dt: float
    dt: float | None

    @property
    def control(self):
        """The centralised controller keyword of the engine, where the set-up has one."""
        return {} if self.cartesian is None else {"cartesian": self.cartesian}


# ---------------------------------------------------------------- one run
def _estimate(result, axis, run, outputs=range(6)):
    """Welch estimates of platform axes ``outputs`` per base axis ``axis`` of a run."""
    from qzs.analysis.spectral import transmissibility

    j = AXES.index(axis)
    base = result["base_velocity"][:, j]
    twist = result["platform_twist"]
    return {i: transmissibility(base, twist[:, i], run.sample_rate,
                                fft_length=run.fft_length, overlap=run.overlap,
                                estimator=run.estimator, coherence_min=run.coherence_min,
                                base_share_min=run.base_share_min)
            for i in outputs}


def _simulate(run, excitation, dt, duration):
    from qzs.engine.hexapod import simulate_hexapod

    return simulate_hexapod(run.geometry, run.platform, run.isolator, run.controller,
                            excitation={run.axis: excitation}, duration=duration, dt=dt,
                            sample_rate=run.sample_rate, solver=run.solver, **run.control)


def axis_step(task):
    """The step of one run: accuracy-driven (see the module docstring), or the set-up's.

    :func:`qzs.engine.step_choice.choose` on the run's chirp (a six-leg probe), the driven
    axis's transmissibility against ``task.tolerance_db``, halving down to the set-up's
    ``dt`` and falling back to it where no coarser step meets the tolerance (the one
    fallback, :mod:`qzs.engine.step_search`).

    Parameters
    ----------
    task : AxisRun
        One run (:func:`hexapod_transmissibility` plans them).

    Returns
    -------
    dt : float
        The step [s].
    record : dict
        The step record's entries (:meth:`~qzs.engine.step_search.StepChoice.attributes`:
        ``step``, ``step_error_db``, ``step_tolerance_db``, ``step_reference_dt``,
        ``step_probe_duration``, ``step_reason``) and ``step_history`` (``(dt [s],
        difference to the next finer step [dB])`` per step compared).
    """
    from qzs.engine.hexapod.accuracy import HexapodProbe
    from qzs.engine.step_choice import StepRequest, choose

    f0, f1 = task.f0, task.f1
    probe = HexapodProbe(
        geometry=task.geometry, platform=task.platform, isolator=task.isolator,
        controller=task.controller, excitation={task.axis: task.excitation},
        solver=task.solver, sample_rate=task.sample_rate,
        band=(min(1.0, 0.5 * f1) if f0 == 0 else f0, f1), **task.control)
    choice = choose(StepRequest(tolerance=task.tolerance_db), probe, finest=task.setup_dt,
                    fallback=True)
    history = tuple((dt, d) for dt, d, _ in choice.history)
    return choice.dt, dict(choice.attributes(), step_history=history)


def run_axis(run):
    """Run one axis's chirp and reduce it to its column (top level: process pools call it).

    Parameters
    ----------
    run : AxisRun
        The run.

    Returns
    -------
    dict
        ``axis``, ``frequency`` [Hz], ``response`` (6, n) complex, ``coherence`` (6, n),
        ``trusted`` (6, n), ``record`` (the run's record, see
        :attr:`HexapodTransmissibility.runs`).
    """
    start = time.perf_counter()
    if run.dt is not None:
        dt, record = run.dt, dict(StepChoice.literal(run.dt).attributes(), step_history=())
    else:
        dt, record = axis_step(run)
    result = _simulate(run, run.excitation, dt, run.duration)
    estimates = _estimate(result, run.axis, run)
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
                  stroke_half=float(run.geometry.stroke_half),
                  energy_residual=float(np.max(np.abs(residual))), base_work_max=work,
                  n_averages=int(first.n_averages),
                  relative_pose_max=np.max(np.abs(result["platform_pose"]
                                                  - result["base_pose"]), axis=0))
    record["seconds"] = time.perf_counter() - start
    return dict(axis=run.axis, frequency=first.frequency, response=response,
                coherence=np.array([e.coherence for e in estimates.values()]),
                trusted=np.array([e.trusted for e in estimates.values()]), record=record)
