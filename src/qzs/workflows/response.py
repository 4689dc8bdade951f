"""Steady-state frequency response by stepped-sine simulation (docs/response.md).

For each frequency the isolator is simulated under a sine until its response is periodic:
the state at the same phase of successive periods agrees within a tolerance. Each frequency
starts from the last one's final state, in a sweep up and a sweep down, so that coexisting
branches and the jumps between them show. Then the fundamental amplitude ratio of payload to
base acceleration (the steady-state transmissibility), its higher harmonics, the relative
amplitude, the share of the period the payload is locked and the stop contacts are read from
the last period (or the last two or three, for a sub-harmonic response).

>>> import numpy as np
>>> from qzs.workflows.response import steady_state_response
>>> response = steady_state_response(np.linspace(0.5, 20, 40))  # doctest: +SKIP
>>> response.branch("up")["transmissibility"]  # doctest: +SKIP

The harmonic balance of the smooth model (:mod:`qzs.analysis.harmonic_balance`) is drawn over
it, with its unstable branch and folds; the paper's chirp-and-Welch estimate can be set beside
it (:func:`chirp_transmissibility`).
"""
import dataclasses
import math
import time
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from qzs import defaults
from qzs._validation import choice, integer, positive, worker_count
from qzs.errors import ParameterError, ToleranceNotMetError
from qzs.model.excitation import Chirp, Sine

__all__ = ["ResponsePoint", "SteadyStateResponse", "steady_state_response",
           "chirp_transmissibility", "steps_for", "DIRECTIONS", "RESPONSE_SUFFIXES",
           "SAMPLES_PER_PERIOD", "PERIODIC_TOLERANCE", "MAX_PERIODS", "settle_time_cap"]

#: Sweep directions: ``up`` (rising frequency), ``down`` (falling), ``both`` (one of each).
DIRECTIONS = ("up", "down", "both")
#: File formats :meth:`SteadyStateResponse.save` writes, by extension.
RESPONSE_SUFFIXES = (".nc", ".csv", ".json")
#: Output samples per period [-]: the DFT's length per period. A multiple of the kernels'
#: exact-sine period (256 steps), so a period is a whole number of kernel chunks and the
#: numbers are those of one uncut run (docs/model.md §9).
SAMPLES_PER_PERIOD = 256
#: Default tolerance of periodicity [-]: the state's change over a period, relative to the
#: base's amplitude (displacement, velocity, integral), and its extrapolated remainder.
PERIODIC_TOLERANCE = 1e-6
#: Successive periods that must meet the tolerance [-].
CONSECUTIVE_PERIODS = 3
#: Periods simulated at most per frequency [-] (a safety cap; the time cap usually ends it).
MAX_PERIODS = 100_000
#: By default a frequency may run this many of the linearised closed loop's slowest time
#: constants [-] (a linear decay from O(1) is then below 1e-13) before it is reported
#: unconverged: settling takes time constants, not periods (docs/response.md §3).
SETTLE_TIME_CONSTANTS = 30.0
#: The default time cap [s] is at least this, and this where the linear loop has no
#: decaying slowest mode (a pole at 0).
MIN_TIME = 60.0
#: ... and at most this [s].
MAX_TIME = 3600.0
#: Largest sub-harmonic order looked for [-]: period-2 and period-3 responses.
MAX_PERIOD_MULTIPLE = 3
#: A period-m response needs every shorter period's state change above this many
#: tolerances [-]: far from settling, not merely slower.
SUBHARMONIC_SEPARATION = 1000.0
#: Default fade-in [s] of the first frequency of a sweep (rounded up to whole periods).
FADE_IN = 2.0
#: Default highest harmonic reported [-] (2..this).
HARMONICS = 5
#: A frequency needs at least this many integration steps per period at ``dt`` [-]: a
#: tenth of the step's Nyquist rate (the simulate summary warns below 20 as well).
MIN_STEPS_PER_PERIOD = 20
#: Scaled state changes below this are round-off: the response repeats exactly [-].
ROUND_OFF = 1e-11
#: Chirp of the comparison: the paper's sweep rate [Hz/s] (0 -> 20 Hz over 2000 s).
PAPER_SWEEP_RATE = 0.01


# ---------------------------------------------------------------- results
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

    def to_dict(self):
        """The point as a plain dict (``harmonics`` as a list).

        Returns
        -------
        dict
        """
        record = dataclasses.asdict(self)
        record["harmonics"] = list(self.harmonics)
        return record


#: Numeric fields of :class:`ResponsePoint` with their units and descriptions.
POINT_FIELDS = {
    "transmissibility": ("1", "fundamental amplitude ratio of payload to base acceleration"),
    "phase": ("rad", "phase of the payload's fundamental relative to the base's"),
    "subharmonic": ("1", "largest sub-harmonic payload acceleration over the base's fundamental"),
    "period_multiple": ("1", "periods of the excitation per period of the response (0: none)"),
    "relative_amplitude": ("m", "fundamental amplitude of the relative position"),
    "relative_peak": ("m", "half the peak-to-peak relative position"),
    "mean_relative_position": ("m", "mean relative position"),
    "locked_fraction": ("1", "share of the period the payload is locked"),
    "stop_contacts": ("1", "hard-stop contacts per period"),
    "saturated_fraction": ("1", "share of the period the motor command is at its limit"),
    "periods": ("1", "periods simulated at this frequency"),
    "settle_time": ("s", "simulated time at this frequency"),
    "residual": ("1", "scaled state change over the last period(s)"),
    "converged": ("1", "1 if the response became periodic"),
    "dt": ("s", "integration step at this frequency"),
    "seconds": ("s", "wall time of this frequency"),
}


