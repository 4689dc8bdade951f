"""One run per excited base axis: its step, its simulation and its column of estimates."""
import math
import time

import numpy as np

from qzs._format import decibels
from qzs.defaults import AXES
from qzs.errors import ParameterError
from qzs.workflows.hexapod_transmissibility.plan import _control, _default_fft_length, _stable


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
