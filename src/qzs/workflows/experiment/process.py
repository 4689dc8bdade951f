"""Process an experiment log: measured transmissibility beside the matching simulation.

The paper's experiment (Section 4) shakes the isolator with a constant-displacement chirp
and measures base and payload with accelerometers whose charge amplifiers integrate to
velocity through a first-order 1 Hz high-pass. Both channels pass the same high-pass, so
it cancels in their ratio in theory; in practice the band below 1.5x the corner is not
trustworthy (tiny, phase-shifted signals) and is flagged. :func:`process_experiment`

1. takes base and payload velocities (or accelerations) of a :class:`~qzs.iotools.rig.Recording`,
2. estimates their transmissibility ``sqrt(S_payload/S_base)`` (Welch, Hann window),
3. infers the chirp from the base signal (:func:`infer_chirp`) unless it is given,
4. simulates the model under that chirp, at the log's sample rate and length, passes the
   simulated signals through the same high-pass and estimates the same way,
5. and reports both curves, their metrics and the flagged band (figure and Markdown).

Command line (``qzs experiment``, :mod:`qzs.cli.experiment`)::

    qzs experiment LOG --map MAP.toml [--out DIR] [--no-simulation] [--fft-length N]
                   [--averages N] [--config PARAMS.toml] [--resample]
"""
from __future__ import annotations

import dataclasses
import time as _time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import decibels, markdown_table
from qzs.analysis.spectral import (band_mask, highpass, required_samples, transmissibility,
                                   transmissibility_metrics, welch_average_count)
from qzs.defaults import ANALYSIS
from qzs.engine.prepare import steps_per_sample
from qzs.engine.simulate import simulate
from qzs._validation import integer, non_negative_real
from qzs.errors import DataError, DataWarning, ParameterError
from qzs.iotools.config import load_config
from qzs.iotools.files import atomic_path
from qzs.iotools.paths import check_output_path
from qzs.iotools.result_files import save_by_extension, save_doc, suffixes_of
from qzs.iotools.rig import Recording, load_channel_map, read_recording
from qzs.iotools.schema import Schema, Variable, to_dataset
from qzs.iotools.writer import write_dataset
from qzs.model.excitation import Chirp
from qzs.viz.figures import check_frequency_scale

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.analysis.spectral import TransmissibilityEstimate, TransmissibilityMetrics
    from qzs.model.controller import ControllerParameters
    from qzs.model.isolator import IsolatorParameters

__all__ = ["ExperimentResult", "process_experiment", "experiment_metrics", "infer_chirp",
           "run_experiment", "experiment_schema"]

#: Welch averages of the paper's experiment (Section 4).
EXPERIMENT_AVERAGES = 29
#: Shortest Welch segment [samples] (:func:`qzs.analysis.spectral.transmissibility`).
MIN_FFT_LENGTH = 8
#: What the report writes at most [bytes]: two figures, a table, the Markdown (generous).
REPORT_BYTES = 20 * 1024 ** 2
SIGNAL_PAIRS = {"velocity": ("base_velocity", "payload_velocity"),
                "acceleration": ("base_acceleration", "payload_acceleration")}


def _signal_kind(recording):
    for kind, (base, payload) in SIGNAL_PAIRS.items():
        if base in recording.channels and payload in recording.channels:
            return kind
    raise DataError(f"{recording.source}: an experiment needs base_velocity and "
                    "payload_velocity, or base_acceleration and payload_acceleration; the "
                    f"recording has {sorted(recording.channels)}. Name them in the channel map.")


