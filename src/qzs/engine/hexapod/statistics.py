"""Run statistics of a six-axis run over every output sample, and the summary text.

Exact over the whole run however it is stored (in memory, or streamed to a file with only
a preview kept): what :meth:`~qzs.engine.hexapod.result.HexapodResult.summary` reports.
"""
import numpy as np

from qzs.analysis.statistics import BlockStatistics, RunStatistics
from qzs.analysis.summary import block_lines, excitation_part
from qzs.engine.channels import block_costs
from qzs.engine.hexapod.layout import (C_ACC, C_BASE_POSE, C_DF, C_DS, C_EG, C_EK, C_ESP,
                                       C_EST, C_FCO, C_FDI, C_FLI, C_FMO, C_FOB, C_POSE,
                                       C_TIME, C_WB, C_WM, C_Z, LEG_COUNT, O_LOCKED)

#: Each leg's block channels' first column (six columns, a leg each), as the rows hold them.
_BLOCK_COLUMNS = {"compensation_force": C_FCO, "friction_estimate": C_FOB,
                  "dither_force": C_FDI, "linear_force": C_FLI}


class _Statistics:
    """Running statistics of a hexapod run over every output sample, chunk by chunk.

    What the summary reports, exact over the whole run however it is stored (in memory
    or streamed to a file with only a preview kept): per leg the largest distance from the
    stops' centre [m], the share of samples locked [-], the motor force's RMS and largest
    magnitude [N]; the largest relative translation [m] and rotation [rad] of the platform;
    the largest energy-ledger residual [J] and |base work| [J]; with a leg's controller's
    blocks, what they cost (the single axis's :class:`BlockStatistics`, a leg per case: each
    block force's RMS [N], and the platform's acceleration at the leg's dither frequency:
    the amplitude of its top frame origin's translation [m/s^2]).
    """

    def __init__(self, centers, controllers=None):
        self._legs = RunStatistics(centers)  # the single axis's statistics, a leg per case
        costs = [block_costs(c) for c in controllers or ()]
        self._blocks = (BlockStatistics(*zip(*costs))
                        if any(names or dither is not None for names, dither in costs)
                        else None)
        self._rows = 0
        self._motor_max = np.zeros(LEG_COUNT)
        self._translation = self._rotation = 0.0
        self._residual = self._base_work = 0.0
        self._energy0 = None

    def add(self, block, flags):
        """Absorb output rows ``block`` (``N_CHANNELS`` columns) and their ``flags``."""
        if block.shape[0] == 0:
            return
        motor = block[:, C_FMO:C_FMO + LEG_COUNT]
        self._legs.add(block[:, C_Z:C_Z + LEG_COUNT].T, motor.T,
                       flags[:, O_LOCKED:O_LOCKED + LEG_COUNT].T)
        self._motor_max = np.maximum(self._motor_max, np.max(np.abs(motor), axis=0))
        pose = block[:, C_POSE:C_POSE + 6] - block[:, C_BASE_POSE:C_BASE_POSE + 6]
        self._translation = max(self._translation, float(np.max(np.abs(pose[:, :3]))))
        self._rotation = max(self._rotation, float(np.max(np.abs(pose[:, 3:]))))
        energy = block[:, C_EK] + block[:, C_ESP] + block[:, C_EG] + block[:, C_EST]
        if self._energy0 is None:
            self._energy0 = float(energy[0])
        net = block[:, C_WB] + block[:, C_WM] - block[:, C_DF] - block[:, C_DS]
        self._residual = max(self._residual,
                             float(np.max(np.abs(energy - self._energy0 - net))))
        self._base_work = max(self._base_work, float(np.max(np.abs(block[:, C_WB]))))
        if self._blocks is not None:
            self._blocks.add(block[:, C_TIME],
                             {name: block[:, column:column + LEG_COUNT].T
                              for name, column in _BLOCK_COLUMNS.items()},
                             block[:, C_ACC:C_ACC + 3].T)
        self._rows += block.shape[0]

    def result(self):
        """The statistics as a dict of floats and per-leg lists, with their units in the keys."""
        legs = self._legs.result()
        return {"samples": self._rows, "stroke_used_m": legs["peak_stroke"].tolist(),
                "locked_share": legs["locked_fraction"].tolist(),
                "motor_rms_N": legs["motor_force_rms"].tolist(),
                "motor_max_N": self._motor_max.tolist(),
                "relative_translation_max_m": self._translation,
                "relative_rotation_max_rad": self._rotation,
                "energy_residual_max_J": self._residual, "base_work_max_J": self._base_work,
                **({} if self._blocks is None else
                   {"blocks": [self._blocks.result(i) for i in range(LEG_COUNT)]})}


