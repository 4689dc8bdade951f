"""Process an experiment log: measured transmissibility beside the matching simulation.

The paper's experiment (Section 4) shakes the isolator with a constant-displacement chirp
and measures base and payload with accelerometers whose charge amplifiers integrate to
velocity through a first-order 1 Hz high-pass. Both channels pass the same high-pass, so
it cancels in their ratio in theory; in practice the band below 1.5x the corner is not
trustworthy (tiny, phase-shifted signals) and is flagged. :func:`process_experiment`

1. takes base and payload velocities (or accelerations) of a :class:`~qzs.readers.Recording`,
2. estimates their transmissibility ``sqrt(S_payload/S_base)`` (Welch, Hann window),
3. infers the chirp from the base signal (:func:`infer_chirp`) unless it is given,
4. simulates the model under that chirp, at the log's sample rate and length, passes the
   simulated signals through the same high-pass and estimates the same way,
5. and reports both curves, their metrics and the flagged band (figure and Markdown).

Command line (wired into ``qzs`` as ``qzs experiment``; also ``python -m qzs.experiment``)::

    qzs experiment LOG --map MAP.toml [--out DIR] [--no-simulation] [--fft-length N]
                   [--averages N] [--config PARAMS.toml] [--resample]
"""
from __future__ import annotations

import dataclasses
import time as _time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from qzs.errors import DataError, ParameterError
from qzs.readers import DataWarning, Recording
from qzs.spectral import highpass

