"""``design_controller``: the design's stages in order, timed, and their record.

The stages: the inputs checked and the steps chosen (:mod:`.inputs`); the PI search
(:mod:`.proportional_search`), the damping search (:mod:`.damping_search`) and the final
gains' verification, repeated once with the damping gain when it changed what the cases
need; hunting at rest (:mod:`.hunting`); the sampled loop's margins (:mod:`.margins`); why
damping did not help much (:mod:`.damping_effect`); the linear stability and the static
design of the final gains. Each stage's wall time is in :attr:`DesignResult.seconds`.
"""
from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from qzs.analysis import control_design as cd
from qzs.workflows.design.cases import _cases
from qzs.workflows.design.damping_effect import _why
from qzs.workflows.design.damping_search import _search_damping
from qzs.workflows.design.hunting import _check_hunting
from qzs.workflows.design.inputs import _design_settings
from qzs.workflows.design.margins import _margins, margin_steps
from qzs.workflows.design.proportional_search import _run_cases, _search_pi, _summary
from qzs.workflows.design.result import DesignResult
from qzs.workflows.design.settings import BISECTIONS, DAMPING_GAIN_MAX, DAMPING_POINTS, KP_GRID

if TYPE_CHECKING:
    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Chirp, DisplacementRecord, RandomExcitation
    from qzs.model.isolator import IsolatorParameters

__all__ = ["design_controller"]


def design_controller(isolator: IsolatorParameters | None = None,
                      controller: ControllerParameters | None = None, *,
                      excitation: Chirp | RandomExcitation | DisplacementRecord | None = None,
                      stiction_range: tuple[float, float] | None = None,
                      mass_range: tuple[float, float] | None = None,
                      force_steps: Sequence[float] = (-2.0, 2.0),
                      band: tuple[float, float] = (1.0, 20.0), cost: str = "rms",
                      controller_rate: float | None = None, delay: float = 0.0,
                      quick: bool = False, dt: float | None = None,
                      damping_gain_max: float = DAMPING_GAIN_MAX,
                      gain_margin_min: float = cd.GAIN_MARGIN_MIN,
                      phase_margin_min: float = cd.PHASE_MARGIN_MIN, workers: int | None = None,
                      progress: bool = False) -> DesignResult:
    """Design the PI and damping gains of the isolator by simulation (docs/design.md).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        The nominal plant; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Setpoint, high-pass, the ratio ``Ki/Kp`` the search keeps, and the damping gain of the
        PI search (default 0); defaults if omitted.
    excitation : Chirp, RandomExcitation or DisplacementRecord, optional
        The base motion; default the paper's chirp (``quick``: its first 200 s as a sweep
        over the same band in 200 s).
    stiction_range : tuple of float, optional
        Stiction forces [N, N]; default half to one and a half times the isolator's.
    mass_range : tuple of float, optional
        Moving masses [kg, kg]; default the isolator's mass +-0.2 kg.
    force_steps : sequence of float
        Payload force steps [N], upward positive (the integral starts off its preload by
        ``dF/Ki``); default +-2 N (about the weight deficit the integral carries).
    band : tuple of float
        Band of the transmissibility cost [Hz, Hz]; default 1-20 Hz.
    cost : {"rms", "peak"}
        Transmissibility cost minimised by the damping gain.
    controller_rate : float, optional
        Controller rate [Hz] with zero-order hold; 0 continuous; default the controller's.
    delay : float
        Delay from sampling to the motor force [s] for the margins (the simulator has none).
    quick : bool
        Shorter runs, fewer cases (the ranges' ends only), a coarser search.
    dt : float, optional
        Integration step [s]; default the accuracy-driven step
        (:func:`~qzs.engine.accuracy.choose_step`, 0.01 dB over the band).
    damping_gain_max : float
        Largest damping gain tried [N*s/m].
    gain_margin_min : float
        Least gain margin of the sampled loop [dB].
    phase_margin_min : float
        Least phase margin of the sampled loop [deg].
    workers : int, optional
        Threads; default all cores.
    progress : bool
        Show progress bars.

    Returns
    -------
    DesignResult

    Raises
    ------
    ParameterError
        A bad argument, before any simulation.
    """
    began = time.perf_counter()
    settings = _design_settings(
        isolator, controller, excitation=excitation, stiction_range=stiction_range,
        mass_range=mass_range, force_steps=force_steps, band=band, cost=cost,
        controller_rate=controller_rate, delay=delay, quick=quick, dt=dt,
        damping_gain_max=damping_gain_max, gain_margin_min=gain_margin_min,
        phase_margin_min=phase_margin_min, workers=workers, progress=progress)
    seconds = {"choose_step": time.perf_counter() - began}
    cases = _cases(settings.stiction_range, settings.mass_range, settings.force_steps,
                   settings.quick)
    choice = _choose_gains(settings, cases, seconds)
    checks = _check_design(settings, choice, seconds)
    final = settings.controller_at(choice.kp, choice.kd)
    stability = cd.routh_hurwitz(settings.isolator, final)
    static = cd.static_design(settings.isolator, settings.controller,
                              mass_range=settings.mass_range)
    seconds["total"] = time.perf_counter() - began
    return _result(settings, cases, choice, checks, stability, static, seconds)