@dataclass(frozen=True, eq=False)
class SteadyStateResponse:
    """Result of :func:`steady_state_response`.

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

    points: tuple
    frequencies: np.ndarray
    amplitude: float
    isolator: object
    controller: object
    solver: str
    dt: float
    step: object
    settings: dict
    balance: object = None
    linear: dict = field(default_factory=dict)
    chirp: object = None
    notes: tuple = ()
    elapsed: float = 0.0

    @property
    def directions(self):
        """The sweeps run, in the order ``up``, ``down`` [-]."""
        present = {p.direction for p in self.points}
        return tuple(d for d in ("up", "down") if d in present)

    def branch(self, direction):
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

    def chirp_at(self, frequencies=None):
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

    def hysteresis(self, threshold_db=0.1):
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
            gap = np.abs(20 * np.log10(up["transmissibility"] / down["transmissibility"]))
        return up["frequency"][gap > threshold_db]

    def jumps(self, threshold_db=1.0, agreement_db=0.1):
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
            db = {d: 20 * np.log10(self.branch(d)["transmissibility"]) for d in self.directions}
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

    def to_records(self):
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

    def to_record(self):
        """The whole response as data, for ``--json``.

        Returns
        -------
        dict
            ``points`` (see :meth:`to_records`), ``amplitude`` [m], ``dt`` [s], ``solver``,
            ``settings``, ``step`` (the accuracy choice or None), ``balance`` (the curve or
            None), ``jumps``, ``hysteresis`` [Hz], ``notes``, ``elapsed`` [s].
        """
        step = None
        if self.step is not None:
            step = {"dt": self.step.dt, "error_db": self.step.error,
                    "tolerance_db": self.step.tolerance, "notes": list(self.step.notes)}
        return {"points": self.to_records(), "amplitude": self.amplitude, "dt": self.dt,
                "solver": self.solver, "settings": dict(self.settings), "step": step,
                "balance": None if self.balance is None else self.balance.to_dict(),
                "jumps": {k: [list(p) for p in v] for k, v in self.jumps().items()},
                "hysteresis": self.hysteresis().tolist(), "notes": list(self.notes),
                "elapsed": self.elapsed}

    def summary(self):
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
                db = f"{20 * math.log10(t):+8.2f}" if t > 0 else "     nan"
                row += (f"  {db}    {b['locked_fraction'][i]:5.2f}  "
                        f"{int(b['periods'][i]):4d}")
            if self.chirp is not None:
                row += (f"  {20 * math.log10(chirp[i]):+8.2f}" if chirp[i] > 0 else "       nan")
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

    def to_xarray(self):
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
        import xarray as xr

        from qzs._version import __version__

        directions = list(self.directions)
        n_harm = len(self.points[0].harmonics) if self.points else 0
        variables = {}
        branches = [self.branch(d) for d in directions]
        for name, (unit, doc) in POINT_FIELDS.items():
            values = np.array([b[name] for b in branches])
            if name in ("period_multiple", "periods"):
                values = values.astype(np.int64)
            elif name == "converged":
                values = values.astype(np.int8)
            variables[name] = (("direction", "frequency"), values,
                               {"units": unit, "long_name": doc})
        variables["harmonics"] = (("direction", "frequency", "harmonic"),
                                  np.array([b["harmonics"] for b in branches]).reshape(
                                      len(directions), self.frequencies.size, n_harm),
                                  {"units": "1", "long_name": "payload acceleration at the "
                                   "harmonic over the base's fundamental"})
        for name in ("reason", "start"):
            variables[name] = (("direction", "frequency"),
                               np.array([b[name] for b in branches], dtype=str), {})
        variables["linear_transmissibility"] = (
            ("linear_frequency",), np.asarray(self.linear.get("transmissibility", [])),
            {"units": "1", "long_name": "linearised closed loop |X/Y|"})
        coords = {"direction": ("direction", np.array(directions, dtype=str)),
                  "frequency": ("frequency", self.frequencies, {"units": "Hz"}),
                  "harmonic": ("harmonic", np.arange(2, 2 + n_harm), {"units": "1"}),
                  "linear_frequency": ("linear_frequency",
                                       np.asarray(self.linear.get("frequency", [])),
                                       {"units": "Hz"})}
        if self.balance is not None:
            b = self.balance
            coords["balance_point"] = ("balance_point", np.arange(b.frequency.size))
            variables.update({
                "balance_frequency": ("balance_point", b.frequency, {"units": "Hz"}),
                "balance_transmissibility": ("balance_point", b.transmissibility,
                                             {"units": "1", "long_name": "harmonic balance, "
                                              "fundamental amplitude ratio"}),
                "balance_relative_amplitude": ("balance_point", b.relative_amplitude,
                                               {"units": "m"}),
                "balance_stable": ("balance_point", b.stable.astype(np.int8),
                                   {"units": "1", "long_name": "1 where stable (Hill)"}),
                "balance_valid": ("balance_point", b.valid.astype(np.int8),
                                  {"units": "1", "long_name": "1 within stops and saturation"})})
        if self.chirp is not None:
            coords["chirp_frequency"] = ("chirp_frequency", self.chirp.frequency,
                                         {"units": "Hz"})
            variables["chirp_transmissibility"] = (
                "chirp_frequency", self.chirp.magnitude,
                {"units": "1", "long_name": "chirp and Welch amplitude ratio (PSD ratio)"})
            variables["chirp_trusted"] = ("chirp_frequency", self.chirp.trusted.astype(np.int8),
                                          {"units": "1"})
        attrs = {"Conventions": "CF-1.10",
                 "title": "qzs steady-state frequency response of the semi-active QZS isolator",
                 "source": f"qzs {__version__}: stepped-sine simulation (docs/response.md)",
                 "qzs_version": __version__, "amplitude": self.amplitude,
                 "amplitude_units": "m", "dt": self.dt, "dt_units": "s",
                 "solver": self.solver, "elapsed": self.elapsed, "elapsed_units": "s",
                 "notes": " | ".join(self.notes)}
        for key, value in self.settings.items():
            attrs[f"settings.{key}"] = value
        attrs.update(_parameter_attributes(self.isolator, self.controller))
        return xr.Dataset(variables, coords=coords, attrs=attrs)

    def plot(self, path=None, title=None):
        """The figure (:func:`qzs.viz.response.plot_response`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (format from the extension).
        title : str, optional
            Figure title.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.response import plot_response

        return plot_response(self, path=path, title=title)

    def save(self, path):
        """Write the response atomically: ``.nc`` (NetCDF), ``.csv`` (one row per point) or
        ``.json`` (:meth:`to_record`).

        Parameters
        ----------
        path : str or Path
            The file; its extension chooses the format.

        Returns
        -------
        Path
        """
        from qzs.iotools.files import atomic_path
        from qzs.iotools.paths import check_output_path

        path = check_output_path(path, argument="path", suffixes=RESPONSE_SUFFIXES)
        suffix = path.suffix.lower()
        with atomic_path(path) as tmp:
            if suffix == ".nc":
                self.to_xarray().to_netcdf(tmp, engine="h5netcdf")
            elif suffix == ".json":
                import json

                Path(tmp).write_text(json.dumps(_json_safe(self.to_record()),
                                                allow_nan=False, indent=1), encoding="utf-8")
            else:
                Path(tmp).write_text(_csv(self), encoding="utf-8")
        return path


def _json_safe(value):
    """Plain JSON types: NaN and inf -> None, numpy -> Python."""
    if isinstance(value, dict):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return _json_safe(value.tolist())
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def _csv(response):
    """The points as CSV: ``# key = value [unit]`` lines, a header, one row per point."""
    attrs = _parameter_attributes(response.isolator, response.controller)
    lines = [f"# amplitude = {response.amplitude!r} [m]", f"# dt = {response.dt!r} [s]",
             f"# solver = {response.solver}"]
    lines += [f"# {key} = {value}" for key, value in attrs.items() if not key.endswith("_units")]
    records = response.to_records()
    n_harm = len(records[0]["harmonics"]) if records else 0
    names = (["direction", "frequency", "transmissibility", "phase"]
             + [f"harmonic_{k}" for k in range(2, 2 + n_harm)]
             + [n for n in records[0] if n not in ("direction", "frequency", "transmissibility",
                                                  "phase", "harmonics")] if records else [])
    lines.append(",".join(names))
    for record in records:
        row = []
        for name in names:
            value = (record["harmonics"][int(name.split("_")[1]) - 2]
                     if name.startswith("harmonic_") else record[name])
            if isinstance(value, str):
                row.append('"' + value.replace('"', "'") + '"' if "," in value else value)
            elif isinstance(value, bool):
                row.append(str(int(value)))
            else:
                row.append(f"{value:.10g}")
        lines.append(",".join(row))
    return "\n".join(lines) + "\n"


def _parameter_attributes(isolator, controller):
    from qzs.model.registry import unit_of

    attrs = {}
    for section, params in (("isolator", isolator), ("controller", controller)):
        for item in dataclasses.fields(params):
            value = getattr(params, item.name)
            if value is None:
                value = "none"
            elif isinstance(value, bool):
                value = int(value)
            attrs[f"{section}.{item.name}"] = value
            attrs[f"{section}.{item.name}_units"] = unit_of(item.name)
    return attrs


# ---------------------------------------------------------------- one frequency
def steps_for(frequency, dt):
    """Integration steps per period at ``frequency`` for a largest step ``dt`` [-].

    The fewest multiple of :data:`SAMPLES_PER_PERIOD` whose step ``1/(frequency*steps)``
    is at most ``dt``: every period is then a whole number of steps and of output samples.

    Parameters
    ----------
    frequency : float
        Excitation frequency [Hz].
    dt : float
        Largest integration step [s].

    Returns
    -------
    int
    """
    blocks = max(1, math.ceil(1.0 / (frequency * dt * SAMPLES_PER_PERIOD) - 1e-9))
    return SAMPLES_PER_PERIOD * blocks


def _scaled_distance(a, b, scale):
    """Largest scaled difference of two period-boundary states; inf if the modes differ."""
    if a[1] != b[1]:
        return math.inf
    return float(np.max(np.abs(a[0] - b[0]) / scale))


def _remaining(history, multiple):
    """Estimated distance of the last state from the periodic limit [-].

    ``history`` holds the scaled changes ``d_k = |s_k - s_{k-multiple}|``; with the
    per-period contraction ``rho`` (the largest ratio of successive changes) the rest of
    a geometric approach is ``d_k rho^m / (1 - rho^m)``. Changes below round-off count as
    zero. Returns inf where the changes do not shrink.
    """
    values = [0.0 if d <= ROUND_OFF else d for d in list(history)[-CONSECUTIVE_PERIODS:]]
    last = values[-1]
    if last == 0.0:
        return 0.0
    rho = 0.0
    for previous, current in zip(values, values[1:]):
        if current == 0.0:
            continue
        if previous == 0.0:
            return math.inf
        rho = max(rho, current / previous)
    if rho >= 1.0:
        return math.inf
    contraction = rho ** multiple
    return last * contraction / (1.0 - contraction)


_STATE_NAMES = {0: "the relative position", 1: "the relative velocity",
                2: "the high-pass state", 3: "the PI integral"}


def _dominant(boundaries, scale, rows):
    """Which state changed most (scaled) over the last period, for a reason."""
    if len(boundaries) < 2:
        return "unknown"
    change = np.abs(boundaries[-1][0] - boundaries[-2][0]) / scale
    name = _STATE_NAMES[rows[int(np.argmax(change))]]
    if boundaries[-1][1] != boundaries[-2][1]:
        name += ", and the stick/slip mode differs"
    return name


def _dft(values, bins):
    """Complex amplitudes of ``values`` (samples of whole periods, from phase 0) at ``bins``."""
    n = values.size
    phase = np.exp(-2j * np.pi * np.outer(bins, np.arange(n)) / n)
    return (2.0 / n) * (phase @ values)


def _analyse(rows, flags, period_count, amplitude, motor_force_max, harmonic_count, K):
    """The steady-state quantities of ``period_count`` whole periods of output rows."""
    # the kernel records at the end of each block: the last row is at phase 2*pi*count,
    # i.e. phase 0; rolled to the front, row j is at phase 2*pi*j/samples*count
    rows = np.roll(rows, 1, axis=0)
    flags = np.roll(flags, 1, axis=0)
    m = period_count
    x, y, z = rows[:, K.C_X], rows[:, K.C_BASE_Y], rows[:, K.C_Z]
    fundamental = _dft(y, [m])[0]
    harmonic_bins = [m * k for k in range(1, harmonic_count + 1)]
    payload = _dft(x, harmonic_bins)
    ratio = payload[0] / fundamental
    # acceleration harmonic k = -(k w)^2 x_k: k^2 |x_k| / |y_1| (exact for periodic motion)
    harmonics = tuple(float(k * k * abs(payload[k - 1]) / abs(fundamental))
                      for k in range(2, harmonic_count + 1))
    sub = 0.0
    if m > 1:
        sub_bins = [j for j in range(1, m * harmonic_count) if j % m]
        values = np.abs(_dft(x, sub_bins)) * (np.array(sub_bins) / m) ** 2 / abs(fundamental)
        sub = float(values.max())
    command = rows[:, K.C_F_PI] + rows[:, K.C_F_DAMP]
    return dict(transmissibility=float(abs(ratio)), phase=float(np.angle(ratio)),
                harmonics=harmonics, subharmonic=sub,
                relative_amplitude=float(abs(_dft(z, [m])[0])),
                relative_peak=float(0.5 * np.ptp(z)), mean_relative_position=float(z.mean()),
                locked_fraction=float(np.mean(flags[:, 0])),
                saturated_fraction=float(np.mean(np.abs(command) >= motor_force_max)))


def _nan_values(harmonic_count):
    nan = math.nan
    return dict(transmissibility=nan, phase=nan, harmonics=(nan,) * (harmonic_count - 1),
                subharmonic=nan, relative_amplitude=nan, relative_peak=nan,
                mean_relative_position=nan, locked_fraction=nan, saturated_fraction=nan,
                stop_contacts=nan)


def _run_frequency(task):
    """Simulate one frequency until periodic (runs in a worker process or inline).

    ``task``: ``frequency`` [Hz], ``amplitude`` [m], ``isolator``, ``controller``, ``dt``
    (largest step [s]), ``solver``, ``carried`` (None, or the previous frequency's final
    ``(state, flags)`` arrays), ``direction`` and the settings. Returns ``(point, carried)``:
    the :class:`ResponsePoint` and the final state to start the next frequency from
    (None after a divergence).
    """
    from qzs.engine import kernels as K
    from qzs.engine import lanes
    from qzs.engine.prepare import divergence_message, prepare_run

    started = time.perf_counter()
    frequency, amplitude = task["frequency"], task["amplitude"]
    settings = task["settings"]
    period = 1.0 / frequency
    steps = steps_for(frequency, task["dt"])
    dt = period / steps
    decimation = steps // SAMPLES_PER_PERIOD
    carried = task["carried"]
    fade_periods = 0 if carried is not None else math.ceil(settings["fade_in"] * frequency - 1e-9)
    # base y = A sin(w t + pi/2) = A cos(w t): every period starts at the crest, where the
    # base velocity is zero, so a state carried from another frequency starts with the same
    # base displacement and velocity as it ended with (docs/response.md §4)
    excitation = Sine(amplitude=amplitude, frequency=frequency, phase=0.5 * math.pi,
                      fade_in=fade_periods * period)
    run = prepare_run(excitation, task["isolator"], task["controller"], duration=period, dt=dt,
                      sample_rate=frequency * SAMPLES_PER_PERIOD, solver=task["solver"])
    state, flags, params = run.state, run.flags, run.params
    if carried is not None:
        state[:] = carried[0]
        state[K.S_W_BASE:K.S_D_STOP + 1] = 0.0  # a fresh energy ledger
        state[K.A_MARGIN] = np.nan  # the base acceleration changed: work the margin out again
        flags[:] = carried[1]
        flags[K.I_STEP] = flags[K.I_N_CONTACTS] = flags[K.I_N_STICKS] = 0
    harmonic_count = settings["harmonics"]
    omega = 2 * math.pi * frequency
    # the states that act on the motion: z and v; the high-pass state where the damping
    # loop feeds it back; the PI integral where Ki > 0 (without its gain the integral of a
    # payload held off the setpoint grows for ever, and the motion is periodic all the same)
    controller = task["controller"]
    state_rows = [K.S_Z, K.S_V]
    scale = [amplitude, amplitude * omega]
    if controller.damping_gain > 0 and controller.velocity_highpass > 0:
        state_rows.append(K.S_HP)
        scale.append(amplitude * omega)
    if controller.pi_ki > 0:
        state_rows.append(K.S_INT)
        scale.append(amplitude / omega)
    scale = np.array(scale)
    keep = MAX_PERIOD_MULTIPLE
    rows = np.empty((keep, SAMPLES_PER_PERIOD, K.N_CHANNELS))
    marks = np.zeros((keep, SAMPLES_PER_PERIOD, 2), dtype=np.bool_)
    boundaries = deque(maxlen=MAX_PERIOD_MULTIPLE + 1)
    contacts = deque(maxlen=MAX_PERIOD_MULTIPLE + 1)
    changes = {m: deque(maxlen=CONSECUTIVE_PERIODS) for m in range(1, MAX_PERIOD_MULTIPLE + 1)}
    tolerance = settings["periodic_tolerance"]
    motor_force_max = task["isolator"].motor_force_max
    multiple, periods, residual, reason = 0, 0, math.inf, ""
    cap = max(min(settings["max_periods"], math.floor(settings["max_time"] * frequency)),
              fade_periods + CONSECUTIVE_PERIODS + MAX_PERIOD_MULTIPLE + 1)
    for periods in range(1, cap + 1):
        slot = periods % keep
        status, _ = lanes.run_single(run.solver_code, steps, decimation, state, flags, params,
                                     *run.packed, rows[slot], marks[slot], 0)
        if status != K.STATUS_OK:
            reason = "diverged: " + divergence_message(state, flags[K.I_STEP], dt)
            point = ResponsePoint(direction=task["direction"], frequency=frequency,
                                  **_nan_values(harmonic_count), period_multiple=0,
                                  periods=periods, settle_time=periods * period,
                                  residual=math.nan, converged=False, reason=reason,
                                  start="continued" if carried is not None else "rest", dt=dt,
                                  seconds=time.perf_counter() - started)
            return point, None
        boundaries.append((state[state_rows].copy(), int(flags[K.I_MODE])))
        contacts.append(int(flags[K.I_N_CONTACTS]))
        if periods <= fade_periods:
            continue
        for m in range(1, MAX_PERIOD_MULTIPLE + 1):
            if len(boundaries) > m and periods - m >= fade_periods:
                changes[m].append(_scaled_distance(boundaries[-1], boundaries[-1 - m], scale))
        residual = changes[1][-1] if changes[1] else math.inf
        for m in range(1, MAX_PERIOD_MULTIPLE + 1):
            history = changes[m]
            # a period-m response: its m-period changes settle while every shorter period's
            # changes stay large (a period-1 response approached slowly can meet the
            # 2-period test a little before the 1-period one: it is not period 2)
            shorter_apart = all(changes[j] and changes[j][-1] > SUBHARMONIC_SEPARATION * tolerance
                                for j in range(1, m))
            if (len(history) == CONSECUTIVE_PERIODS and max(history) <= tolerance
                    and _remaining(history, m) <= tolerance and shorter_apart):
                multiple, residual = m, history[-1]
                break
        if multiple:
            break
    start = "continued" if carried is not None else "rest"
    if multiple:
        order = [(periods - multiple + 1 + i) % keep for i in range(multiple)]
        values = _analyse(np.concatenate([rows[i] for i in order]),
                          np.concatenate([marks[i] for i in order]), multiple, amplitude,
                          motor_force_max, harmonic_count, K)
        values["stop_contacts"] = (contacts[-1] - contacts[-1 - multiple]) / multiple
    else:
        values = _nan_values(harmonic_count)
        last = periods % keep
        offset = float(np.mean(rows[last][:, K.C_Z])) - controller.position_setpoint
        reason = (f"not periodic after {periods} periods ({periods * period:.4g} s): the state "
                  f"still changed by {residual:.2g} (relative to the base's amplitude; mostly "
                  f"{_dominant(boundaries, scale, state_rows)}) over the last period, and no "
                  "period-2 or period-3 response either (in the last period the payload was "
                  f"locked {100 * np.mean(marks[last][:, 0]):.0f} % of the time, its mean "
                  f"{1e3 * offset:+.3g} mm from the setpoint); raise `max_periods` or "
                  "`max_time`, or the response is quasi-periodic or chaotic")
    point = ResponsePoint(direction=task["direction"], frequency=frequency, **values,
                          period_multiple=multiple, periods=periods,
                          settle_time=periods * period, residual=float(residual),
                          converged=bool(multiple), reason=reason, start=start, dt=dt,
                          seconds=time.perf_counter() - started)
    return point, (state.copy(), flags.copy())


def _run_balance(task):
    """Harmonic balance over the range (a worker task); returns ``(curve, note)``."""
    from qzs.analysis.harmonic_balance import SmoothModel, frequency_response_curve

    try:
        model = SmoothModel.from_parameters(task["isolator"], task["controller"],
                                            amplitude=task["amplitude"],
                                            friction_velocity=task["friction_velocity"])
        curve = frequency_response_curve(model, task["range"], harmonics=task["harmonics"])
    except (ParameterError, np.linalg.LinAlgError, FloatingPointError) as error:
        return None, f"harmonic balance failed: {error}"
    if curve.frequency.size < 2:
        return None, "harmonic balance: " + "; ".join(curve.notes)
    note = ("harmonic balance: " + "; ".join(curve.notes)) if curve.notes else ""
    return curve, note


def _run_chirp(task):
    """The chirp-and-Welch estimate (a worker task)."""
    return chirp_transmissibility(task["amplitude"], task["isolator"], task["controller"],
                                  top=task["top"], dt=task["dt"], solver=task["solver"])


def chirp_transmissibility(amplitude=0.010, isolator=None, controller=None, *, top=20.0,
                           dt=defaults.SIMULATION["dt"], solver=defaults.SIMULATION["solver"],
                           fft_length=defaults.ANALYSIS["fft_length"]):
    """The paper's transmissibility estimate: a slow chirp and a Welch ratio.

    A linear chirp from 0 Hz to ``top`` at the paper's rate (0.01 Hz/s: 20 Hz in 2000 s),
    1 kHz output, Welch with ``fft_length``-sample Hann segments, half overlap
    (docs/model.md §10).

    Parameters
    ----------
    amplitude : float
        Chirp displacement amplitude [m].
    isolator : IsolatorParameters, optional
        Plant parameters.
    controller : ControllerParameters, optional
        PI and damping loops.
    top : float
        End frequency of the chirp [Hz]; at least 20.
    dt : float
        Integration step [s].
    solver : {"ode3", "rk4", "euler"}
        Integrator.
    fft_length : int
        Welch segment length [samples].

    Returns
    -------
    TransmissibilityEstimate
    """
    from qzs.analysis.spectral import transmissibility
    from qzs.engine.simulate import simulate

    top = max(20.0, positive("top", top))
    rate = defaults.ANALYSIS["sample_rate"]
    chirp = Chirp(amplitude=amplitude, f0=0.0, f1=top, duration=top / PAPER_SWEEP_RATE)
    result = simulate(chirp, isolator, controller, dt=dt, sample_rate=rate, solver=solver)
    return transmissibility(result.base_acceleration, result.payload_acceleration, rate,
                            fft_length=fft_length)


# ---------------------------------------------------------------- the sweeps
def _frequencies(frequencies):
    try:
        values = np.array(frequencies, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"`frequencies` must be numbers in Hz, got {frequencies!r}.") from None
    if values.size == 0:
        raise ParameterError("`frequencies` is empty; give at least one frequency in Hz.")
    bad = values[~np.isfinite(values) | (values <= 0)]
    if bad.size:
        raise ParameterError(f"`frequencies` must be positive and finite, got "
                             f"{float(bad[0])!r} Hz; drop it or give a positive frequency.")
    values = np.unique(values)
    return values


def _check_step(dt, frequencies, isolator, controller, solver):
    from qzs.engine.stability import largest_stable_step, stability_test

    if not stability_test(isolator, controller, solver)(dt):
        limit = largest_stable_step(isolator, controller, solver)
        raise ParameterError(f"`dt` ({dt!r} s) is too large for a stable {solver} integration "
                             f"of this model; the largest stable step is {limit:.3g} s. "
                             "Reduce `dt`.")
    top = frequencies[-1]
    if top * dt * MIN_STEPS_PER_PERIOD > 1.0 + 1e-9:
        raise ParameterError(
            f"`frequencies` reach {top:g} Hz, above a tenth of the Nyquist rate of the step "
            f"dt = {dt:g} s ({1 / (MIN_STEPS_PER_PERIOD * dt):g} Hz, {MIN_STEPS_PER_PERIOD} "
            f"steps per period); lower `dt` to at most {1 / (MIN_STEPS_PER_PERIOD * top):.3g} "
            "s or drop the higher frequencies.")


def settle_time_cap(isolator=None, controller=None):
    """Default simulated time at most per frequency [s].

    :data:`SETTLE_TIME_CONSTANTS` times the slowest time constant of the linearised closed
    loop (:func:`qzs.analysis.linear.linearize`, frictionless), clipped to
    [:data:`MIN_TIME`, :data:`MAX_TIME`]: 115 s for the paper's default loop (Kp = 50 N/m,
    Ki = 20 N/(m s): slowest pair at -0.26 1/s), 900 s for its stiction study's Kp = 5 N/m,
    Ki = 2 N/(m s) (-0.033 1/s). Friction changes how fast a response settles, but a
    response still changing after this long is on no decay the loop explains: a PI loop
    hunting against stiction, or a quasi-periodic or chaotic motion.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters.
    controller : ControllerParameters, optional
        PI and damping loops.

    Returns
    -------
    float
    """
    from qzs.analysis.linear import linearize

    try:
        poles = np.asarray(linearize(isolator, controller).poles)
    except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
        return MAX_TIME
    decay = -poles.real
    decay = decay[decay > 1e-9]
    if decay.size < poles.size or decay.size == 0:
        return MIN_TIME if decay.size == 0 else MAX_TIME
    return float(np.clip(SETTLE_TIME_CONSTANTS / decay.min(), MIN_TIME, MAX_TIME))


def _choose_step(frequencies, amplitude, isolator, controller, solver, tolerance_db, progress):
    """The accuracy-driven step on a chirp over the band; ``(dt, choice, note)``."""
    from qzs.engine.accuracy import choose_step

    low, high = float(frequencies[0]), float(frequencies[-1])
    rate = max(defaults.SIMULATION["sample_rate"], math.ceil(MIN_STEPS_PER_PERIOD * high))
    if low == high:
        low = 0.8 * high
    probe = Chirp(amplitude=amplitude, f0=low, f1=high, duration=60.0,
                  fade_in=min(2.0 / low, 15.0))
    try:
        step = choose_step(probe, isolator, controller, tolerance_db=tolerance_db,
                           solver=solver, sample_rate=rate, band=(low, high), progress=progress)
    except ToleranceNotMetError as error:
        dt = defaults.SIMULATION["dt"]
        return dt, None, (f"no step met {tolerance_db:g} dB on the chirp probe ({error}); using "
                          f"the paper's dt = {dt:g} s")
    except ParameterError as error:  # the probe's own limits (no trusted bin in the band)
        dt = min(defaults.SIMULATION["dt"], 1.0 / (MIN_STEPS_PER_PERIOD * high))
        return dt, None, (f"the step could not be chosen on a chirp probe ({error}); using "
                          f"dt = {dt:g} s")
    return step.dt, step, (f"dt <= {step.dt:.3g} s chosen for {tolerance_db:g} dB on a "
                           f"{low:g}-{high:g} Hz chirp probe (estimated error "
                           f"{step.error:.2g} dB)")


def steady_state_response(frequencies, amplitude=0.010, isolator=None, controller=None, *,
                          direction="both", dt=None, tolerance_db=None,
                          solver=defaults.SIMULATION["solver"],
                          periodic_tolerance=PERIODIC_TOLERANCE, max_periods=MAX_PERIODS,
                          max_time=None, fade_in=FADE_IN, harmonics=HARMONICS,
                          harmonic_balance=True,
                          friction_velocity=None, balance_harmonics=None, compare_chirp=False,
                          workers=None, progress=False):
    """Steady-state frequency response by stepped-sine simulation.

    Each sweep (``up``: rising frequency, ``down``: falling) starts from rest at its first
    frequency with a fade-in and continues each later frequency from the previous one's
    final state, the base at its crest (zero velocity) at the junction. At each frequency
    the isolator is simulated period by period until the state (z, v, high-pass state, PI
    integral, and the stick/slip mode) at the start of a period agrees with the one a
    period before (or two or three: a sub-harmonic response) within ``periodic_tolerance``
    for 3 periods in a row, the extrapolated remainder of a geometric approach too. The
    last period(s) then give the fundamental amplitude ratio (a single-bin DFT of 256
    samples per period: exact for a periodic signal up to aliasing of harmonics above
    127), the harmonics, relative amplitude, locked share and stop contacts. A frequency
    that does not settle within ``max_periods`` is NaN with its reason.

    The two sweeps run in parallel processes (each is sequential: every frequency starts
    from the last); the harmonic balance and the chirp, if asked, run beside them.

    Parameters
    ----------
    frequencies : array_like
        Frequencies [Hz], positive; sorted, duplicates dropped.
    amplitude : float
        Base displacement amplitude [m].
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted. A sampled controller is not supported.
    direction : {"both", "up", "down"}
        Sweeps to run.
    dt : float, optional
        Largest integration step [s]; each frequency uses the largest step at most this
        with a whole number of output samples per period. Default: chosen for
        ``tolerance_db`` (:func:`qzs.engine.accuracy.choose_step`, on a chirp over the
        band).
    tolerance_db : float, optional
        Accuracy of the chosen step [dB]; default 0.01 (``qzs.defaults.ACCURACY``). Not
        with ``dt``.
    solver : {"ode3", "rk4", "euler"}
        Integrator.
    periodic_tolerance : float
        Periodicity tolerance [-]: scaled state change per period (z by the base amplitude
        A, velocities by A*w, the integral by A/w).
    max_periods : int
        Periods at most per frequency [-].
    max_time : float, optional
        Simulated time at most per frequency [s] (whichever cap comes first; at least the
        fade-in and the few periods the tests need). Default :func:`settle_time_cap`: 30
        of the linearised loop's slowest time constants, within 60 to 3600 s.
    fade_in : float
        Fade-in of each sweep's first frequency [s], rounded up to whole periods.
    harmonics : int
        Highest harmonic reported [-] (2..harmonics; at most 64).
    harmonic_balance : bool
        Also follow the smooth model by harmonic balance over the range.
    friction_velocity : float, optional
        Regularisation velocity of the smooth model's friction [m/s]; default
        :data:`qzs.analysis.harmonic_balance.FRICTION_VELOCITY`.
    balance_harmonics : int, optional
        Harmonics of the harmonic balance [-]; default
        :data:`qzs.analysis.harmonic_balance.DEFAULT_HARMONICS`.
    compare_chirp : bool
        Also simulate the paper's chirp for this case and estimate its transmissibility
        (:func:`chirp_transmissibility`; 2000 s of simulated time for 0-20 Hz).
    workers : int, optional
        Processes [-]; default the tasks that can run at once, at most the core count.
        1 runs everything in this process.
    progress : bool
        Show a progress bar over frequencies.

    Returns
    -------
    SteadyStateResponse

    Raises
    ------
    ParameterError
        Invalid input, found before any simulation: frequencies not positive and finite or
        above a tenth of the step's Nyquist rate, a non-positive amplitude, an unknown
        direction, both ``dt`` and ``tolerance_db``, an unstable ``dt``, a sampled
        controller.
    """
    import qzs.analysis.harmonic_balance as hb
    from qzs.analysis.linear import linearize
    from qzs.engine.prepare import run_inputs

    started = time.perf_counter()
    frequencies = _frequencies(frequencies)
    amplitude = positive("amplitude", amplitude)
    _, isolator, controller = run_inputs(None, isolator, controller)
    direction = choice("direction", direction, DIRECTIONS)
    from qzs.engine.stability import SOLVERS

    solver = choice("solver", solver, tuple(SOLVERS))
    if dt is not None and tolerance_db is not None:
        raise ParameterError("give `dt` (a fixed largest step) or `tolerance_db` (the step "
                             "chosen for an accuracy), not both.")
    if tolerance_db is not None:
        tolerance_db = positive("tolerance_db", tolerance_db)
    if dt is not None:
        dt = positive("dt", dt)
    periodic_tolerance = positive("periodic_tolerance", periodic_tolerance)
    if periodic_tolerance >= 0.1:
        raise ParameterError(f"`periodic_tolerance` must be below 0.1, got "
                             f"{periodic_tolerance!r}; 1e-6 is the default.")
    max_periods = integer("max_periods", max_periods, CONSECUTIVE_PERIODS + MAX_PERIOD_MULTIPLE + 1)
    if max_time is not None:
        max_time = positive("max_time", max_time)
    fade_in = float(fade_in)
    if not math.isfinite(fade_in) or fade_in < 0:
        raise ParameterError(f"`fade_in` must be a non-negative number of seconds, got "
                             f"{fade_in!r}.")
    harmonics = integer("harmonics", harmonics, 2)
    if harmonics > SAMPLES_PER_PERIOD // 4:
        raise ParameterError(f"`harmonics` must be at most {SAMPLES_PER_PERIOD // 4} (the "
                             f"{SAMPLES_PER_PERIOD} samples per period), got {harmonics}.")
    friction_velocity = hb.FRICTION_VELOCITY if friction_velocity is None else positive(
        "friction_velocity", friction_velocity)
    balance_harmonics = hb.DEFAULT_HARMONICS if balance_harmonics is None else integer(
        "balance_harmonics", balance_harmonics, 1)
    if workers is not None:
        workers = integer("workers", workers, 1)
    if controller.controller_rate > 0:
        raise ParameterError(
            f"`controller_rate` ({controller.controller_rate!r} Hz) > 0: a sampled controller "
            "adds its own period, which divides no excitation period in general, so the "
            "response is not periodic; set controller_rate=0 (continuous) for the steady "
            "state.")
    notes = []
    step = None
    if dt is None:
        tolerance_db = defaults.ACCURACY["tolerance_db"] if tolerance_db is None else tolerance_db
        dt, step, note = _choose_step(frequencies, amplitude, isolator, controller, solver,
                                      tolerance_db, progress)
        notes.append(note)
    _check_step(dt, frequencies, isolator, controller, solver)
    if max_time is None:
        max_time = settle_time_cap(isolator, controller)
    settings = {"periodic_tolerance": periodic_tolerance, "max_periods": max_periods,
                "max_time": max_time, "samples_per_period": SAMPLES_PER_PERIOD, "fade_in": fade_in,
                "harmonics": harmonics}

    chains = {"up": list(frequencies), "down": list(frequencies[::-1])}
    chains = {d: chains[d] for d in (("up", "down") if direction == "both" else (direction,))}
    base = dict(amplitude=amplitude, isolator=isolator, controller=controller, dt=dt,
                solver=solver, settings=settings)
    extra = {}
    if harmonic_balance:
        low, high = float(frequencies[0]), float(frequencies[-1])
        if low == high:
            low, high = 0.9 * low, 1.1 * high
        extra["balance"] = (_run_balance, dict(
            isolator=isolator, controller=controller, amplitude=amplitude,
            friction_velocity=friction_velocity, range=(low, high), harmonics=balance_harmonics))
    if compare_chirp:
        extra["chirp"] = (_run_chirp, dict(amplitude=amplitude, isolator=isolator,
                                           controller=controller, top=float(frequencies[-1]),
                                           dt=min(dt, defaults.SIMULATION["dt"] * 10),
                                           solver=solver))
    concurrent = len(chains) + len(extra)
    if workers is None:  # an explicit count is the user's; the default, no more than there is to do
        workers = worker_count(None, concurrent)
    settings["workers"] = workers
    points, outcomes = _run_chains(chains, base, extra, workers, progress)
    balance, note = outcomes.get("balance", (None, ""))
    if note:
        notes.append(note)
    linear = {}
    try:
        grid = (np.geomspace(frequencies[0], frequencies[-1], 400) if frequencies.size > 1
                else frequencies)
        model = linearize(isolator, controller)
        linear = {"frequency": grid,
                  "transmissibility": np.asarray(model.transmissibility(grid), dtype=float),
                  "at_frequencies": np.asarray(model.transmissibility(frequencies),
                                               dtype=float)}
    except (ValueError, np.linalg.LinAlgError) as error:  # pragma: no cover - defensive
        notes.append(f"no linear model: {error}")
    unconverged = [p for p in points if not p.converged]
    if unconverged:
        where = "; ".join(
            f"{d} {min(p.frequency for p in unconverged if p.direction == d):g}-"
            f"{max(p.frequency for p in unconverged if p.direction == d):g} Hz"
            for d in chains if any(p.direction == d for p in unconverged))
        notes.append(f"{len(unconverged)} point(s) NaN ({where}); e.g. {unconverged[0].direction} "
                     f"{unconverged[0].frequency:g} Hz: {unconverged[0].reason}")
    return SteadyStateResponse(points=tuple(points), frequencies=frequencies,
                               amplitude=amplitude, isolator=isolator, controller=controller,
                               solver=solver, dt=dt, step=step, settings=settings,
                               balance=balance, linear=linear,
                               chirp=outcomes.get("chirp"), notes=tuple(notes),
                               elapsed=time.perf_counter() - started)


def _task(base, direction, frequency, carried):
    return dict(base, direction=direction, frequency=frequency, carried=carried)


def _run_chains(chains, base, extra, workers, progress):
    """Run the sweeps (each a chain of frequencies) and the extra tasks; returns
    ``(points in sweep order, {name: outcome})``."""
    from tqdm.auto import tqdm

    total = sum(len(c) for c in chains.values())
    bar = tqdm(total=total, unit="frequency", desc="steady state", disable=not progress,
               leave=False)
    points = {d: [] for d in chains}
    outcomes = {}
    try:
        if workers == 1:
            for name, (function, task) in extra.items():
                outcomes[name] = function(task)
            for d, chain in chains.items():
                carried = None
                for frequency in chain:
                    point, carried = _run_frequency(_task(base, d, frequency, carried))
                    points[d].append(point)
                    bar.update()
        else:
            _run_pool(chains, base, extra, workers, points, outcomes, bar)
    finally:
        bar.close()
    return [p for d in chains for p in points[d]], outcomes


def _run_pool(chains, base, extra, workers, points, outcomes, bar):
    pool = ProcessPoolExecutor(max_workers=workers)
    finished = False
    try:
        pending = {}
        for name, (function, task) in extra.items():
            pending[pool.submit(function, task)] = ("extra", name, None)
        for d, chain in chains.items():
            pending[pool.submit(_run_frequency, _task(base, d, chain[0], None))] = ("chain", d, 0)
        while pending:
            done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
            for future in done:
                kind, name, index = pending.pop(future)
                if kind == "extra":
                    outcomes[name] = future.result()
                    continue
                point, carried = future.result()
                points[name].append(point)
                bar.update()
                if index + 1 < len(chains[name]):
                    task = _task(base, name, chains[name][index + 1], carried)
                    pending[pool.submit(_run_frequency, task)] = ("chain", name, index + 1)
        finished = True
    finally:
        if not finished:  # Ctrl-C, SIGTERM, an error: stop the workers now, not after their task
            processes = getattr(pool, "_processes", None) or {}
            for process in list(processes.values()):
                process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)

