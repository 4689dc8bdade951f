"""Run statistics: stroke, time locked, motor effort, accumulated block by block.

One implementation serves a single run (one block), the batch engine (chunk by
chunk while it integrates, one row per case), the paper's studies and the run
summary.
"""
import numpy as np

import math

__all__ = ["RunStatistics", "run_statistics", "STATISTICS", "SATURATION", "SummaryStatistics",
           "SUMMARY_STATISTICS", "BLOCK_STATISTICS", "BlockStatistics"]

#: Statistics of a run: name -> (unit, description).
STATISTICS = {
    "z_min": ("m", "lowest relative position"),
    "z_max": ("m", "highest relative position"),
    "peak_stroke": ("m", "largest |z - stop_center|"),
    "motor_force_rms": ("N", "RMS motor force"),
    "locked_fraction": ("1", "fraction of samples locked"),
}

#: The statistic :class:`RunStatistics` adds where it knows the motor's limits.
SATURATION = {"saturated_fraction": ("1", "fraction of samples where the loops ask for the "
                                          "motor's limit or more")}


class RunStatistics:
    """Statistics of ``n_cases`` runs, fed with consecutive blocks of samples.

    Parameters
    ----------
    stop_centers : array_like, shape (n_cases,)
        Centre of each case's stroke in relative position [m]: the peak stroke is
        measured from it.
    force_limits : array_like, shape (n_cases,), optional
        Each case's motor force limit [N]. Given, :meth:`result` adds
        ``saturated_fraction`` (:data:`SATURATION`): the share of samples whose motor
        force sits at the limit, which is where the loops ask for the limit or more (the
        motor force is the loops' demand clipped to it).
    """

    def __init__(self, stop_centers, force_limits=None):
        self.centers = np.atleast_1d(np.asarray(stop_centers, dtype=float))
        n = self.centers.size
        self.limits = (None if force_limits is None
                       else np.broadcast_to(np.asarray(force_limits, dtype=float), (n,)))
        self.saturated = np.zeros(n)
        self.z_min = np.full(n, np.inf)
        self.z_max = np.full(n, -np.inf)
        self.peak = np.zeros(n)
        self.force_squares = np.zeros(n)
        self.locked = np.zeros(n)
        self.counted = np.zeros(n)

    def add(self, relative_position, motor_force, locked, cases=slice(None)):
        """Absorb one block of samples of every case, or of the cases ``cases``.

        Blocks of disjoint ``cases`` may be added from different threads at once.

        Parameters
        ----------
        relative_position : ndarray, shape (n_cases, n_samples)
            Relative position z [m].
        motor_force : ndarray, shape (n_cases, n_samples)
            Motor force [N].
        locked : ndarray of bool, shape (n_cases, n_samples)
            Whether the payload is held at zero slip.
        cases : slice
            The cases the rows are (default all).
        """
        z = relative_position
        self.z_min[cases] = np.minimum(self.z_min[cases], z.min(axis=1))
        self.z_max[cases] = np.maximum(self.z_max[cases], z.max(axis=1))
        self.peak[cases] = np.maximum(self.peak[cases],
                                      np.abs(z - self.centers[cases, None]).max(axis=1))
        self.force_squares[cases] += (motor_force ** 2).sum(axis=1)
        self.locked[cases] += locked.sum(axis=1)
        self.counted[cases] += z.shape[1]
        if self.limits is not None:
            at_limit = np.abs(motor_force) >= self.limits[cases, None] * (1.0 - 1e-9)
            self.saturated[cases] += at_limit.sum(axis=1)

    def result(self):
        """The statistics so far: name (see :data:`STATISTICS`) -> array of shape (n_cases,)."""
        counted = np.maximum(self.counted, 1)
        result = {"z_min": self.z_min, "z_max": self.z_max, "peak_stroke": self.peak,
                  "motor_force_rms": np.sqrt(self.force_squares / counted),
                  "locked_fraction": self.locked / counted}
        if self.limits is not None:
            result["saturated_fraction"] = self.saturated / counted
        return result


def run_statistics(relative_position, motor_force, locked, stop_center):
    """Statistics of one run (see :data:`STATISTICS`) as floats.

    Parameters
    ----------
    relative_position : array_like, shape (n_samples,)
        Relative position z [m].
    motor_force : array_like, shape (n_samples,)
        Motor force [N].
    locked : array_like of bool, shape (n_samples,)
        Whether the payload is held at zero slip.
    stop_center : float
        Centre of the stroke [m].
    """
    statistics = RunStatistics([stop_center])
    statistics.add(np.asarray(relative_position, dtype=float)[None, :],
                   np.asarray(motor_force, dtype=float)[None, :],
                   np.asarray(locked, dtype=bool)[None, :])
    return {name: float(value[0]) for name, value in statistics.result().items()}