@dataclass
class _Choice:
    """The gains the searches chose, with their records."""

    pi: dict
    kp: float
    damping: dict
    curves: dict
    kd: float
    verification: dict
    first_search: dict | None = None


def _bar(settings, total, desc, unit="run"):
    """A progress bar of ``total`` runs (hidden unless ``settings.progress``)."""
    from qzs.engine.progress import progress_bar

    return progress_bar(total=total, unit=unit, desc=desc, disable=not settings.progress,
                        leave=False)


def _search(settings, cases, kd, desc, below=None):
    """The PI search at damping gain ``kd``, with its progress bar."""
    quick = settings.quick
    bar = _bar(settings, len(cases) * (len(KP_GRID[quick]) + BISECTIONS[quick]), desc)
    try:
        return _search_pi(cases, settings, kd, bar, below)
    finally:
        bar.close()


def _damp(settings, kp):
    """The damping search at proportional gain ``kp``, with its progress bar."""
    coarse, fine = DAMPING_POINTS[settings.quick]
    bar = _bar(settings, 1 + coarse + fine, "damping gain")
    try:
        return _search_damping(settings, kp, bar)
    finally:
        bar.close()


def _verify(settings, cases, kp, kd):
    """Every case at the gains ``(kp, kd)``: the summary and the rows."""
    bar = _bar(settings, len(cases), "verification")
    try:
        (rows,) = _run_cases(cases, [(kp, kd)], settings, bar)
    finally:
        bar.close()
    return {"summary": _summary(kp, kd, settings, rows), "rows": rows}


def _choose_gains(settings, cases, seconds):
    """The PI search, the damping search and the verification, timed into ``seconds``.

    When the final gains fail the verification because the damping gain changed what the
    cases need, the PI search is repeated once with that damping gain (upwards from the
    failing gain), and the damping search and verification after it.
    """
    controller = settings.controller
    clock = time.perf_counter()
    pi = _search(settings, cases, controller.damping_gain, "PI gains")
    seconds["pi_search"] = time.perf_counter() - clock
    kp = pi["pi_kp"] if pi["found"] else controller.pi_kp
    clock = time.perf_counter()
    damping, curves = _damp(settings, kp)
    kd = damping["chosen"]
    seconds["damping_search"] = time.perf_counter() - clock
    clock = time.perf_counter()
    verification = _verify(settings, cases, kp, kd)
    verification["repeated"] = False
    seconds["verification"] = time.perf_counter() - clock
    choice = _Choice(pi=pi, kp=kp, damping=damping, curves=curves, kd=kd,
                     verification=verification)
    first_pass = None
    if pi["found"] and not verification["summary"]["passes"] and kd != controller.damping_gain:
        # the damping loop changed what the cases need: search again with it, once
        clock = time.perf_counter()
        first_pass = {"pi_kp": kp, "damping_gain": kd,
                      "verification": verification["summary"]}
        choice = _repeat_with_damping(settings, cases, choice)
        seconds["repeat"] = time.perf_counter() - clock
    choice.verification["first_pass"] = first_pass
    return choice


