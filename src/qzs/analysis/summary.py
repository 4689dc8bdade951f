"""The summary of a run: what a careful engineer would check first, as text or as a record.

The numbers come from :attr:`SimulationResult.statistics` (every sample, also of a
run streamed to a file); the warnings from :func:`run_warnings`.
"""
import numpy as np

__all__ = ["summary_text", "summary_record", "run_title", "run_warnings", "excitation_part",
           "block_lines", "batch_text", "WARNING_LIMITS"]

#: Where the summary starts to warn: the output rate per excitation frequency [-], the
#: integration steps per period [-], the energy-ledger residual per unit of base work [-].
WARNING_LIMITS = {"samples_per_period": 5.0, "steps_per_period": 20.0,
                  "energy_residual_share": 1e-4}


def excitation_part(excitation, duration):
    """The excitation and the part of it a run of ``duration`` covers, for people.

    ``Chirp 0-20 Hz over 2000 s: first 200 s run (0-2 Hz)`` (the band reached, by the sweep
    law), ``Sine 3 Hz: 10 s run``, ``Random 0.5-20 Hz over 100 s: all 100 s run``,
    ``Record of 60 s: first 20 s run``.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation, DisplacementRecord or None
        The base motion.
    duration : float
        The run's simulated time [s].

    Returns
    -------
    str
    """
    from qzs.model.excitation import Chirp, DisplacementRecord, RandomExcitation, Sine

    if isinstance(excitation, Sine):
        return f"Sine {excitation.frequency:g} Hz: {duration:g} s run"
    if isinstance(excitation, Chirp):
        law = " (logarithmic)" if excitation.method == "logarithmic" else ""
        what = f"Chirp {excitation.f0:g}-{excitation.f1:g} Hz{law} over {excitation.duration:g} s"
    elif isinstance(excitation, RandomExcitation):
        what = (f"Random {excitation.f_low:g}-{excitation.f_high:g} Hz over "
                f"{excitation.duration:g} s")
    elif isinstance(excitation, DisplacementRecord):
        what = f"Record of {excitation.duration:g} s"
    else:
        return f"{type(excitation).__name__}: {duration:g} s run"
    if duration >= excitation.duration * (1 - 1e-12):
        return f"{what}: all {duration:g} s run"
    reached = ""
    if isinstance(excitation, Chirp):
        reached = (f" ({excitation.f0:g}-{float(excitation.frequency_at(duration)):.3g} Hz)")
    return f"{what}: first {duration:g} s run{reached}"


def run_title(result):
    """One line naming the excitation and the part of it run, the solver and step of a run.

    Parameters
    ----------
    result : SimulationResult
        The run.
    """
    return (f"{excitation_part(result.excitation, result.run['duration'])}, "
            f"{result.run['solver']} dt = {result.run['dt']:g} s")


