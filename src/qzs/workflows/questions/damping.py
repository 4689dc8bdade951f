"""The paper's first open question, "attenuate the peaks", as a study of damping designs.

The paper's damping loop is a skyhook: the motor pushes against the measured payload velocity,
``-Kd v`` (the charge amplifier's high-pass in the path). Two loops are designed here with
python-control on the linearised plant (:func:`qzs.analysis.linear.plant_system`, the
frictionless-guide limit, docs/model.md §10), each a :class:`qzs.LinearController` added to the
paper's PI loop in place of the Kd loop:

``shaped skyhook``
    ``K(s) = -k w_l^2/(s^2 + 1.4 w_l s + w_l^2)`` on the measured payload velocity (the charge
    amplifier's signal, high-passed as the paper's Kd loop reads it): the skyhook with its gain
    rolled off above the band (``w_l``, 40 Hz);
    ``k`` the largest whose linear loop keeps the phase margin of :func:`qzs.loop_margins` and
    whose motor force under the study's chirp stays within a share of the motor's limit.
``base-velocity cancellation``
    ``K(s) = -g Cv s/(s + w_c)^2`` on the base accelerometer (the rig's second one): the base's
    velocity, band-passed, times the guide's viscous coefficient, which cancels the force the
    guide's viscous friction carries from the base into the payload (the transmission above
    the isolation onset, docs/design.md §7); ``w_c`` and ``g`` chosen over a grid for the least
    linear band RMS of T within the same force limit.

Both are then run on the nonlinear model (stick-slip, the motor's saturation) with the paper's
damping gains, in one lockstep batch under one chirp, and compared on the two metrics ``qzs
paper`` and ``qzs design`` report (:func:`qzs.analysis.damping.damping_change`: the largest per-bin
reduction of T and the change of its band RMS, against the PI loop without damping, over the
paper's band of the damping claim). :func:`damping_answer` says which, if any, beats the best
of the paper's gains, and why.
"""
import dataclasses
import math

import numpy as np

from qzs.analysis.damping import damping_change
from qzs.analysis.linear import close_loop, continuous_controller_matrices, plant_matrices
from qzs.defaults import DAMPING_CLAIM
from qzs.model.controller import SENSORS, ControllerParameters, LinearController
from qzs.model.excitation import Chirp
from qzs.model.isolator import IsolatorParameters
from qzs.workflows.questions.common import (Answer, ChirpPlan, check_step, finite,
                                            run_chirp_cases)

__all__ = ["QUESTION", "STATEMENT", "PAPER_GAINS", "plan", "linear_responses",
           "shaped_skyhook", "base_cancellation", "design_loops", "damping_answer",
           "run_damping_study", "FORCE_SHARE", "PHASE_MARGIN"]

QUESTION = "damping_design"
STATEMENT = ('"Due to the presence of significant peaks in the experimental results, active '
             'damping is to be further investigated in an attempt to attenuate the peaks" '
             '(Section 4.2).')
#: The paper's damping gains (Figs. 14 and 15) [N*s/m].
PAPER_GAINS = (20.0, 50.0, 100.0)
#: The share of the motor's force limit a design's linear peak force under the chirp may take.
FORCE_SHARE = 0.8
#: The phase margin a design keeps [deg].
PHASE_MARGIN = 45.0
#: A design beats the paper's best gain by at least this on both metrics [dB].
MARGIN_DB = 0.5
#: The shaped skyhook's roll-off corner [Hz].
ROLLOFF = 40.0


def plan(quick=False, dt=1e-4):
    """The chirp: 10 mm (the paper's), 1-20 Hz (the band of the damping claim is 1.5-20 Hz).

    Parameters
    ----------
    quick : bool
        40 s and 2048-point segments (0.49 Hz bins) instead of 200 s and 4096 points.
    dt : float
        Integration step [s].

    Returns
    -------
    ChirpPlan
    """
    duration, fft = (40.0, 2048) if quick else (200.0, 4096)
    return ChirpPlan(Chirp(amplitude=0.010, f0=1.0, f1=20.0, duration=duration, fade_in=2.0),
                     sample_rate=1000.0, fft_length=fft, dt=dt)