__all__ = ["ExperimentResult", "process_experiment", "infer_chirp", "plot_experiment",
           "add_parser", "run", "main"]

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

    from qzs.excitation import Chirp

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
    isolator, controller
        Parameters of the simulation.
    notes : tuple of str
        Warnings raised while processing.
    simulation_seconds : float
        Wall time of the simulation [s].
    """

    recording: Recording
    signal: str
    measured: object
    simulated: object
    metrics: object
    simulated_metrics: object
    band: tuple
    highpass_corner: float
    untrusted_below: float
    excitation: object
    excitation_inferred: bool
    isolator: object
    controller: object
    notes: tuple
    simulation_seconds: float

    def _in_band(self, estimate):
        keep = (estimate.frequency > 0) & (estimate.frequency <= self.band[1])
        return estimate.frequency[keep], estimate.magnitude[keep], estimate.coherence[keep]

    def discrepancy_db(self):
        """Median ``|20 log10(measured/simulated)|`` [dB] over the trusted band (NaN if none)."""
        if self.simulated is None:
            return float("nan")
        f, measured, _ = self._in_band(self.measured)
        simulated = np.interp(f, self.simulated.frequency, self.simulated.magnitude)
        trusted = (f >= self.untrusted_below) & (measured > 0) & (simulated > 0)
        if not trusted.any():
            return float("nan")
        return float(np.median(np.abs(20 * np.log10(measured[trusted] / simulated[trusted]))))

    def plot(self, path=None, title=None):
        """The two curves and the coherence (:func:`plot_experiment`)."""
        return plot_experiment(self, path=path, title=title)

    def to_xarray(self):
        """Both curves on coordinate ``frequency`` [Hz] over the band, with a ``trusted`` flag."""
        import xarray as xr

        f, measured, coherence = self._in_band(self.measured)
        variables = {"experiment": ("frequency", measured, {"units": "1", "long_name":
                                    "measured transmissibility sqrt(S_payload/S_base)"}),
                     "coherence": ("frequency", coherence, {"units": "1"}),
                     "trusted": ("frequency", (f >= self.untrusted_below).astype("i1"),
                                 {"long_name": f"1 at or above {self.untrusted_below:g} Hz"})}
        if self.simulated is not None:
            variables["simulation"] = ("frequency", np.interp(f, self.simulated.frequency,
                                                              self.simulated.magnitude),
                                       {"units": "1", "long_name": "simulated transmissibility"})
        return xr.Dataset(variables, coords={"frequency": ("frequency", f, {"units": "Hz"})},
                          attrs={"source": self.recording.source,
                                 "untrusted_below": self.untrusted_below})

    def summary(self):
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

    def write_report(self, folder):
        """Write ``transmissibility.png`` (+ .svg), ``transmissibility.csv`` and ``report.md``.

        Returns
        -------
        dict
            ``figure``, ``table``, ``report`` -> Path.
        """
        import matplotlib.pyplot as plt

        from qzs.io import atomic_path

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = {"figure": folder / "transmissibility.png",
                 "table": folder / "transmissibility.csv", "report": folder / "report.md"}
        plt.close(self.plot(path=paths["figure"]))
        data = self.to_xarray()
        names = [n for n in ("experiment", "simulation", "coherence", "trusted") if n in data]
        with atomic_path(paths["table"]) as tmp:
            np.savetxt(tmp, np.column_stack([data["frequency"].values,
                                             *(data[n].values for n in names)]),
                       delimiter=",", fmt="%.8g", comments="",
                       header=",".join(["frequency", *names]))
        with atomic_path(paths["report"]) as tmp:
            Path(tmp).write_text(_markdown(self, paths["figure"].name), encoding="utf-8")
        return paths


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
        rows.append(f"| {name} | {units.get(name, '-')} | {value:.4g} | {other:.4g} |")
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
             "| metric | unit | experiment | simulation |", "|---|---|---|---|",
             *_metric_rows(result), ""]
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


def plot_experiment(result, *, path=None, title=None):
    """Measured and simulated transmissibility [dB] and the coherence, flagged band shaded.

    Parameters
    ----------
    result : ExperimentResult
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    from qzs.plotting import new_figure, save_figure

    fig, (top, bottom) = new_figure(2, height=2.6, sharex=False)
    bottom.sharex(top)
    f, measured, coherence = result._in_band(result.measured)
    top.plot(f, 20 * np.log10(np.maximum(measured, 1e-12)), color="C0", lw=1.0,
             label=f"experiment ({result.measured.n_averages} averages)")
    if result.simulated is not None:
        g = result.simulated.frequency
        keep = (g > 0) & (g <= result.band[1])
        top.plot(g[keep], 20 * np.log10(np.maximum(result.simulated.magnitude[keep], 1e-12)),
                 color="C3", lw=1.0, ls="--", label="simulation (same chirp and processing)")
    bottom.plot(f, coherence, color="C0", lw=0.8)
    for ax in (top, bottom):
        if result.untrusted_below > 0:
            ax.axvspan(0, result.untrusted_below, color="0.85", zorder=0,
                       label=f"not trustworthy (< {result.untrusted_below:g} Hz, high-pass)")
        ax.grid(True, alpha=0.3)
    top.axhline(0.0, color="k", lw=0.6)
    top.set_xlim(0, result.band[1])
    top.set_ylabel("transmissibility [dB]\nsqrt(S_payload/S_base)")
    top.legend(fontsize="small")
    bottom.set_ylim(0, 1.05)
    bottom.set_ylabel("coherence [-]")
    bottom.set_xlabel("frequency [Hz]")
    top.set_title(title if title is not None else Path(result.recording.source.split(" (")[0]).name)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig


def _averages(n_samples, fft_length, n_averages, notes):
    """``n_averages`` if the log holds them, else None (all that fit) with a warning."""
    from qzs.spectral import welch_average_count

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