def infer_chirp(recording, *, highpass_corner=1.0):
    """Infer the base's linear chirp (amplitude, start and end frequency) from the log.

    The analytic signal (Hilbert transform) of the base channel gives its phase and
    envelope where it is strong (envelope above 20 % of its maximum, and the
    instantaneous frequency above 3x the high-pass corner). A quadratic fitted to the
    unwrapped phase gives ``f0`` and the sweep rate, so ``f1 = f0 + rate*T`` with ``T``
    the log's length (the log is assumed to start with the chirp); ``f0`` is clipped at
    0. The displacement amplitude is the median of the envelope divided by ``2*pi*f``
    (velocity) or ``(2*pi*f)^2`` (acceleration) and the high-pass gain.

    Parameters
    ----------
    recording : Recording
        With base velocity or acceleration.
    highpass_corner : float
        Corner of the measurement's first-order high-pass [Hz] (0: none).

    Returns
    -------
    Chirp

    Raises
    ------
    DataError
        The base signal is not a linear chirp (phase residual above 1 rad rms).
    """
    from scipy import signal


    kind = _signal_kind(recording)
    base = recording[SIGNAL_PAIRS[kind][0]]
    t = recording.time - recording.time[0]
    analytic = signal.hilbert(base - np.mean(base))
    envelope = np.abs(analytic)
    phase = np.unwrap(np.angle(analytic))
    trim = slice(max(1, t.size // 100), t.size - max(1, t.size // 100))
    strong = np.zeros(t.size, bool)
    strong[trim] = envelope[trim] > 0.2 * np.max(envelope[trim])
    for _ in range(2):  # fit, then drop what the high-pass distorts
        if np.count_nonzero(strong) < 10:
            raise DataError(f"{recording.source}: too few strong samples of the base signal "
                            "to infer the chirp; give amplitude, f0 and f1 in the map's "
                            "[experiment] table.")
        c2, c1, c0 = np.polyfit(t[strong], phase[strong], 2)
        frequency = (c1 + 2 * c2 * t) / (2 * np.pi)
        strong &= frequency > 3 * highpass_corner
    misfit = np.sqrt(np.mean((np.polyval([c2, c1, c0], t[strong]) - phase[strong]) ** 2))
    if not misfit < 1.0 or c2 <= 0:
        raise DataError(f"{recording.source}: the base signal is not a rising linear chirp "
                        f"(phase misfit {misfit:.3g} rad rms); give amplitude, f0 and f1 in the "
                        "map's [experiment] table.")
    f0 = max(c1 / (2 * np.pi), 0.0)
    f1 = (c1 + 2 * c2 * t[-1]) / (2 * np.pi)
    omega = 2 * np.pi * frequency[strong]
    gain = omega / np.sqrt(omega ** 2 + (2 * np.pi * highpass_corner) ** 2)
    power = 1 if kind == "velocity" else 2
    amplitude = float(np.median(envelope[strong] / (omega ** power * gain)))
    return Chirp(amplitude=amplitude, f0=float(f0), f1=float(f1), duration=float(t[-1]))


@dataclass(frozen=True, eq=False)
class ExperimentResult:
    """Result of :func:`process_experiment`.

    Attributes
    ----------
    recording : Recording
        The log processed.
    signal : {"velocity", "acceleration"}
        Which base/payload pair was used.
    measured, simulated : TransmissibilityEstimate
        The experiment's and the matching simulation's transmissibility (``simulated``
        None without simulation).
    metrics, simulated_metrics : TransmissibilityMetrics
        Metrics of both over the chirp's band (``simulated_metrics`` None without simulation).
    band : (float, float)
        Frequency band analysed [Hz]: up to the frequency the chirp reached at the centre
        of the last Welch segment used (above it the base is barely excited).
    highpass_corner : float
        Corner of the measurement's high-pass [Hz] (0: none).
    untrusted_below : float
        Upper edge of the flagged band [Hz]: ``1.5 * highpass_corner``.
    excitation : Chirp
        The chirp simulated (``excitation_inferred`` tells whether it was inferred).
    excitation_inferred : bool
        True if the chirp was inferred from the log (:func:`infer_chirp`), False if given.
    isolator, controller : IsolatorParameters, ControllerParameters
        Parameters of the simulation.
    notes : tuple of str
        Warnings raised while processing.
    simulation_seconds : float
        Wall time of the simulation [s].
    """

    recording: Recording
    signal: str
    measured: TransmissibilityEstimate
    simulated: TransmissibilityEstimate | None
    metrics: TransmissibilityMetrics
    simulated_metrics: TransmissibilityMetrics | None
    band: tuple
    highpass_corner: float
    untrusted_below: float
    excitation: Chirp
    excitation_inferred: bool
    isolator: IsolatorParameters
    controller: ControllerParameters
    notes: tuple[str, ...]
    simulation_seconds: float

    def _in_band(self, estimate):
        """Frequency [Hz], magnitude [-], coherence [-] and trust of the bins in the band.

        A bin is trusted where the estimate trusts it (docs/model.md §10) and it lies at or
        above :attr:`untrusted_below`.
        """
        keep = band_mask(estimate.frequency, 0.0, self.band[1])
        f = estimate.frequency[keep]
        trusted = estimate.trusted[keep] & (f >= self.untrusted_below)
        return f, estimate.magnitude[keep], estimate.coherence[keep], trusted

    def discrepancy_db(self) -> float:
        """Median ``|20 log10(measured/simulated)|`` [dB] over the trusted band (NaN if none)."""
        if self.simulated is None:
            return float("nan")
        f, measured, _, trusted = self._in_band(self.measured)
        simulated = np.interp(f, self.simulated.frequency, self.simulated.magnitude)
        simulated_trusted = np.interp(f, self.simulated.frequency,
                                      self.simulated.trusted.astype(float)) == 1.0
        trusted &= simulated_trusted & (measured > 0) & (simulated > 0)
        if not trusted.any():
            return float("nan")
        return float(np.median(np.abs(decibels(measured[trusted] / simulated[trusted]))))

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> Figure:
        """The two curves and the coherence (:func:`qzs.viz.experiment.plot_experiment`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (a .png also as .svg).
        title : str, optional
            Figure title; default the log's file name.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.experiment import plot_experiment

        return plot_experiment(self, path=path, title=title, frequency_scale=frequency_scale)

    def to_xarray(self) -> xr.Dataset:
        """Both curves on coordinate ``frequency`` [Hz] over the band, with a ``trusted`` flag
        (:func:`experiment_schema`)."""
        f, measured, coherence, trusted = self._in_band(self.measured)
        values = {"frequency": f, "experiment": measured, "coherence": coherence,
                  "trusted": trusted}
        if self.simulated is not None:
            values["simulation"] = np.interp(f, self.simulated.frequency,
                                             self.simulated.magnitude)
        return to_dataset(experiment_schema(self), values,
                          {"title": f"qzs experiment: transmissibility of "
                                    f"{self.recording.source}",
                           "source": self.recording.source,
                           "untrusted_below": self.untrusted_below})

    def summary(self) -> str:
        """A few lines: the log, the chirp, the flagged band, key metrics of both."""
        rec, chirp = self.recording, self.excitation
        lines = [f"experiment       {rec.source}",
                 f"  log            {rec.time.size} samples at {rec.sample_rate:g} Hz, "
                 f"{rec.duration:g} s; {self.signal} of base and payload",
                 f"  chirp          {chirp.amplitude * 1e3:.3g} mm, {chirp.f0:.3g} -> "
                 f"{chirp.f1:.3g} Hz over {chirp.duration:g} s "
                 f"({_origin(self)})",
                 f"  Welch          fft_length {self.measured.fft_length}, "
                 f"{self.measured.n_averages} averages, Hann",
                 f"  flagged band   below {self.untrusted_below:g} Hz (high-pass corner "
                 f"{self.highpass_corner:g} Hz): not trustworthy"]
        for label, metrics in (("experiment", self.metrics),
                               ("simulation", self.simulated_metrics)):
            if metrics is not None:
                lines.append(f"  {label:<14} resonance {metrics.resonance_frequency:.3g} Hz "
                             f"(peak {metrics.resonance_peak:.3g}), isolation from "
                             f"{metrics.isolation_onset:.3g} Hz, T(12 Hz) = "
                             f"{metrics.at.get(12.0, float('nan')):.3g}")
        if self.simulated is not None:
            lines.append(f"  agreement      median |difference| {self.discrepancy_db():.2f} dB "
                         "over the trusted band")
        lines.extend(f"  note           {note}" for note in self.notes)
        return "\n".join(lines)

    def to_record(self) -> dict[str, Any]:
        """The summary as data (plain types; NaN where a metric is undefined), for ``--json``.

        Returns
        -------
        dict
            ``log`` (source, samples, sample_rate [Hz], duration [s], signal), ``chirp``
            (amplitude [m], f0 and f1 [Hz], duration [s], inferred), ``welch`` (fft_length
            [samples], n_averages, window), ``band`` [Hz], ``highpass_corner`` and
            ``untrusted_below`` [Hz], ``metrics`` and ``simulated_metrics`` (None without
            simulation), ``discrepancy_db`` [dB], ``simulation_seconds`` [s] and ``notes``.
        """
        rec, chirp = self.recording, self.excitation
        return {
            "log": {"source": rec.source, "samples": int(rec.time.size),
                    "sample_rate": rec.sample_rate, "duration": rec.duration,
                    "signal": self.signal},
            "chirp": {"amplitude": chirp.amplitude, "f0": chirp.f0, "f1": chirp.f1,
                      "duration": chirp.duration, "inferred": self.excitation_inferred},
            "welch": {"fft_length": int(self.measured.fft_length),
                      "n_averages": int(self.measured.n_averages), "window": "hann"},
            "band": [float(b) for b in self.band],
            "highpass_corner": self.highpass_corner, "untrusted_below": self.untrusted_below,
            "metrics": self.metrics.to_dict(),
            "simulated_metrics": (self.simulated_metrics.to_dict()
                                  if self.simulated_metrics is not None else None),
            "discrepancy_db": self.discrepancy_db(),
            "simulation_seconds": self.simulation_seconds, "notes": list(self.notes)}

    #: The extensions :meth:`save` accepts.
    save_suffixes = suffixes_of(dataset=True, record=True)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray, record=self.to_record)

    save.__doc__ = save_doc("``.nc``, ``.csv``, ``.mat`` (:meth:`to_xarray`: the "
                            "transmissibility [1] on frequency [Hz]) or ``.json`` "
                            "(:meth:`to_record`)")

    def write_report(self, folder: str | Path,
                     frequency_scale: str | None = None) -> dict[str, Path]:
        """Write ``transmissibility.png`` (+ .svg), ``transmissibility.csv`` and ``report.md``.

        Parameters
        ----------
        folder : str or Path
            Output folder, created if missing.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis of the figure; default ``qzs.defaults.FIGURES["frequency_scale"]``
            (log).

        Returns
        -------
        dict
            ``figure``, ``table``, ``report`` -> Path.
        """
        import matplotlib.pyplot as plt

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = {"figure": folder / "transmissibility.png",
                 "table": folder / "transmissibility.csv", "report": folder / "report.md"}
        plt.close(self.plot(path=paths["figure"], frequency_scale=frequency_scale))
        write_dataset(self.to_xarray(), paths["table"])  # a units row under the names
        with atomic_path(paths["report"]) as tmp:
            Path(tmp).write_text(_markdown(self, paths["figure"].name), encoding="utf-8")
        return paths


def experiment_schema(result):
    """The CF-1.10 layout of an experiment's dataset (:meth:`ExperimentResult.to_xarray`).

    Coordinate ``frequency`` [Hz]; the measured transmissibility ``experiment``, its
    ``coherence``, the ``trusted`` flag (int8) and, with a simulation, ``simulation``.

    Parameters
    ----------
    result : ExperimentResult
        The experiment (whether it has a simulation, and its flagged band).

    Returns
    -------
    Schema
    """
    variables = [
        Variable(name="experiment", dims=("frequency",), units="1",
                 long_name="measured transmissibility sqrt(S_payload/S_base)"),
        Variable(name="coherence", dims=("frequency",), units="1",
                 long_name="magnitude-squared coherence of payload and base"),
        Variable(name="trusted", dims=("frequency",), units="1", dtype="int8",
                 flag_meanings="untrusted trusted",
                 long_name="1 where the measured estimate is trusted (coherence, base power, "
                           f"at or above {result.untrusted_below:g} Hz)",
                 order=("units", "flag_values", "flag_meanings", "long_name"))]
    if result.simulated is not None:
        variables.append(Variable(name="simulation", dims=("frequency",), units="1",
                                  long_name="simulated transmissibility"))
    return Schema(kind="an experiment", dimensions={"frequency": None},
                  coordinates=(Variable(name="frequency", dims=("frequency",), units="Hz",
                                        long_name="frequency"),),
                  variables=variables)


def _origin(result):
    return "inferred from the log" if result.excitation_inferred else "given"


def _metric_rows(result):
    rows = []
    measured = result.metrics.to_dict()
    simulated = result.simulated_metrics.to_dict() if result.simulated_metrics else {}
    units = {"resonance_frequency": "Hz", "isolation_onset": "Hz", "minus_3db_frequency": "Hz",
             "rolloff_db_per_decade": "dB/decade", "untrusted_below": "Hz"}
    for name, value in measured.items():
        other = simulated.get(name, float("nan"))
        rows.append([name, units.get(name, "-"), f"{value:.4g}", f"{other:.4g}"])
    return rows


def _markdown(result, figure):
    rec, chirp = result.recording, result.excitation
    lines = [f"# Experiment: {Path(rec.source.split(' (')[0]).name}", "",
             f"- Log: `{rec.source}`, {rec.time.size} samples at {rec.sample_rate:g} Hz "
             f"({rec.duration:g} s); {result.signal} of base and payload.",
             f"- Chirp: {chirp.amplitude * 1e3:.4g} mm, {chirp.f0:.4g} -> {chirp.f1:.4g} Hz over "
             f"{chirp.duration:g} s ({_origin(result)}).",
             f"- Transmissibility: amplitude ratio sqrt(S_payload / S_base), Welch with a Hann "
             f"window, FFT length {result.measured.fft_length}, {result.measured.n_averages} "
             f"averages, band {result.band[0]:g}-{result.band[1]:.4g} Hz.",
             "",
             f"**Flagged band: below {result.untrusted_below:g} Hz the curves are not "
             f"trustworthy.** Both channels passed the charge amplifiers' first-order "
             f"{result.highpass_corner:g} Hz high-pass; it cancels in the ratio in theory, but "
             "below 1.5x its corner the signals are small and distorted. The band is shaded in "
             "the figure and left out of the resonance metrics.", "",
             f"![transmissibility]({figure})", "",
             *markdown_table(["metric", "unit", "experiment", "simulation"],
                             _metric_rows(result)), ""]
    if result.simulated is not None:
        given = result.isolator is not None or result.controller is not None
        lines += [f"Simulation: the model ({'given parameters' if given else 'Table 1 defaults'}"
                  f") under the same chirp, sampled at the log's rate, through the same high-pass "
                  f"and estimated the same way ({result.simulation_seconds:.1f} s). Median "
                  f"|difference| over the trusted band: {result.discrepancy_db():.2f} dB.", ""]
    else:
        lines += ["Simulation: not run (--no-simulation).", ""]
    if result.notes:
        lines += ["Notes:", *(f"- {note}" for note in result.notes), ""]
    return "\n".join(lines)


def _averages(n_samples, fft_length, n_averages, notes):
    """``n_averages`` if the log holds them, else None (all that fit) with a warning."""
    if n_averages is None:
        return None
    available = welch_average_count(n_samples, fft_length)
    if available >= n_averages:
        return n_averages
    if available == 0:
        raise DataError(f"`fft_length` ({fft_length}) is longer than the log ({n_samples} "
                        "samples); pass a smaller fft_length (--fft-length).")
    message = (f"the log holds only {available} Welch averages of fft_length {fft_length}, not "
               f"the {n_averages} requested; using {available} (pass a smaller fft_length for "
               "more).")
    warnings.warn(message, DataWarning, stacklevel=3)
    notes.append(message)
    return available


def process_experiment(recording, *, highpass_corner=1.0, fft_length=ANALYSIS["fft_length"],
                       n_averages=EXPERIMENT_AVERAGES,
                       isolator=None, controller=None, simulate_match=True, excitation=None,
                       dt=1e-4):
    """Transmissibility of an experiment log, its metrics, and the matching simulation.

    Parameters
    ----------
    recording : Recording
        With ``base_velocity`` and ``payload_velocity`` (or the accelerations) [SI].
    highpass_corner : float
        Corner of the charge amplifiers' first-order high-pass [Hz]; 0 for none. The band
        below ``1.5 * highpass_corner`` is flagged untrustworthy.
    fft_length : int
        Welch segment length [samples] (the paper: 32768).
    n_averages : int or None
        Welch averages (the paper's experiment: 29); None for all that fit. A log too
        short for them gives a warning and uses all that fit.
    isolator, controller : IsolatorParameters, ControllerParameters, optional
        Model of the simulation (Table 1 defaults).
    simulate_match : bool
        Simulate the same chirp and process it the same way.
    excitation : Chirp, optional
        The chirp; default inferred from the base signal (:func:`infer_chirp`).
    dt : float
        Largest integration step [s]; the step used divides the log's sample interval.

    Returns
    -------
    ExperimentResult

    Raises
    ------
    ParameterError
        ``fft_length`` below 8 or ``n_averages`` below 1 (or not integers).
    DataError
        Missing channels, a log shorter than one FFT segment, a base signal that is not a
        chirp (when it must be inferred).
    """
    if not isinstance(recording, Recording):
        raise ParameterError(f"`recording` must be a qzs.iotools.rig.Recording, got "
                             f"{type(recording).__name__}; read the log with read_recording.")
    corner = non_negative_real("highpass_corner", highpass_corner or 0.0, fix="in Hz")
    fft_length = _welch_setting("fft_length", fft_length, MIN_FFT_LENGTH)
    if n_averages is not None:
        n_averages = _welch_setting("n_averages", n_averages, 1)
    kind = _signal_kind(recording)
    notes = []
    averages = _averages(recording.time.size, fft_length, n_averages, notes)
    inferred = excitation is None
    if inferred:
        excitation = infer_chirp(recording, highpass_corner=corner)
    elif not isinstance(excitation, Chirp):
        raise ParameterError(f"`excitation` must be a Chirp or None, got "
                             f"{type(excitation).__name__}.")
    rate = recording.sample_rate
    welch = dict(fft_length=fft_length, n_averages=averages, highpass_corner=corner or None)
    base, payload = (recording[name] for name in SIGNAL_PAIRS[kind])
    measured = transmissibility(base, payload, rate, **welch)
    # Welch uses the log's start; the last segment's second half sees the top of the sweep
    # only through the window's taper: analyse up to the sweep's frequency at its centre.
    used = required_samples(fft_length, measured.n_averages) - fft_length // 2
    band = (0.0, min(float(excitation.frequency_at(used / rate)), rate / 2))
    untrusted = 1.5 * corner

    simulated = simulated_metrics = None
    seconds = 0.0
    if simulate_match:
        simulated, seconds = _simulate_like(recording, kind, excitation, isolator, controller,
                                            corner, welch, dt)
        simulated_metrics = experiment_metrics(simulated, band, corner)
    return ExperimentResult(recording, kind, measured, simulated,
                            experiment_metrics(measured, band, corner),
                            simulated_metrics, band, corner, untrusted, excitation, inferred,
                            isolator, controller, tuple(notes), seconds)


def experiment_metrics(estimate, band, highpass_corner):
    """Metrics of an experiment's (or its simulation's) estimate from its trusted bins only.

    Parameters
    ----------
    estimate : TransmissibilityEstimate
        The measured or simulated transmissibility.
    band : (float, float)
        Analysed band [Hz]; bins above ``band[1]`` are left out.
    highpass_corner : float
        High-pass corner of the measurement chain [Hz] (0 for none): bins below 1.5 times it
        are left out too (docs/model.md §10).

    Returns
    -------
    TransmissibilityMetrics
    """
    keep = band_mask(estimate.frequency, 0.0, band[1])
    return transmissibility_metrics(estimate.frequency[keep], estimate.magnitude[keep],
                                    trusted=estimate.trusted[keep],
                                    highpass_corner=highpass_corner or None)


_FIXES = {"fft_length": "a power of two such as 8192 (--fft-length)",
          "n_averages": "a count such as 29 (--averages), or leave it out for all that fit"}


def _welch_setting(name, value, minimum, where=None):
    """``value`` as an int >= ``minimum``, or a ParameterError naming it and the fix."""
    try:
        return integer(name, value, minimum)
    except ParameterError:
        label = f"`{name}`" if where is None else where
        raise ParameterError(f"{label} must be an integer >= {minimum}, got {value!r}; "
                             f"use {_FIXES[name]}.") from None


def _simulate_like(recording, kind, excitation, isolator, controller, corner, welch, dt):
    """Simulate ``excitation`` at the log's rate and length; estimate like the log."""
    rate = recording.sample_rate
    steps = steps_per_sample(rate, dt, rounding="up")
    n = recording.time.size
    duration = (n - 1) / rate
    chirp = excitation
    if chirp.duration < duration:
        chirp = dataclasses.replace(chirp, duration=duration)
    began = _time.perf_counter()
    run = simulate(chirp, isolator, controller, duration=duration, dt=1.0 / (rate * steps),
                   sample_rate=rate)
    base, payload = (highpass(run[name][:n], corner, rate) for name in SIGNAL_PAIRS[kind])
    return transmissibility(base, payload, rate, **welch), _time.perf_counter() - began


def run_experiment(log: str | Path, channel_map: str | Path, *, out: str | Path,
                   fft_length: int | None = None, n_averages: int | None = None,
                   config: str | Path | None = None, resample: bool = False,
                   simulate_match: bool = True,
                   frequency_scale: str | None = None) -> tuple[ExperimentResult, dict[str, Path]]:
    """Read a log, process it (:func:`process_experiment`) and write its report (``qzs experiment``).

    The channel map's ``[experiment]`` table gives the high-pass corner [Hz], the chirp
    (``amplitude`` [m], ``f0``/``f1`` [Hz], ``method``; what it leaves out is inferred from
    the log), ``fft_length`` and ``n_averages``; the arguments override the last two.

    Parameters
    ----------
    log : str or Path
        The log file (.csv, .mat, .mf4, .nc).
    channel_map : str or Path
        The channel map (TOML, see :mod:`qzs.iotools.rig`).
    out : str or Path
        Output folder, created if missing; checked (writable, free space) before the log
        is read.
    fft_length : int, optional
        Welch segment length [samples]; default the map's, else 32768.
    n_averages : int, optional
        Welch averages; default the map's, else 29.
    config : str or Path, optional
        Model parameters for the simulation (a run configuration TOML).
    resample : bool
        Resample a non-uniform time base onto a uniform grid.
    simulate_match : bool
        Simulate the same chirp and process it the same way.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the figure; default ``qzs.defaults.FIGURES["frequency_scale"]``
        (log).

    Returns
    -------
    result : ExperimentResult
    paths : dict
        ``figure``, ``table``, ``report`` -> Path.

    Raises
    ------
    ParameterError
        ``out`` cannot be written (checked first, :func:`qzs.iotools.paths.check_output_path`),
        ``fft_length`` below 8 or ``n_averages`` below 1 (the arguments or the map's).
    DataError
        The log cannot be read or processed (see :func:`qzs.iotools.rig.read_recording`).
    """
    check_output_path(out, argument="out", suffixes=None, directory=True,
                      estimated_bytes=REPORT_BYTES)
    if frequency_scale is not None:
        check_frequency_scale(frequency_scale)
    channel_map = load_channel_map(channel_map)
    settings = dict(channel_map.experiment)
    welch = {}
    for name, value, minimum in (("fft_length", fft_length, MIN_FFT_LENGTH),
                                 ("n_averages", n_averages, 1)):
        if value is not None:
            welch[name] = _welch_setting(name, value, minimum)
        elif name in settings:
            welch[name] = _welch_setting(name, settings[name], minimum,
                                         where=f"the channel map's [experiment] {name}")
    recording = read_recording(log, channel_map, resample=True if resample else None)
    isolator = controller = None
    if config:
        loaded = load_config(config)
        isolator, controller = loaded["isolator"], loaded["controller"]
    corner = settings.get("highpass_corner", 1.0)
    given: dict[str, Any] = {k: settings[k] for k in ("amplitude", "f0", "f1", "method")
                             if k in settings}
    excitation = None
    if given:
        inferred = (infer_chirp(recording, highpass_corner=corner)
                    if not {"amplitude", "f0", "f1"} <= set(given) else None)
        values = {k: getattr(inferred, k) for k in ("amplitude", "f0", "f1")} if inferred else {}
        excitation = Chirp(**{**values, **given}, duration=recording.duration)
    result = process_experiment(
        recording, highpass_corner=corner,
        fft_length=welch.get("fft_length", ANALYSIS["fft_length"]),
        n_averages=welch.get("n_averages", EXPERIMENT_AVERAGES),
        isolator=isolator, controller=controller, simulate_match=simulate_match,
        excitation=excitation)
    return result, result.write_report(out, frequency_scale=frequency_scale)
