"""The one-screen text summary of a run: what a careful engineer would check first."""
import numpy as np

from qzs.analysis.statistics import run_statistics

__all__ = ["summary_text", "run_title"]


def run_title(result):
    """One line naming the excitation, duration, solver and step of a run.

    Parameters
    ----------
    result : SimulationResult
        The run.
    """
    exc = result.excitation
    return (f"{type(exc).__name__}: {result.run['duration']:g} s, "
            f"{result.run['solver']} dt = {result.run['dt']:g} s")


def summary_text(result):
    """One-screen summary: operating point, stroke used, contacts, time locked, speed.

    Parameters
    ----------
    result : SimulationResult
        The run.
    """
    iso, ctrl, run = result.isolator, result.controller, result.run
    z = result.relative_position
    t = result.time
    low, high = run["stop_low"], run["stop_high"]
    statistics = run_statistics(z, result.motor_force, result.locked, 0.5 * (low + high))
    used = (statistics["z_max"] - statistics["z_min"]) / (high - low)
    lines = [
        f"qzs simulation  {run_title(result)}{'' if result.completed else '  [INTERRUPTED]'}",
        f"  steps            {run['steps']:,} in {run['elapsed']:.2f} s "
        f"({result.steps_per_second / 1e6:.2f} M steps/s), {len(result):,} samples at "
        f"{run['sample_rate']:g} Hz",
        f"  operating point  setpoint z_ref = {ctrl.position_setpoint * 1e3:.1f} mm; "
        f"mean z = {z.mean() * 1e3:.2f} mm; final z = {z[-1] * 1e3:.2f} mm",
        f"  stroke used      z in [{statistics['z_min'] * 1e3:.2f}, {statistics['z_max'] * 1e3:.2f}] mm = "
        f"{100 * used:.1f} % of the stops' [{low * 1e3:.0f}, {high * 1e3:.0f}] mm",
        f"  stop contacts    {run['stop_contacts']} "
        f"({100 * result.stop_contact.mean():.2f} % of the time in contact)",
        f"  locked           {100 * statistics['locked_fraction']:.1f} % of the time; "
        f"{run['stick_events']} stick events",
        f"  motor force      RMS {statistics['motor_force_rms']:.2f} N, "
        f"peak {np.abs(result.motor_force).max():.2f} N (limit {iso.motor_force_max:g} N)",
    ]
    deficit = iso.weight_deficit
    if deficit > 0:
        lines.append(
            f"  note             m*g = {iso.mass * iso.gravity:.2f} N exceeds the spring's "
            f"{iso.spring_force:.2f} N plateau: the PI integral must carry {deficit:.2f} N"
            + ("" if ctrl.pi_ki > 0 else " (pi_ki = 0: nothing does; the payload sinks)"))
    residual = np.abs(result.energy_residual()).max()
    scale = max(np.abs(result.base_work).max(), 1e-300)
    lines.append(f"  energy ledger    max residual {residual:.3g} J "
                 f"({residual / scale:.2g} of the base work)")
    lines.append(f"  time span        {t[0]:g} .. {t[-1]:g} s")
    return "\n".join(lines)
