"""Run statistics: stroke, time locked, motor effort, accumulated block by block.

One implementation serves a single run (one block), the batch engine (chunk by
chunk while it integrates, one row per case), the paper's studies and the run
summary.
"""
import numpy as np

__all__ = ["RunStatistics", "run_statistics", "STATISTICS"]

#: Statistics of a run: name -> (unit, description).
STATISTICS = {
    "z_min": ("m", "lowest relative position"),
    "z_max": ("m", "highest relative position"),
    "peak_stroke": ("m", "largest |z - stop_center|"),
    "motor_force_rms": ("N", "RMS motor force"),
    "locked_fraction": ("1", "fraction of samples locked"),
}


class RunStatistics:
    """Statistics of ``n_cases`` runs, fed with consecutive blocks of samples.

    Parameters
    ----------
    stop_centers : array_like, shape (n_cases,)
        Centre of each case's stroke in relative position [m]: the peak stroke is
        measured from it.
    """

    def __init__(self, stop_centers):
        self.centers = np.atleast_1d(np.asarray(stop_centers, dtype=float))
        n = self.centers.size
        self.z_min = np.full(n, np.inf)
        self.z_max = np.full(n, -np.inf)
        self.peak = np.zeros(n)
        self.force_squares = np.zeros(n)
        self.locked = np.zeros(n)
        self.counted = np.zeros(n)

    def add(self, relative_position, motor_force, locked):
        """Absorb one block of samples of every case.

        Parameters
        ----------
        relative_position : ndarray, shape (n_cases, n_samples)
            Relative position z [m].
        motor_force : ndarray, shape (n_cases, n_samples)
            Motor force [N].
        locked : ndarray of bool, shape (n_cases, n_samples)
            Whether the payload is held at zero slip.
        """
        z = relative_position
        self.z_min = np.minimum(self.z_min, z.min(axis=1))
        self.z_max = np.maximum(self.z_max, z.max(axis=1))
        self.peak = np.maximum(self.peak, np.abs(z - self.centers[:, None]).max(axis=1))
        self.force_squares += (motor_force ** 2).sum(axis=1)
        self.locked += locked.sum(axis=1)
        self.counted += z.shape[1]

    def result(self):
        """The statistics so far: name (see :data:`STATISTICS`) -> array of shape (n_cases,)."""
        counted = np.maximum(self.counted, 1)
        return {"z_min": self.z_min, "z_max": self.z_max, "peak_stroke": self.peak,
                "motor_force_rms": np.sqrt(self.force_squares / counted),
                "locked_fraction": self.locked / counted}


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