def _repeat_with_damping(settings, cases, first):
    """The PI search again at the first pass's damping gain, and what follows from it."""
    again = _search(settings, cases, first.kd, "PI gains with Kd",
                    below=(first.kp, first.verification["rows"]))
    if not again["found"]:
        return dataclasses.replace(first, first_search=first.pi)
    kp = again["pi_kp"]
    damping, curves = _damp(settings, kp)
    kd = damping["chosen"]
    verification = _verify(settings, cases, kp, kd)
    verification["repeated"] = True
    return _Choice(pi=again, kp=kp, damping=damping, curves=curves, kd=kd,
                   verification=verification, first_search=first.pi)


def _check_design(settings, choice, seconds):
    """Hunting at rest, the margins and why damping did not help, timed into ``seconds``."""
    kp, kd = choice.kp, choice.kd
    clock = time.perf_counter()
    bar = _bar(settings, 6, "hunting")
    try:
        hunting, traces = _check_hunting(settings, kp, kd, bar)
    finally:
        bar.close()
    seconds["hunting"] = time.perf_counter() - clock
    clock = time.perf_counter()
    bar = _bar(settings, margin_steps(settings), "sampled-loop margins", unit="analysis")
    try:
        margins = _margins(settings, kp, kd, bar)
    finally:
        bar.close()
    seconds["margins"] = time.perf_counter() - clock
    clock = time.perf_counter()
    bar = _bar(settings, 40, "why damping")
    try:
        why = _why(settings, settings.controller.pi_kp, kd, choice.damping["rows"], bar)
    finally:
        bar.close()
    seconds["why"] = time.perf_counter() - clock
    return {"hunting": hunting, "traces": traces, "margins": margins, "why": why}


def _record_settings(settings, cases):
    """The problem as solved, JSON-ready: what :attr:`DesignResult.settings` holds."""
    excitation = settings.excitation
    return {
        "isolator": settings.isolator.to_dict(), "controller": settings.controller.to_dict(),
        "excitation": {"kind": type(excitation).__name__,
                       **{f.name: getattr(excitation, f.name)
                          for f in dataclasses.fields(excitation)
                          if not isinstance(getattr(excitation, f.name), np.ndarray)},
                       "units": {f.name: f.metadata.get("unit", "")
                                 for f in dataclasses.fields(excitation)}},
        "duration": settings.duration, "stiction_range": list(settings.stiction_range),
        "mass_range": list(settings.mass_range), "force_steps": list(settings.force_steps),
        "band": list(settings.band), "cost": settings.cost,
        "controller_rate": settings.controller_rate, "delay": settings.delay,
        "quick": settings.quick, "dt": settings.dt, "dt_note": settings.dt_note,
        "stroke_dt": settings.stroke_dt, "sample_rate": settings.sample_rate,
        "fft_length": settings.fft_length, "integral_ratio": settings.ratio,
        "stroke_band": list(settings.stroke_band),
        "damping_gain_max": settings.damping_gain_max,
        "gain_margin_min": settings.gain_margin_min,
        "phase_margin_min": settings.phase_margin_min,
        "cases": [c.label for c in cases], "workers": settings.workers}


def _result(settings, cases, choice, checks, stability, static, seconds):
    """The :class:`DesignResult` of the stages' records."""
    kp, kd, pi, first_search = choice.kp, choice.kd, choice.pi, choice.first_search
    gains = {"pi_kp": float(kp), "pi_ki": float(settings.ratio * kp), "damping_gain": float(kd)}
    series = {"damping_curves": {k: (v.frequency, v.magnitude, v.trusted)
                                 for k, v in choice.curves.items()},
              "damping_estimates": dict(choice.curves),
              "hunting_traces": checks["traces"], "hunting_loop": checks["hunting"].get("loop"),
              "pi_details": pi.get("details", {}),
              "pi_details_first": (first_search or {}).get("details", {})}
    pi_record = dict(pi)
    pi_record["cases"] = len(cases)
    if first_search is not None:
        pi_record["first_search"] = {k: v for k, v in first_search.items() if k != "details"}
    return DesignResult(gains=gains, settings=_record_settings(settings, cases), static=static,
                        pi_search=pi_record, stability=stability, hunting=checks["hunting"],
                        damping=choice.damping, margins=checks["margins"], why=checks["why"],
                        verification=choice.verification, seconds=seconds, series=series)
