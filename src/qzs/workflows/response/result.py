"""The steady-state response's results: one point per frequency and sweep, and the whole.

:class:`ResponsePoint` is what :mod:`~qzs.workflows.response.frequency` finds at one
frequency; :class:`SteadyStateResponse` holds the sweeps with the harmonic balance, the
linear model and the chirp beside them, and reads them (branches, jumps, hysteresis, a
table). Its files are written by :mod:`~qzs.workflows.response.files`, its figure by
:mod:`qzs.viz.response`.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from qzs._format import decibels
from qzs._validation import choice
from qzs.workflows.response.files import POINT_FIELDS, RESPONSE_SUFFIXES, response_dataset

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.analysis.harmonic_balance import FrequencyResponseCurve
    from qzs.analysis.spectral import TransmissibilityEstimate
    from qzs.engine.accuracy import StepChoice
    from qzs.model.controller import ControllerParameters
    from qzs.model.isolator import IsolatorParameters

__all__ = ["ResponsePoint", "SteadyStateResponse"]


@dataclass(frozen=True)
class ResponsePoint:
    """The steady state at one frequency of one sweep (NaN where undefined, with ``reason``).

    Attributes
    ----------
    direction : str
        ``"up"`` or ``"down"``: the sweep the point belongs to.
    frequency : float
        Excitation frequency [Hz].
    transmissibility : float
        Fundamental amplitude ratio of payload to base acceleration [-].
    phase : float
        Phase of the payload's fundamental relative to the base's [rad].
    harmonics : tuple of float
        Payload acceleration at harmonics 2, 3, ... of the excitation over the base's
        fundamental [-].
    subharmonic : float
        Largest payload acceleration at a sub-harmonic (``j f / period_multiple``, j not a
        multiple of it) over the base's fundamental [-]; 0 for a period-1 response.
    period_multiple : int
        The response repeats every this many excitation periods (1, 2 or 3) [-]; 0 if it
        did not become periodic.
    relative_amplitude : float
        Fundamental amplitude of the relative position z [m].
    relative_peak : float
        Half the peak-to-peak relative position over the steady period(s) [m].
    mean_relative_position : float
        Mean relative position [m].
    locked_fraction : float
        Share of the period the payload is locked (stuck, or resting on a plastic stop) [-].
    stop_contacts : float
        Hard-stop contacts per period [-].
    saturated_fraction : float
        Share of the period the motor command is at its limit [-].
    periods : int
        Periods simulated at this frequency, fade-in included [-].
    settle_time : float
        Simulated time at this frequency [s].
    residual : float
        Scaled state change over the last period (or ``period_multiple`` periods) [-].
    converged : bool
        The response became periodic within the tolerance.
    reason : str
        Why the point is NaN ('' if converged).
    start : str
        ``"rest"`` (from rest, with a fade-in) or ``"continued"`` (from the previous
        frequency's final state).
    dt : float
        Integration step at this frequency [s]: ``1/(frequency*steps)`` with a whole
        number of steps per period.
    seconds : float
        Wall time of this frequency [s].
    """

    direction: str
    frequency: float
    transmissibility: float
    phase: float
    harmonics: tuple
    subharmonic: float
    period_multiple: int
    relative_amplitude: float
    relative_peak: float
    mean_relative_position: float
    locked_fraction: float
    stop_contacts: float
    saturated_fraction: float
    periods: int
    settle_time: float
    residual: float
    converged: bool
    reason: str
    start: str
    dt: float
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """The point as a plain dict (``harmonics`` as a list).

        Returns
        -------
        dict
        """
        record = dataclasses.asdict(self)
        record["harmonics"] = list(self.harmonics)
        return record


@dataclass(frozen=True, eq=False)
class SteadyStateResponse:
    """Result of :func:`~qzs.workflows.response.sweep.steady_state_response`.

    Attributes
    ----------
    points : tuple of ResponsePoint
        Every frequency of every sweep, each sweep in the order it ran.
    frequencies : ndarray
        The frequencies asked for, ascending [Hz].
    amplitude : float
        Base displacement amplitude [m].
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    solver : str
        Integrator.
    dt : float
        The largest integration step [s] (each frequency uses the largest step at most this
        that divides its period into a whole number of output samples).
    step : StepChoice or None
        The accuracy-driven choice of ``dt`` (None when ``dt`` was given).
    settings : dict
        ``periodic_tolerance`` [-], ``max_periods``, ``max_time`` [s],
        ``samples_per_period``, ``fade_in`` [s], ``harmonics``, ``workers``.
    balance : FrequencyResponseCurve or None
        Harmonic balance of the smooth model over the range (None if not asked or failed).
    linear : dict
        The linearised closed loop: ``frequency`` [Hz] and ``transmissibility`` [-] on a
        fine grid over the range, and ``at_frequencies`` [-], its value at
        :attr:`frequencies`.
    chirp : TransmissibilityEstimate or None
        The paper's chirp-and-Welch estimate for the same case (None if not asked).
    notes : tuple of str
        What the reader should know (step choice, harmonic balance, unconverged points).
    elapsed : float
        Wall time of the whole response [s].
    """

    points: tuple[ResponsePoint, ...]
    frequencies: np.ndarray
    amplitude: float
    isolator: IsolatorParameters
    controller: ControllerParameters
    solver: str
    dt: float
    step: StepChoice | None
    settings: dict
    balance: FrequencyResponseCurve | None = None
    linear: dict = field(default_factory=dict)
    chirp: TransmissibilityEstimate | None = None
    notes: tuple[str, ...] = ()
    elapsed: float = 0.0

    @property
    def directions(self) -> tuple[str, ...]:
        """The sweeps run, in the order ``up``, ``down`` [-]."""
        present = {p.direction for p in self.points}
        return tuple(d for d in ("up", "down") if d in present)

    def branch(self, direction: str) -> dict[str, np.ndarray]:
        """One sweep's points as arrays in ascending frequency.

        Parameters
        ----------
        direction : {"up", "down"}
            The sweep.

        Returns
        -------
        dict of ndarray
            Every field of :class:`ResponsePoint` (``harmonics`` as shape (n, k)).
        """
        choice("direction", direction, self.directions)
        points = sorted((p for p in self.points if p.direction == direction),
                        key=lambda p: p.frequency)
        out = {"frequency": np.array([p.frequency for p in points])}
        for name in POINT_FIELDS:
            out[name] = np.array([getattr(p, name) for p in points], dtype=float)
        out["harmonics"] = np.array([p.harmonics for p in points], dtype=float)
        for name in ("reason", "start", "direction"):
            out[name] = np.array([getattr(p, name) for p in points], dtype=object)
        return out

    def chirp_at(self, frequencies: ArrayLike | None = None) -> np.ndarray:
        """The chirp estimate at ``frequencies``, between trusted bins only (NaN elsewhere).

        Parameters
        ----------
        frequencies : array_like, optional
            Where to read it [Hz]; default :attr:`frequencies`.

        Returns
        -------
        ndarray
            Amplitude ratio [-]; all NaN without a chirp.
        """
        from qzs.analysis.spectral import transmissibility_at

        at = self.frequencies if frequencies is None else np.asarray(frequencies, float)
        if self.chirp is None:
            return np.full(np.shape(at), np.nan)
        return transmissibility_at(self.chirp.frequency, self.chirp.magnitude, at,
                                   trusted=self.chirp.trusted)

    def hysteresis(self, threshold_db: float = 0.1) -> np.ndarray:
        """Frequencies where the up and down sweeps settle on different responses.

        Parameters
        ----------
        threshold_db : float
            Smallest difference of the transmissibility counted [dB].

        Returns
        -------
        ndarray
            The frequencies [Hz] (empty with one sweep).
        """
        if self.directions != ("up", "down"):
            return np.array([])
        up, down = self.branch("up"), self.branch("down")
        with np.errstate(divide="ignore", invalid="ignore"):
            gap = np.abs(decibels(up["transmissibility"] / down["transmissibility"]))
        return up["frequency"][gap > threshold_db]

    def jumps(self, threshold_db: float = 1.0,
              agreement_db: float = 0.1) -> dict[str, list[tuple[float, float]]]:
        """Where each sweep jumps from one branch to another.

        A sweep jumps between neighbouring frequencies where it lands on the other sweep's
        response (the two agree within ``agreement_db`` there) after leaving a point where
        they differ, its transmissibility changing by more than ``threshold_db``: the edges
        of a band where two responses coexist. Needs both sweeps (an empty dict
        otherwise); NaN points are never an edge.

        Parameters
        ----------
        threshold_db : float
            Least change across the pair [dB].
        agreement_db : float
            Largest difference of the sweeps that counts as the same response [dB].

        Returns
        -------
        dict of str to list of (float, float)
            Direction -> ``(from, to)`` frequency pairs [Hz], in the sweep's order.
        """
        if self.directions != ("up", "down"):
            return {}
        with np.errstate(divide="ignore", invalid="ignore"):
            db = {d: decibels(self.branch(d)["transmissibility"]) for d in self.directions}
            agree = np.abs(db["up"] - db["down"]) <= agreement_db
        f = self.frequencies
        up, down = [], []
        finite = np.isfinite(db["up"]) & np.isfinite(db["down"])
        for i in range(f.size - 1):
            if not (finite[i] and finite[i + 1]):
                continue
            if (agree[i + 1] and not agree[i]
                    and abs(db["up"][i + 1] - db["up"][i]) > threshold_db):
                up.append((float(f[i]), float(f[i + 1])))
            if (agree[i] and not agree[i + 1]
                    and abs(db["down"][i] - db["down"][i + 1]) > threshold_db):
                down.append((float(f[i + 1]), float(f[i])))
        return {"up": up, "down": down[::-1]}

    def to_records(self) -> list[dict[str, Any]]:
        """One plain dict per point (``frequency`` [Hz], ``transmissibility`` [-] and the
        rest of :class:`ResponsePoint`), with the chirp estimate and the linear model's
        value at its frequency.

        Returns
        -------
        list of dict
        """
        chirp = dict(zip(self.frequencies.tolist(), self.chirp_at().tolist()))
        linear = dict(zip(self.frequencies.tolist(), self._linear_at(self.frequencies)))
        records = []
        for p in self.points:
            record = p.to_dict()
            record["linear_transmissibility"] = linear.get(p.frequency, math.nan)
            if self.chirp is not None:
                record["chirp_transmissibility"] = chirp.get(p.frequency, math.nan)
            records.append(record)
        return records

    def _linear_at(self, frequencies):
        if not self.linear:
            return [math.nan] * len(frequencies)
        return np.asarray(self.linear["at_frequencies"], dtype=float).tolist()

    def to_record(self) -> dict[str, Any]:
        """The whole response as data, for ``--json``.

        Returns
        -------
        dict
            ``points`` (see :meth:`to_records`), ``amplitude`` [m], ``dt`` [s], ``solver``,
            ``settings``, ``step`` (the accuracy choice or None), ``balance`` (the curve or
            None), ``jumps``, ``hysteresis`` [Hz], ``notes``, ``elapsed`` [s].
        """
        step = None if self.step is None else self.step.to_dict()
        return {"points": self.to_records(), "amplitude": self.amplitude, "dt": self.dt,
                "solver": self.solver, "settings": dict(self.settings), "step": step,
                "balance": None if self.balance is None else self.balance.to_dict(),
                "jumps": {k: [list(p) for p in v] for k, v in self.jumps().items()},
                "hysteresis": self.hysteresis().tolist(), "notes": list(self.notes),
                "elapsed": self.elapsed}

    def summary(self) -> str:
        """A table of the sweeps and what to know about them.

        Returns
        -------
        str
        """
        lines = [f"steady-state response  {len(self.frequencies)} frequencies "
                 f"{self.frequencies[0]:g}-{self.frequencies[-1]:g} Hz, base amplitude "
                 f"{self.amplitude * 1e3:g} mm, {self.solver} dt <= {self.dt:.3g} s, "
                 f"{'/'.join(self.directions)} in {self.elapsed:.1f} s"]
        branches = {d: self.branch(d) for d in self.directions}
        header = "  f [Hz]  " + "  ".join(f"T_{d:<4} [dB] locked per." for d in self.directions)
        if self.chirp is not None:
            header += "  chirp [dB]"
        lines.append(header)
        chirp = self.chirp_at()
        for i, f in enumerate(self.frequencies):
            row = f"  {f:7.3f} "
            for d in self.directions:
                b = branches[d]
                t = b["transmissibility"][i]
                db = f"{decibels(t):+8.2f}" if t > 0 else "     nan"
                row += (f"  {db}    {b['locked_fraction'][i]:5.2f}  "
                        f"{int(b['periods'][i]):4d}")
            if self.chirp is not None:
                row += (f"  {decibels(chirp[i]):+8.2f}" if chirp[i] > 0 else "       nan")
            lines.append(row)
        for direction, pairs in self.jumps().items():
            if pairs:
                lines.append(f"  jumps ({direction}): " + ", ".join(
                    f"{a:g} -> {b:g} Hz" for a, b in pairs))
        gap = self.hysteresis()
        if gap.size:
            lines.append(f"  up and down differ (> 0.1 dB) at {gap.size} frequencies, "
                         f"{gap.min():g}-{gap.max():g} Hz")
        if self.balance is not None and self.balance.folds:
            lines.append("  harmonic balance folds at " + ", ".join(
                f"{f:.4g}" for f in self.balance.folds) + " Hz")
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)

    def to_xarray(self) -> xr.Dataset:
        """The response as an ``xarray.Dataset``: sweeps on ``(direction, frequency)``.

        Variables of :class:`ResponsePoint` on ``(direction, frequency)`` (``harmonics`` on
        ``(direction, frequency, harmonic)``, ``reason`` and ``start`` as strings), the
        linear model on ``linear_frequency``, the harmonic balance on ``balance_point``,
        the chirp estimate on ``chirp_frequency``; every parameter as a global attribute
        ``isolator.<name>`` / ``controller.<name>`` with its unit.

        Returns
        -------
        xarray.Dataset
        """
        return response_dataset(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> Figure:
        """The figure (:func:`qzs.viz.response.plot_response`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (format from the extension).
        title : str, optional
            Figure title.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.response import plot_response

        return plot_response(self, path=path, title=title, frequency_scale=frequency_scale)

    #: The extensions :meth:`save` accepts.
    save_suffixes = RESPONSE_SUFFIXES

    def save(self, path: str | Path) -> Path:
        """Write the response atomically: ``.nc`` (NetCDF), ``.csv`` (one row per point),
        ``.json`` (:meth:`to_record`) or ``.mat`` (MATLAB, the NetCDF's variables).

        Parameters
        ----------
        path : str or Path
            The file; its extension chooses the format.

        Returns
        -------
        Path
        """
        from qzs.workflows.response.files import write_response

        return write_response(self, path)