def run_warnings(result):
    """What in a run deserves a second look, each as ``(code, message)``.

    Codes: ``interrupted``; ``motor_saturated`` (the loops asked for the motor's limit
    or more); ``setpoint_outside_constant_force`` (the setpoint is not where the
    spring's force is flat, so the isolator is not quasi-zero-stiffness there);
    ``output_rate_low`` (the excitation reaches above a fifth of the output rate);
    ``few_steps_per_period`` (fewer than 20 integration steps per period of the
    excitation's highest frequency); ``energy_residual`` (the energy ledger does not
    balance to 1e-4 of the base work).

    Parameters
    ----------
    result : SimulationResult
        The run.

    Returns
    -------
    list of tuple of str
    """
    iso, ctrl, run = result.isolator, result.controller, result.run
    stats = result.statistics
    warnings = []
    if not result.completed:
        warnings.append(("interrupted", f"the run was interrupted at t = "
                                        f"{stats['time_last']:g} s of {run['duration']:g} s"))
    if stats["saturated_fraction"] > 0:
        warnings.append((
            "motor_saturated",
            f"the motor saturates {100 * stats['saturated_fraction']:.2f} % of the time (the "
            f"loops ask for motor_force_max = {iso.motor_force_max:g} N or more): the loops "
            "have no authority left there; lower the gains or the excitation, or check the "
            "load"))
    edge = iso.constant_force_edge
    if iso.spring_law.kind == "tanh" and ctrl.position_setpoint > edge:
        from qzs.model.isolator import spring_force, spring_stiffness

        force = -float(spring_force(ctrl.position_setpoint, iso))
        stiffness = float(spring_stiffness(ctrl.position_setpoint, iso))
        warnings.append((
            "setpoint_outside_constant_force",
            f"the setpoint z_ref = {1e3 * ctrl.position_setpoint:.1f} mm lies outside the "
            f"spring's constant-force region (z < {1e3 * edge:.1f} mm): the spring gives "
            f"{force:.2f} N of its {iso.spring_force:g} N plateau with a stiffness of "
            f"{stiffness:.0f} N/m, so the isolator is not quasi-zero-stiffness there; move "
            "position_setpoint below the edge"))
    top = _highest_frequency(result)
    if top > 0:
        per_sample = run["sample_rate"] / top
        if per_sample < WARNING_LIMITS["samples_per_period"]:
            warnings.append((
                "output_rate_low",
                f"the excitation reaches {top:g} Hz, above a fifth of the output rate "
                f"({run['sample_rate']:g} Hz; {per_sample:.1f} samples per period): the "
                "output under-resolves it; raise sample_rate"))
        per_step = 1.0 / (top * run["dt"])
        if per_step < WARNING_LIMITS["steps_per_period"]:
            warnings.append((
                "few_steps_per_period",
                f"only {per_step:.1f} integration steps per period at {top:g} Hz (dt = "
                f"{run['dt']:g} s); the fixed-step integrator is inaccurate there, reduce dt "
                f"below {1.0 / (WARNING_LIMITS['steps_per_period'] * top):.3g} s"))
    share = _residual_share(stats)
    if share > WARNING_LIMITS["energy_residual_share"]:
        warnings.append((
            "energy_residual",
            f"the energy ledger is off by {stats['energy_residual_max']:.3g} J "
            f"({share:.2g} of the base work): the integration error is large; reduce dt"))
    return warnings


def _highest_frequency(result):
    """Highest frequency [Hz] the excitation reaches within the run."""
    from qzs.model.excitation import highest_frequency

    return highest_frequency(result.excitation, result.run["duration"])


def _residual_share(stats):
    return stats["energy_residual_max"] / max(stats["base_work_max"], 1e-300)


def _step_line(run):
    """How the run's step was chosen, as a line (docs/model.md §7); '' for a literal step."""
    from qzs._format import step_line

    if run.get("step", "given") == "given":
        return ""
    return f"  step             {step_line(run)}"


def block_lines(controller, stats, payload="payload acceleration"):
    """The controller and what its blocks cost (their RMS forces, the dither's acceleration).

    Parameters
    ----------
    controller : ControllerParameters
        The controller with blocks (of a run, or of one leg of a platform).
    stats : dict
        Its statistics: those of :data:`~qzs.analysis.statistics.BLOCK_STATISTICS` it has,
        and ``motor_force_rms`` [N].
    payload : str
        What the dither's acceleration [m/s^2] is of, for the line.

    Returns
    -------
    list of str
        ``controller``, ``block forces`` and ``dither cost`` lines.
    """
    lines = [f"  controller       {controller.describe()}"]
    forces = [f"{label} RMS {stats[name + '_rms']:.3g} N"
              for name, label in (("compensation_force", "compensation"),
                                  ("friction_estimate", "friction estimate"),
                                  ("dither_force", "dither"),
                                  ("linear_force", f"'{getattr(controller.linear, 'name', '')}'"))
              if name + "_rms" in stats]
    if forces:
        lines.append(f"  block forces     {'; '.join(forces)}")
    if "dither_payload_acceleration" in stats:
        lines.append(f"  dither cost      {payload} "
                     f"{stats['dither_payload_acceleration']:.3g} m/s^2 at "
                     f"{controller.dither.frequency:g} Hz; motor RMS "
                     f"{stats['motor_force_rms']:.3g} N in all")
    return lines


def summary_record(result):
    """The summary as data: run settings, statistics (SI units) and warnings.

    Parameters
    ----------
    result : SimulationResult
        The run.

    Returns
    -------
    dict
        ``excitation`` (kind), ``run`` (settings and counts, ``steps_per_second`` [1/s]
        of integration only), ``statistics`` (:data:`~qzs.analysis.statistics.SUMMARY_STATISTICS`
        names: [m], [N], [J], [s], shares in [-]), ``warnings`` (list of ``{"code",
        "message"}``).
    """
    run = dict(result.run)
    run["steps_per_second"] = result.steps_per_second
    return {"excitation": type(result.excitation).__name__, "run": run,
            "statistics": dict(result.statistics),
            "warnings": [{"code": c, "message": m} for c, m in run_warnings(result)]}