class BlockStatistics:
    """What controller blocks cost, accumulated exactly over consecutive blocks of samples.

    One implementation for a single run (one case) and a six-axis platform (a leg per case):
    each block channel's RMS [N] and, with a dither, the payload's acceleration amplitude at
    the dither's frequency [m/s^2] (a single-frequency Fourier coefficient over the samples;
    of several acceleration components, the Euclidean norm of their amplitudes).

    Parameters
    ----------
    blocks : sequence of sequence of str
        Per case, the channels of its controller's blocks (``compensation_force``,
        ``dither_force``, ``linear_force``, ``friction_estimate``).
    dither_frequencies : sequence of float or None
        Per case, its dither's frequency [Hz], or None without a dither.
    """

    def __init__(self, blocks, dither_frequencies):
        self.blocks = [tuple(names) for names in blocks]
        self.squares = [dict.fromkeys(names, 0.0) for names in self.blocks]
        self.omegas = [None if f is None else 2 * np.pi * f for f in dither_frequencies]
        self.sums = [None] * len(self.omegas)
        self.count = 0

    def add(self, time, forces, acceleration):
        """Absorb one block of consecutive samples of every case.

        Parameters
        ----------
        time : ndarray, shape (n_samples,)
            Sample times [s].
        forces : mapping of str to ndarray, shape (n_cases, n_samples)
            The block channels [N] (those of :attr:`blocks`).
        acceleration : ndarray, shape (n_components, n_samples)
            The payload's acceleration [m/s^2] (of a platform: its translation's components).
        """
        self.count += len(time)
        for case, names in enumerate(self.blocks):
            for name in names:
                values = forces[name][case]
                with np.errstate(over="ignore"):  # a diverging controller's RMS is inf
                    self.squares[case][name] += float(np.dot(values, values))
        for case, omega in enumerate(self.omegas):
            if omega is None:
                continue
            phase = np.exp(-1j * omega * np.asarray(time, dtype=float))
            sums = [complex(np.dot(np.asarray(component), phase)) for component in acceleration]
            self.sums[case] = (sums if self.sums[case] is None
                               else [a + b for a, b in zip(self.sums[case], sums)])

    def result(self, case=0):
        """The statistics of one case so far (the names of :data:`BLOCK_STATISTICS`).

        Parameters
        ----------
        case : int
            The case (a leg of a platform), from 0.

        Returns
        -------
        dict
            ``<block channel>_rms`` [N], and ``dither_payload_acceleration`` [m/s^2] with a
            dither.
        """
        counted = max(self.count, 1)
        out = {f"{name}_rms": float(np.sqrt(total / counted))
               for name, total in self.squares[case].items()}
        if self.omegas[case] is not None:
            sums = self.sums[case] or [0j]
            out["dither_payload_acceleration"] = 2 * math.hypot(*map(abs, sums)) / counted
        return out