def linear_responses(isolator, controller, frequency):
    """The linear loop's transmissibility and motor force per base acceleration.

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant.
    controller : ControllerParameters
        The whole controller (its linear part, :func:`~qzs.analysis.linear.controller_system`).
    frequency : array_like
        Frequencies [Hz].

    Returns
    -------
    transmissibility : ndarray of complex
        Payload over base acceleration [-].
    force : ndarray of complex
        Motor force per base acceleration [N/(m/s^2)].
    stable : bool
        Every closed-loop pole in the left half-plane.
    """
    a, b, c, d = close_loop(plant_matrices(isolator, controller, base=True),
                            continuous_controller_matrices(isolator, controller))
    rows = [list(SENSORS).index("payload_acceleration"), c.shape[0] - 1]
    c, d = c[rows], d[rows][:, :1]
    b = b[:, :1]
    omega = 2 * np.pi * np.asarray(frequency, dtype=float)
    eye = np.eye(a.shape[0])
    out = np.array([(c @ np.linalg.solve(1j * w * eye - a, b) + d)[:, 0] for w in omega])
    loop = close_loop(plant_matrices(isolator, controller, base=False),  # without the base's
                      continuous_controller_matrices(isolator, controller))  # pure integrator
    stable = bool(np.all(np.linalg.eigvals(loop[0]).real < 0))
    return out[:, 0], out[:, 1], stable


def _peak_force(isolator, controller, chirp, frequency):
    """The linear peak motor force under the chirp [N]: |F/a| times the base acceleration."""
    _, force, stable = linear_responses(isolator, controller, frequency)
    if not stable:
        return math.inf
    acceleration = chirp.amplitude * (2 * np.pi * frequency) ** 2
    return float(np.max(np.abs(force) * acceleration))


def shaped_skyhook(gain):
    """``-gain w_l^2/(s^2 + 1.4 w_l s + w_l^2)`` on the measured payload velocity.

    Parameters
    ----------
    gain : float
        Damping gain in the band [N*s/m].

    Returns
    -------
    LinearController
    """
    import control

    s = control.tf("s")
    w = 2 * np.pi * ROLLOFF
    system = -gain * w ** 2 / (s ** 2 + 1.4 * w * s + w ** 2)
    return LinearController.from_system(system, inputs=["measured_payload_velocity"],
                                        name="shaped skyhook")


def base_cancellation(viscous_damping, corner, share=1.0):
    """``-share Cv s/(s + w_c)^2`` on the base acceleration: the guide's viscous push cancelled.

    Parameters
    ----------
    viscous_damping : float
        The guide's viscous coefficient Cv [N*s/m].
    corner : float
        Corner of the band-pass that turns acceleration into velocity [Hz].
    share : float
        Share of ``Cv`` cancelled [-].

    Returns
    -------
    LinearController
    """
    import control

    s = control.tf("s")
    w = 2 * np.pi * corner
    system = -share * viscous_damping * s / (s + w) ** 2
    return LinearController.from_system(system, inputs=["base_acceleration"],
                                        name="base-velocity cancellation")