def summary_text(result):
    """One-screen summary: operating point, stroke used, contacts, time locked, speed, warnings.

    Parameters
    ----------
    result : SimulationResult
        The run.
    """
    iso, ctrl, run = result.isolator, result.controller, result.run
    stats = result.statistics
    low, high = run["stop_low"], run["stop_high"]
    used = (stats["z_max"] - stats["z_min"]) / (high - low)
    samples = run.get("samples", stats["samples"])
    kept = ("" if run.get("preview_every", 1) == 1 else
            f" (in memory: their min/max per {run['preview_every']} samples)")
    lines = [
        f"qzs simulation  {run_title(result)}{'' if result.completed else '  [INTERRUPTED]'}",
        f"  steps            {run['steps']:,} in {run['elapsed']:.2f} s "
        f"({result.steps_per_second / 1e6:.2f} M steps/s, compilation excluded), "
        f"{samples:,} samples at {run['sample_rate']:g} Hz{kept}",
    ]
    step = _step_line(run)
    if step:
        lines.append(step)
    lines += [
        f"  operating point  setpoint z_ref = {ctrl.position_setpoint * 1e3:.1f} mm; "
        f"mean z = {stats['z_mean'] * 1e3:.2f} mm; final z = {stats['z_final'] * 1e3:.2f} mm",
        f"  stroke used      z in [{stats['z_min'] * 1e3:.2f}, {stats['z_max'] * 1e3:.2f}] mm = "
        f"{100 * used:.1f} % of the stops' [{low * 1e3:.0f}, {high * 1e3:.0f}] mm",
        f"  stop contacts    {run['stop_contacts']} "
        f"({100 * stats['contact_fraction']:.2f} % of the time in contact)",
        f"  locked           {100 * stats['locked_fraction']:.1f} % of the time; "
        f"{run['stick_events']} stick events",
        f"  motor force      RMS {stats['motor_force_rms']:.2f} N, "
        f"peak {stats['motor_force_peak']:.2f} N (limit {iso.motor_force_max:g} N)",
    ]
    if ctrl.has_blocks:
        lines += block_lines(ctrl, stats)
    if iso.spring is not None:
        lines.append(f"  spring           {iso.spring.describe()}")
    deficit = iso.weight_deficit
    if deficit > 0 and iso.spring_law.kind == "tanh":
        lines.append(
            f"  note             m*g = {iso.mass * iso.gravity:.2f} N exceeds the spring's "
            f"{iso.spring_force:.2f} N plateau: the PI integral must carry {deficit:.2f} N"
            + ("" if ctrl.pi_ki > 0 else " (pi_ki = 0: nothing does; the payload sinks)"))
    lines.append(f"  energy ledger    max residual {stats['energy_residual_max']:.3g} J "
                 f"({_residual_share(stats):.2g} of the base work)")
    lines.append(f"  time span        {stats['time_first']:g} .. {stats['time_last']:g} s")
    lines += [f"  WARNING          {message}" for code, message in run_warnings(result)
              if code != "interrupted"]
    return "\n".join(lines)


def batch_text(result, statistics):
    """A batch of runs as text: its size, its failures, each case's statistics.

    Parameters
    ----------
    result : BatchResult
        The batch (:func:`qzs.engine.batch.simulate_batch`).
    statistics : mapping of str to (str, str)
        Statistic name -> (unit, description) (``qzs.engine.batch.STATS``).

    Returns
    -------
    str
    """
    n = len(result.status)
    failed = int(np.sum(result.status))
    lines = [f"batch of {n} simulation(s) of {result.time[-1]:.6g} s, {len(result.time)} "
             f"samples each; {failed} failed; {result.elapsed:.3g} s wall time"]
    shown = [name for name in statistics if name in result.stats and name != "steps"]
    for i in range(n):
        values = ", ".join(f"{name} {result.stats[name][i]:.4g}"
                           + (f" {statistics[name][0]}" if statistics[name][0] != "1" else "")
                           for name in shown)
        state = f"failed: {result.messages[i]}" if result.status[i] else values
        lines.append(f"  case {i}: {state}")
    return "\n".join(lines)