def process_experiment(recording, *, highpass_corner=1.0, fft_length=32768, n_averages=29,
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
    DataError
        Missing channels, a log shorter than one FFT segment, a base signal that is not a
        chirp (when it must be inferred).
    """
    from qzs.excitation import Chirp
    from qzs.spectral import required_samples, transmissibility, transmissibility_metrics

    if not isinstance(recording, Recording):
        raise ParameterError(f"`recording` must be a qzs.readers.Recording, got "
                             f"{type(recording).__name__}; read the log with read_recording.")
    corner = float(highpass_corner or 0.0)
    if corner < 0:
        raise ParameterError(f"`highpass_corner` must be >= 0 [Hz], got {highpass_corner!r}.")
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

    def metrics(estimate):
        keep = (estimate.frequency > 0) & (estimate.frequency <= band[1])
        return transmissibility_metrics(estimate.frequency[keep], estimate.magnitude[keep],
                                        highpass_corner=corner or None)

    simulated = simulated_metrics = None
    seconds = 0.0
    if simulate_match:
        simulated, seconds = _simulate_like(recording, kind, excitation, isolator, controller,
                                            corner, welch, dt)
        simulated_metrics = metrics(simulated)
    return ExperimentResult(recording, kind, measured, simulated, metrics(measured),
                            simulated_metrics, band, corner, untrusted, excitation, inferred,
                            isolator, controller, tuple(notes), seconds)


def _simulate_like(recording, kind, excitation, isolator, controller, corner, welch, dt):
    """Simulate ``excitation`` at the log's rate and length; estimate like the log."""
    from qzs.simulate import simulate
    from qzs.spectral import transmissibility

    rate = recording.sample_rate
    steps = int(np.ceil(1.0 / (rate * dt) - 1e-9))
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


# ---------------------------------------------------------------- command line
def add_parser(subparsers):
    """Add ``experiment`` to an ``argparse`` sub-parser collection; returns the parser."""
    parser = subparsers.add_parser(
        "experiment", help="process an experiment log: transmissibility beside the simulation",
        description="Read a test-rig log with a channel map, estimate the transmissibility, "
                    "simulate the same chirp, and write a figure, a table and report.md.")
    parser.add_argument("log", metavar="LOG", help="log file (.csv, .mat, .mf4, .nc)")
    parser.add_argument("--map", required=True, metavar="MAP.toml",
                        help="channel map (see qzs.readers)")
    parser.add_argument("--out", metavar="DIR", default="qzs-experiment",
                        help="output folder (default qzs-experiment)")
    parser.add_argument("--no-simulation", action="store_true",
                        help="do not simulate the matching run")
    parser.add_argument("--fft-length", type=int, metavar="N",
                        help="Welch segment length [samples] (default 32768)")
    parser.add_argument("--averages", type=int, metavar="N",
                        help="Welch averages (default 29; fewer if the log is short)")
    parser.add_argument("--config", metavar="PARAMS.toml",
                        help="model parameters for the simulation (see `qzs params --toml`)")
    parser.add_argument("--resample", action="store_true",
                        help="resample a non-uniform time base onto a uniform grid")
    return parser


def run(args):
    """Run ``qzs experiment`` from parsed arguments; returns the exit code.

    ``ParameterError`` and ``DataError`` propagate to the caller (the ``qzs`` command
    prints them).
    """
    from qzs.excitation import Chirp
    from qzs.readers import load_channel_map, read_recording

    channel_map = load_channel_map(args.map)
    recording = read_recording(args.log, channel_map, resample=True if args.resample else None)
    settings = dict(channel_map.experiment)
    isolator = controller = None
    if args.config:
        from qzs.io import load_config

        config = load_config(args.config)
        isolator, controller = config["isolator"], config["controller"]
    corner = settings.get("highpass_corner", 1.0)
    given = {k: settings[k] for k in ("amplitude", "f0", "f1", "method") if k in settings}
    excitation = None
    if given:
        inferred = (infer_chirp(recording, highpass_corner=corner)
                    if not {"amplitude", "f0", "f1"} <= set(given) else None)
        values = {k: getattr(inferred, k) for k in ("amplitude", "f0", "f1")} if inferred else {}
        excitation = Chirp(**{**values, **given}, duration=recording.duration)
    result = process_experiment(
        recording, highpass_corner=corner,
        fft_length=args.fft_length or settings.get("fft_length", 32768),
        n_averages=args.averages or settings.get("n_averages", 29),
        isolator=isolator, controller=controller, simulate_match=not args.no_simulation,
        excitation=excitation)
    paths = result.write_report(args.out)
    print(result.summary())
    print(f"wrote {paths['report']}, {paths['figure'].name} (+ .svg) and {paths['table'].name}")
    return 0


def main(argv=None):
    """``python -m qzs.experiment``: the same as ``qzs experiment``."""
    import argparse
    import sys

    from qzs.errors import SimulationError

    parser = argparse.ArgumentParser(prog="qzs")
    add_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["experiment", *(sys.argv[1:] if argv is None else argv)])
    try:
        return run(args)
    except (ParameterError, DataError, SimulationError) as error:
        print(f"qzs: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
