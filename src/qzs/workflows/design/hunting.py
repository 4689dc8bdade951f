"""Hunting at rest: the describing functions' predictions against simulations.

Per stiction value, the PI loop alone (``Kd = 0``) and the final design, released from the
plateau the stick-slip relay predicts (:func:`qzs.analysis.control_design.predict_hunting`);
and the integral loop's Nyquist locus against the relay's ``-1/N`` for the figure.
"""
import dataclasses
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from qzs.analysis import control_design as cd
from qzs.engine.simulate import simulate
from qzs.errors import SimulationError
from qzs.model.isolator import InitialState
from qzs.workflows.design.cases import QUIET, _hunting_start
from qzs.workflows.design.settings import HUNTING_MAX


def _hunting_run(isolator, controller, settings):
    """Simulate the loop at rest from the predicted cycle; measure amplitude and period."""
    prediction = cd.predict_hunting(isolator, controller)
    offset, _ = _hunting_start(isolator, controller, HUNTING_MAX[settings.quick])
    period = prediction.relay_period if math.isfinite(prediction.relay_period) else 60.0
    first = isolator.stiction_force / (controller.pi_ki * offset) if controller.pi_ki > 0 \
        else 30.0
    duration = float(np.clip(first + 8 * period, 300.0, 1.5 * HUNTING_MAX[settings.quick]))
    try:
        result = simulate(QUIET, isolator, controller, duration=duration, dt=settings.dt,
                          sample_rate=settings.sample_rate,
                          initial_state=InitialState(
                              relative_position=controller.position_setpoint + offset))
    except SimulationError as error:
        return prediction, {"hunts": False, "failed": True, "message": str(error)}, None
    t, zeta = result.time, result.relative_position - controller.position_setpoint
    locked = np.asarray(result.locked, bool)
    breaks = t[1:][locked[:-1] & ~locked[1:]]
    late = t >= 0.5 * duration
    late_breaks = breaks[breaks >= 0.5 * duration]
    hunts = late_breaks.size >= 4
    amplitude = 0.5 * float(zeta[late].max() - zeta[late].min()) if hunts else 0.0
    period_sim = 2 * float(np.median(np.diff(late_breaks))) if hunts else math.nan
    measured = {"hunts": bool(hunts), "failed": False, "amplitude": amplitude,
                "period": period_sim, "upper": float(zeta[late].max()),
                "lower": float(zeta[late].min()), "breakaways": int(breaks.size),
                "stop_contacts": int(result.run["stop_contacts"]), "duration": duration,
                "release_offset": offset,
                "final_offset": float(zeta[-1])}
    if not hunts:
        measured["amplitude_reason"] = ("the payload stopped slipping: fewer than 4 breakaways "
                                        "in the run's second half")
    every = max(1, t.size // 3000)
    series = (t[::every], zeta[::every])
    return prediction, measured, series


def _check_hunting(settings, kp, kd, bar=None):
    """Hunting at rest: the PI loop alone (Kd = 0) and the final design, per stiction value."""
    values = sorted({settings.stiction_range[0], settings.isolator.stiction_force,
                     settings.stiction_range[1]})
    loops = [("PI loop alone", 0.0)] + ([("final design", float(kd))] if kd > 0 else [])
    tasks = [(name, gain, fs) for name, gain in loops for fs in values]
    rows, series = [], {}

    def run(task):
        name, gain, fs = task
        isolator = dataclasses.replace(settings.isolator, stiction_force=fs)
        return task, _hunting_run(isolator, settings.controller_at(kp, gain), settings)

    with ThreadPoolExecutor(max_workers=settings.workers) as pool:
        for (name, gain, fs), (prediction, measured, trace) in pool.map(run, tasks):
            confirmed = None
            if not measured.get("failed"):
                confirmed = prediction.hunts == measured["hunts"]
            memoryless = len(prediction.friction_intersections) > 0
            rows.append({"loop": name, "damping_gain": gain, "stiction_force": fs,
                         "prediction": prediction.to_dict(), "simulation": measured,
                         "relay_confirmed": confirmed,
                         "memoryless_confirmed": (None if measured.get("failed") else
                                                  memoryless == measured["hunts"])})
            if trace is not None and gain == 0.0:
                series[fs] = trace
            if bar is not None:
                bar.update(1)
    rows.sort(key=lambda r: (r["damping_gain"], r["stiction_force"]))
    z_ref = settings.controller.position_setpoint
    half = min(z_ref - settings.stroke_band[0], settings.stroke_band[1] - z_ref)
    high = dataclasses.replace(settings.isolator, stiction_force=settings.stiction_range[1])
    controller = settings.controller_at(kp, 0.0)
    needed = cd.hunting_stiffness(high, controller, half)
    return {"rows": rows, "kp_for_band": float(needed), "band_half_width": half,
            "loop": _hunting_locus(high, controller)}, series


def _hunting_locus(isolator, controller):
    """The integral loop's Nyquist locus and the element's -1/N, for the figure."""
    prediction = cd.predict_hunting(isolator, controller)
    if prediction.relay_output <= 0 or controller.pi_ki <= 0:
        return None
    g = cd.integral_loop(isolator, controller)
    omega = np.logspace(-3, 1, 400)
    response = cd.frequency_response(g, omega)
    d, h = prediction.relay_output, prediction.switching_force
    amplitude = h * (1 + np.logspace(-6, 1.3, 200))
    import control

    element = control.relay_hysteresis_nonlinearity(d, h)
    minus_inverse = -1 / control.describing_function(element, amplitude)
    point = None
    if prediction.hunts:
        point = complex(-1 / element.describing_function(prediction.integral_force_amplitude))
    return {"omega": omega, "loop": response, "amplitude": amplitude,
            "minus_inverse": minus_inverse, "intersection": point,
            "stiction_force": isolator.stiction_force}
