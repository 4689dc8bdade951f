"""The paper's two open questions, answered as studies (``qzs study friction_compensation``,
``qzs study damping_design``; docs/workflows/questions.md).

==========================  =======================================================================
``common``                  :class:`Answer` (the verdict), the chirp batch through the lanes
``friction``                "remove stiction": friction compensation against its fraction, the
                            hunting boundary predicted and simulated
``damping``                 "attenuate the peaks": damping loops designed with python-control
                            against the paper's Kd, on the nonlinear model
``report``                  figures, ``study.json`` and ``report.html``
==========================  =======================================================================
"""
import time
from pathlib import Path
from typing import Any

from qzs.errors import ParameterError
from qzs.workflows.questions.common import Answer

__all__ = ["QUESTIONS", "Answer", "run_question"]

#: The studies by name: what each answers.
QUESTIONS = {
    "friction_compensation": "remove stiction: friction compensation against its fraction "
                             "0-1.5, and where the loop starts to hunt",
    "damping_design": "attenuate the peaks: damping loops designed with python-control against "
                      "the paper's Kd",
}


def _friction(quick, dt, workers, progress):
    from qzs.viz.questions import plot_friction_compensation, plot_friction_hunting
    from qzs.workflows.questions import friction as fr

    result = fr.run_friction_study(quick, dt=dt, workers=workers, progress=progress)
    boundary = result["boundaries"]["paper loop"]
    figures = {
        "friction_compensation": (
            plot_friction_compensation(result["table"], result["reference"], fr.BAND, boundary),
            f"RMS transmissibility over {fr.BAND[0]:g}-{fr.BAND[1]:g} Hz, isolation onset, stick "
            "events and the motor's RMS force against the compensation fraction, beside the "
            "isolator without stiction (dashed)."),
        "friction_hunting": (
            plot_friction_hunting(result["hunting"]),
            "The cycle predicted by the describing function of the net friction law against the "
            "runs at rest released sliding (simulated points only where the payload keeps "
            "moving); stars: predictions inside the stated accuracy range (2 %)."),
    }
    tables = [("Against the compensation fraction (paper's isolator, 10 mm chirp)",
               result["table"] + [dict(result["reference"], fraction="no stiction")]),
              ("Hunting at rest", [{k: v for k, v in r.items() if k != "tolerance_reason"}
                                   for r in result["hunting"]]),
              ("Where it starts to hunt", [dict(rig=k, **v)
                                           for k, v in result["boundaries"].items()])]
    plan = result["plan"]
    how = (f"Chirp {plan.excitation.amplitude * 1e3:g} mm, {plan.excitation.f0:g}-"
           f"{plan.excitation.f1:g} Hz over {plan.excitation.duration:g} s, dt = {plan.dt:g} s, "
           f"output {plan.sample_rate:g} Hz, Welch {plan.fft_length} points; every case in one "
           "lockstep batch through the lanes. Runs at rest: the base still, the payload "
           "released at the setpoint sliding at 1.5 times the predicted cycle's velocity "
           f"(0.02 m/s when none is predicted), {20 if result['quick'] else 40} s; it hunts "
           f"when its second half moves more than {fr.HUNT_STROKE * 1e3:g} mm peak to peak.")
    return result, figures, tables, how, "Friction compensation: can the motor remove stiction?"


def _damping(quick, dt, workers, progress):
    from qzs.defaults import DAMPING_CLAIM
    from qzs.viz.questions import plot_damping_design
    from qzs.workflows.questions import damping as dm

    result = dm.run_damping_study(quick, dt=dt, workers=workers, progress=progress)
    figures = {"damping_design": (
        plot_damping_design(result["curves"], result["rows"], DAMPING_CLAIM["band"]),
        "Top: the transmissibility (trusted bins) of the PI loop without damping, the paper's "
        "gains, the paper's loop at the motor's limit (solid) and the designed loops (dashed). "
        "Bottom: the two metrics against the undamped loop.")}
    designs = result["designs"]
    design_rows = [{"design": "Kd at the motor's limit", "gain": designs["kd_max"]}]
    for key in ("shaped", "cancellation"):
        if key in designs:
            design_rows.append({"design": key, **{k: v for k, v in designs[key].items()
                                                  if k != "controller"}})
    tables = [("Against the PI loop without damping (nonlinear model)", result["rows"]),
              ("The designs (linear model)", design_rows)]
    plan = result["plan"]
    how = (f"Designed with python-control on the linearised plant (frictionless guide): a "
           f"design keeps a phase margin of {dm.PHASE_MARGIN:g} deg and its linear peak motor "
           f"force under the chirp within {dm.FORCE_SHARE:.0%} of the motor's limit. Run on the "
           f"nonlinear model: chirp {plan.excitation.amplitude * 1e3:g} mm, "
           f"{plan.excitation.f0:g}-{plan.excitation.f1:g} Hz over "
           f"{plan.excitation.duration:g} s, dt = {plan.dt:g} s, output {plan.sample_rate:g} Hz, "
           f"Welch {plan.fft_length} points; every case in one lockstep batch through the lanes. "
           "slycot is not installed: no H-infinity synthesis was tried.")
    return result, figures, tables, how, "Damping design: can a loop attenuate the peaks?"


def run_question(name: str, folder: str | Path, *, quick: bool = False, dt: float = 1e-4,
                 workers: int | None = None, progress: bool = False
                 ) -> tuple[dict[str, Any], dict[str, Path], float]:
    """Run one open-question study and write its figures, ``study.json`` and ``report.html``.

    Parameters
    ----------
    name : str
        A key of :data:`QUESTIONS`.
    folder : str or Path
        The output folder.
    quick : bool
        The quick study (seconds once the kernels are compiled).
    dt : float
        Integration step of every run [s].
    workers : int, optional
        Threads; default all cores.
    progress : bool
        Show the batch's progress bar.

    Returns
    -------
    result : dict
        The study's result (``answer`` among its keys).
    written : dict of str to Path
        The files written.
    seconds : float
        Wall time [s].

    Raises
    ------
    ParameterError
        An unknown name.
    """
    from qzs.workflows.questions.report import write_question

    if name not in QUESTIONS:
        raise ParameterError(f"unknown open-question study {name!r}; they are "
                             f"{sorted(QUESTIONS)}.", "name")
    start = time.perf_counter()
    runner = _friction if name == "friction_compensation" else _damping
    result, figures, tables, how, title = runner(quick, dt, workers, progress)
    written = write_question(result, Path(folder), figures, tables, title=title, how=how)
    return result, written, time.perf_counter() - start