def _summary_text(result):
    """The text of :meth:`HexapodResult.summary` (from the statistics of every sample)."""
    run = result.run
    stats = result.statistics
    moving = "; ".join(f"{axis}: {excitation_part(e, run['duration'])}"
                       for axis, e in result.excitation.items())
    residual = stats["energy_residual_max_J"]
    scale = max(stats["base_work_max_J"], 1e-300)
    lines = [f"Hexapod run: {run['duration']:g} s, {run['solver']} dt = {run['dt']:g} s, "
             f"{run['steps']:,} steps in {run['elapsed']:.3g} s "
             f"({result.steps_per_second:,.0f} steps/s), {run['events']:,} located transitions",
             *_step_line(run),
             f"Base excitation: {moving or 'none'}",
             f"Platform: {result.platform.mass:g} kg, gravity {result.platform.gravity:g} m/s^2",
             "Control: " + ("PI + damping loops on the platform's axes (centralised)"
                            if run.get("control") == "centralised" else "a PI + damping loop "
                            "per leg")
             + (f", sampled at {run['controller_rate']:g} Hz (zero-order hold)"
                if run.get("controller_rate") else ", continuous"),
             "",
             "leg  stroke used [mm]  of [mm]  contacts  locked [%]  stick events  "
             "motor RMS [N]  motor max [N]"]
    for i in range(LEG_COUNT):
        low, high = run["stops"][i]
        lines.append(f"{i + 1:>3}  {1e3 * stats['stroke_used_m'][i]:16.2f}  "
                     f"{1e3 * (high - low) / 2:7.1f}  "
                     f"{run['stop_contacts'][i]:8d}  {100 * stats['locked_share'][i]:10.1f}  "
                     f"{run['stick_events'][i]:12d}  {stats['motor_rms_N'][i]:13.2f}  "
                     f"{stats['motor_max_N'][i]:13.2f}")
    lines += _block_cost_lines(result)
    lines += ["",
              f"Platform relative to base: translation up to "
              f"{1e3 * stats['relative_translation_max_m']:.3g} mm, rotation up to "
              f"{1e3 * stats['relative_rotation_max_rad']:.3g} mrad",
              f"Energy ledger residual: max {residual:.3g} J ({residual / scale:.2g} of the "
              f"largest |base work|)"]
    if not run.get("completed", True):
        lines.append(f"Interrupted: {run['samples']:,} samples up to "
                     f"t = {run['steps'] * run['dt']:.6g} s of {run['duration']:g} s.")
    if run.get("preview_every", 1) > 1:
        lines.append(f"In memory: the min/max envelope of groups of {run['preview_every']} "
                     "samples (a preview; the file holds them all)")
    return "\n".join(lines)


def _block_cost_lines(result):
    """Each leg's controller with blocks and what they cost, as a single run's summary says
    it (:func:`qzs.analysis.summary.block_lines`)."""
    stats = result.statistics
    lines = []
    for i, controller in enumerate(result.controllers):
        if "blocks" in stats and controller.has_blocks:
            lines += ["", f"Leg {i + 1}:", *block_lines(
                controller, {**stats["blocks"][i], "motor_force_rms": stats["motor_rms_N"][i]},
                payload="platform acceleration")]
    return lines


def _step_line(run):
    """How the run's step was chosen, where the caller recorded it (``run["step"]``)."""
    from qzs.engine.step_search import record_line

    return [f"Step: {record_line(run)}"] if "step" in run else []
