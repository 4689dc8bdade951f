"""One run per excited base axis: its step, its simulation and its column of estimates."""
import time

import numpy as np

from qzs.defaults import AXES
from qzs.engine.step_search import StepChoice
from qzs.workflows.hexapod.transmissibility.plan import _control


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


def axis_step(task):
    """The step of one run: accuracy-driven (see the module docstring), or the set-up's.

    :func:`qzs.engine.step_choice.choose` on the run's chirp (a six-leg probe), the driven
    axis's transmissibility against ``task["tolerance_db"]``, halving down to the set-up's
    ``dt`` and falling back to it where no coarser step meets the tolerance (the one
    fallback, :mod:`qzs.engine.step_search`).

    Parameters
    ----------
    task : dict
        One run's task (:func:`hexapod_transmissibility` builds them).

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

    f0, f1 = task["f0"], task["f1"]
    probe = HexapodProbe(
        geometry=task["geometry"], platform=task["platform"], isolator=task["isolator"],
        controller=task["controller"], excitation={task["axis"]: task["excitation"]},
        solver=task["solver"], sample_rate=task["sample_rate"], band=(min(1.0, 0.5 * f1) if f0 == 0 else f0, f1),
        **_control(task))
    choice = choose(StepRequest(tolerance=task["tolerance_db"]), probe,
                    finest=task["setup_dt"], fallback=True)
    history = tuple((dt, d) for dt, d, _ in choice.history)
    return choice.dt, dict(choice.attributes(), step_history=history)


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
        dt, record = task["dt"], dict(StepChoice.literal(task["dt"]).attributes(),
                                      step_history=())
    else:
        dt, record = axis_step(task)
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