class SummaryStatistics:
    """What a run's summary reports, accumulated exactly over consecutive blocks of samples.

    A run that streams its samples to a file keeps only a preview in memory; its
    summary still comes from every sample, block by block, as they are written.
    The stroke, locked share and motor RMS come from :class:`RunStatistics` (one
    implementation for single runs, batches and studies).

    Parameters
    ----------
    stop_center : float
        Centre of the stroke [m].
    motor_force_max : float
        The motor's force limit [N]: a sample saturates when the loops ask for it or more
        (the conditional-integration anti-windup holds the integral at the limit).
    blocks : sequence of str
        The channels of the controller's blocks the run records (``compensation_force``,
        ``dither_force``, ``linear_force``, ``friction_estimate``): each one's RMS is
        reported, and they count in what the loops ask of the motor.
    dither_frequency : float, optional
        A dither's frequency [Hz]: the payload acceleration's amplitude at it is reported
        (a single-frequency Fourier coefficient over the samples), the dither's cost.
    """

    def __init__(self, stop_center, motor_force_max, blocks=(), dither_frequency=None):
        self.run = RunStatistics([stop_center])
        self.force_limit = float(motor_force_max)
        self.blocks = tuple(blocks)
        self.block_costs = BlockStatistics([self.blocks], [dither_frequency])
        self.count = 0
        self.z_sum = 0.0
        self.z_last = np.nan
        self.contact = 0
        self.saturated = 0
        self.motor_peak = 0.0
        self.energy_start = None
        self.residual_max = 0.0
        self.base_work_max = 0.0
        self.time_first = np.nan
        self.time_last = np.nan

    def add(self, block):
        """Absorb one block of consecutive samples.

        Parameters
        ----------
        block : mapping of str to ndarray, each shape (n_samples,)
            ``time`` [s], ``relative_position`` [m], ``motor_force`` [N], ``pi_force`` [N],
            ``damping_force`` [N], ``locked`` and ``stop_contact`` (bool),
            ``mechanical_energy`` [J] (kinetic + spring + gravity + stop),
            ``base_work``, ``motor_work``, ``friction_dissipation`` and
            ``stop_dissipation`` [J].
        """
        z = np.asarray(block["relative_position"], dtype=float)
        if z.size == 0:
            return
        motor = np.asarray(block["motor_force"], dtype=float)
        self.run.add(z[None, :], motor[None, :], np.asarray(block["locked"], bool)[None, :])
        if self.count == 0:
            self.time_first = float(block["time"][0])
            self.energy_start = float(block["mechanical_energy"][0])
        self.count += z.size
        self.z_sum += float(z.sum())
        self.z_last = float(z[-1])
        self.time_last = float(block["time"][-1])
        self.contact += int(np.count_nonzero(block["stop_contact"]))
        asked = np.asarray(block["pi_force"]) + np.asarray(block["damping_force"])
        forces = {name: np.asarray(block[name], dtype=float)[None, :] for name in self.blocks}
        for name in self.blocks:
            if name != "friction_estimate":  # it is in the compensation's force
                asked = asked + forces[name][0]
        self.block_costs.add(block["time"], forces,
                             [block["payload_acceleration"]]
                             if self.block_costs.omegas[0] is not None else ())
        asked = np.abs(asked)
        self.saturated += int(np.count_nonzero(asked >= self.force_limit * (1.0 - 1e-9)))
        self.motor_peak = max(self.motor_peak, float(np.abs(motor).max()))
        net = (block["base_work"] + block["motor_work"] - block["friction_dissipation"]
               - block["stop_dissipation"])
        residual = block["mechanical_energy"] - self.energy_start - net
        self.residual_max = max(self.residual_max, float(np.abs(residual).max()))
        self.base_work_max = max(self.base_work_max, float(np.abs(block["base_work"]).max()))

    def result(self):
        """The statistics so far (see :data:`SUMMARY_STATISTICS`) as floats and ints."""
        run = {name: float(value[0]) for name, value in self.run.result().items()}
        counted = max(self.count, 1)
        return {**run, "samples": self.count, "z_mean": self.z_sum / counted,
                "z_final": self.z_last, "contact_fraction": self.contact / counted,
                "saturated_fraction": self.saturated / counted, "motor_force_peak": self.motor_peak,
                "energy_residual_max": self.residual_max, "base_work_max": self.base_work_max,
                "time_first": self.time_first, "time_last": self.time_last,
                **self.block_costs.result()}


#: What :meth:`SummaryStatistics.result` holds beyond :data:`STATISTICS`: name -> (unit,
#: description).
SUMMARY_STATISTICS = {
    **STATISTICS,
    "samples": ("1", "samples summarised"),
    "z_mean": ("m", "mean relative position"),
    "z_final": ("m", "last relative position"),
    "contact_fraction": ("1", "fraction of samples in contact with a stop"),
    **SATURATION,
    "motor_force_peak": ("N", "largest |motor force|"),
    "energy_residual_max": ("J", "largest |energy-ledger residual|"),
    "base_work_max": ("J", "largest |work done by the base|"),
    "time_first": ("s", "time of the first sample"),
    "time_last": ("s", "time of the last sample"),
}
#: What a run whose controller has blocks adds (each only with its block).
BLOCK_STATISTICS = {
    "compensation_force_rms": ("N", "RMS friction compensation command"),
    "dither_force_rms": ("N", "RMS dither command"),
    "linear_force_rms": ("N", "RMS command of the linear controller"),
    "friction_estimate_rms": ("N", "RMS of the observer's friction estimate"),
    "dither_payload_acceleration": ("m/s^2", "payload acceleration amplitude at the dither "
                                             "frequency"),
}