def design_loops(isolator, controller, chirp):
    """The two designs (module docstring) and their linear evidence.

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant.
    controller : ControllerParameters
        The paper's PI loop without damping (``damping_gain = 0``).
    chirp : Chirp
        The base motion the motor's force limit is checked under.

    Returns
    -------
    dict
        ``kd_max``: the paper's Kd loop at the largest gain within the same limits [N*s/m];
        ``shaped`` and ``cancellation`` (the latter on top of the paper's largest Kd): the
        controller block, its parameters, its linear band RMS change [dB] and peak force [N].
    """
    from qzs.analysis.control_design.stability_margins import loop_margins

    frequency = np.linspace(max(chirp.f0, 0.2), chirp.f1, 400)
    band = DAMPING_CLAIM["band"]
    limit = FORCE_SHARE * isolator.motor_force_max
    reference, _, _ = linear_responses(isolator, controller, frequency)

    def rms_change(loop):
        t, _, stable = linear_responses(isolator, loop, frequency)
        if not stable:
            return math.inf
        return damping_change(frequency, np.abs(reference), np.abs(t),
                              band=band).band_rms_change_db

    def admissible(loop):
        if _peak_force(isolator, loop, chirp, frequency) > limit:
            return False
        margins = loop_margins(isolator, loop)
        return margins.stable and not (margins.phase_margin < PHASE_MARGIN)

    def largest(loop_of):  # bisection on the largest admissible gain [N*s/m]
        low, high = 0.0, 2000.0
        for _ in range(24):
            middle = 0.5 * (low + high)
            low, high = (middle, high) if admissible(loop_of(middle)) else (low, middle)
        return low

    kd_max = largest(lambda g: dataclasses.replace(controller, damping_gain=g))
    gain = largest(lambda g: controller + shaped_skyhook(g))
    shaped = shaped_skyhook(gain)
    best = None
    damped = dataclasses.replace(controller, damping_gain=max(PAPER_GAINS))
    for corner in (0.1, 0.2, 0.3, 0.5, 0.7, 1.0):
        for share in (0.25, 0.5, 0.75, 1.0):
            block = base_cancellation(isolator.viscous_damping, corner, share)
            if not admissible(damped + block):
                continue
            change = rms_change(damped + block)
            if best is None or change < best[0]:
                best = (change, corner, share, block)
    out = {"kd_max": kd_max,
           "shaped": {"controller": shaped, "gain": gain, "rolloff": ROLLOFF,
                      "linear_band_rms_change_db": rms_change(controller + shaped),
                      "peak_force": _peak_force(isolator, controller + shaped, chirp, frequency)}}
    if best is not None:
        change, corner, share, block = best
        out["cancellation"] = {"controller": block, "corner": corner, "share": share,
                               "linear_band_rms_change_db": change,
                               "peak_force": _peak_force(isolator, damped + block, chirp,
                                                         frequency)}
    return out


def damping_answer(rows):
    """The verdict: does a designed loop beat the paper's best damping gain?

    Parameters
    ----------
    rows : list of dict
        One per damped case: ``label``, ``kind`` (``"paper"`` for a paper gain, else
        ``"design"``), ``largest_reduction_db`` and ``band_rms_change_db`` [dB] against the
        undamped loop, ``stop_contacts`` and ``saturated_fraction`` [-].

    Returns
    -------
    Answer
    """
    def undecidable(why):
        return Answer(QUESTION, STATEMENT, "not decidable", "undefined: " + why, why)

    paper = [r for r in rows if r["kind"] == "paper"
             and finite(r["largest_reduction_db"], r["band_rms_change_db"])]
    designs = [r for r in rows if r["kind"] == "design"
               and finite(r["largest_reduction_db"], r["band_rms_change_db"])]
    if not paper or not designs:
        return undecidable("a paper gain or a design has no defined metric (too few trusted "
                           "bins in the band)")
    kd = min(paper, key=lambda r: r["band_rms_change_db"])
    beats = [r for r in designs
             if r["band_rms_change_db"] <= kd["band_rms_change_db"] - MARGIN_DB
             and r["largest_reduction_db"] >= kd["largest_reduction_db"] + MARGIN_DB
             and r["stop_contacts"] == 0]
    numbers = "; ".join(f"{r['label']}: largest reduction {r['largest_reduction_db']:.2f} dB, "
                        f"band RMS {r['band_rms_change_db']:+.2f} dB, motor saturated "
                        f"{r['saturated_fraction']:.1%} of the time" for r in [kd, *designs])
    evidence = (f"Against the PI loop without damping over {DAMPING_CLAIM['band'][0]:g}-"
                f"{DAMPING_CLAIM['band'][1]:g} Hz, nonlinear model: {numbers}.")
    if beats:
        top = min(beats, key=lambda r: r["band_rms_change_db"])
        return Answer(QUESTION, STATEMENT, "yes",
                      f"{top['label']} beats the paper's best gain ({kd['label']}) by "
                      f"{kd['band_rms_change_db'] - top['band_rms_change_db']:.1f} dB of band RMS "
                      f"and {top['largest_reduction_db'] - kd['largest_reduction_db']:.1f} dB at "
                      f"its best bin. Why: above the isolation onset the guide's viscous friction "
                      f"carries the base's velocity into the payload (T ~ Cv/|Cv + Kd + j m w|); "
                      f"a skyhook only dilutes that transmission, a loop that reads the base "
                      f"cancels it.", evidence)
    return Answer(QUESTION, STATEMENT, "no",
                  f"Nothing designed here beats Kd: {kd['label']} does {kd['band_rms_change_db']:+.1f} dB "
                  f"of band RMS and {kd['largest_reduction_db']:.1f} dB at its best bin, and no "
                  f"design does {MARGIN_DB:g} dB better on both. Why: above the isolation onset "
                  f"the guide's viscous friction sets the transmission (T ~ Cv/|Cv + Kd + j m w|, "
                  f"docs/design.md §7); a loop on the payload's velocity can only add to the "
                  f"denominator, as much as the motor's force allows, which a plain Kd already "
                  f"does; a loop that cancels the guide's viscous push from the base accelerometer "
                  f"needs a force that grows with the base's velocity (Cv times it), beyond the "
                  f"motor's limit under a 10 mm sweep, so it cancels only a share of it.",
                  evidence)


def run_damping_study(quick=False, *, dt=1e-4, workers=None, progress=False):
    """Run the damping-design study (module docstring).

    Parameters
    ----------
    quick : bool
        A shorter chirp.
    dt : float
        Integration step of every run [s] (the paper's 1e-4 by default).
    workers : int, optional
        Threads; default all cores.
    progress : bool
        Show the batch's progress bar.

    Returns
    -------
    dict
        ``rows`` (one per damped case, the metrics against the undamped loop), ``curves``
        (:class:`CaseCurve` per case, the undamped first), ``designs`` (their parameters and
        linear evidence), ``linear`` (each case's linear transmissibility), ``answer``,
        ``plan``.
    """
    check_step(dt)
    chirp = plan(quick, dt)
    isolator, controller = IsolatorParameters(), ControllerParameters()
    designs = design_loops(isolator, controller, chirp.excitation)
    cases = [("PI, no damping", "reference", controller)]
    cases += [(f"Kd = {g:g} N*s/m", "paper", dataclasses.replace(controller, damping_gain=g))
              for g in PAPER_GAINS]
    cases.append((f"Kd = {designs['kd_max']:.0f} N*s/m (the motor's limit)", "paper",
                  dataclasses.replace(controller, damping_gain=designs["kd_max"])))
    shaped = designs["shaped"]
    cases.append((f"shaped skyhook, k = {shaped['gain']:.0f} N*s/m", "design",
                  controller + shaped["controller"]))
    if "cancellation" in designs:
        cancel = designs["cancellation"]
        best_kd = dataclasses.replace(controller, damping_gain=max(PAPER_GAINS))
        cases.append((f"Kd = {max(PAPER_GAINS):g} N*s/m + base-velocity cancellation "
                      f"({cancel['share']:g} Cv, {cancel['corner']:g} Hz)", "design",
                      best_kd + cancel["controller"]))
    curves = run_chirp_cases([c[0] for c in cases], [(isolator, c[2]) for c in cases], chirp,
                             workers=workers, progress=progress)
    reference = curves[0]
    rows = []
    for (label, kind, loop), curve in zip(cases[1:], curves[1:]):
        change = damping_change(curve.frequency, reference.magnitude, curve.magnitude,
                                band=DAMPING_CLAIM["band"], reference_trusted=reference.trusted,
                                damped_trusted=curve.trusted)
        rows.append({"label": label, "kind": kind, **change.to_dict(),
                     "stop_contacts": curve.stats["stop_contacts"],
                     "saturated_fraction": curve.stats["saturated_fraction"],
                     "motor_force_rms": curve.stats["motor_force_rms"],
                     "stick_events": curve.stats["stick_events"]})
    frequency = reference.frequency
    linear = {label: np.abs(linear_responses(isolator, loop, np.maximum(frequency, 1e-3))[0])
              for label, _, loop in cases}
    return {"rows": rows, "curves": curves, "designs": designs, "linear": linear,
            "answer": damping_answer(rows), "plan": chirp, "quick": bool(quick)}
