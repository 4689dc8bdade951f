"""What both open-question studies share: the verdict, the chirp batch and its curves.

Every case of a study runs in one lockstep batch through the lanes
(:func:`qzs.engine.batch.simulate_batch`: the numbers :func:`qzs.simulate` gives each, to the
last bit), under one chirp, and is reduced to its transmissibility curve over its trusted bins
(:func:`qzs.analysis.spectral.transmissibility`, docs/model.md §10) and the lanes' statistics.
"""
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs.analysis.damping import band_rms
from qzs.analysis.spectral import (band_mask, metric_unit, transmissibility,
                                   transmissibility_metrics)
from qzs.defaults import ANALYSIS
from qzs.errors import ParameterError, SimulationError
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension, save_doc

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["Answer", "ChirpPlan", "CaseCurve", "run_chirp_cases", "band_transmissibility"]

#: The answer labels, best first.
LABELS = ("yes", "partly", "no", "not decidable")


@dataclass(frozen=True)
class Answer:
    """The verdict of one open question, from the numbers (as ``qzs paper`` gives its own).

    Attributes
    ----------
    question : str
        The question's id (``friction_compensation``, ``damping_design``).
    statement : str
        What the paper leaves open, in its words.
    label : str
        ``"yes"``, ``"partly"``, ``"no"`` or ``"not decidable"``.
    answer : str
        The answer in one sentence.
    evidence : str
        The numbers it rests on, or why it cannot be decided.
    """

    question: str
    statement: str
    label: str
    answer: str
    evidence: str

    def __post_init__(self):
        if self.label not in LABELS:
            raise ValueError(f"`label` must be one of {LABELS}, got {self.label!r}.")

    def to_dict(self):
        """The verdict as a plain ``dict``."""
        return dict(self.__dict__)


@dataclass(frozen=True)
class ChirpPlan:
    """The chirp every case of a study runs under and how its curve is estimated.

    Attributes
    ----------
    excitation : Chirp
        The base motion.
    sample_rate : float
        Output rate [Hz] of the runs and of the Welch estimate.
    fft_length : int
        Welch segment [samples].
    dt : float
        Integration step [s].
    """

    excitation: object
    sample_rate: float
    fft_length: int
    dt: float


@dataclass
class CaseCurve:
    """One case's transmissibility and run statistics.

    Attributes
    ----------
    label : str
        The case's label.
    frequency, magnitude : ndarray
        Bin frequencies [Hz] and transmissibility [-] up to the chirp's top.
    trusted : ndarray of bool
        The bins metrics may use.
    metrics : dict
        :meth:`TransmissibilityMetrics.to_dict <qzs.analysis.spectral.TransmissibilityMetrics>`
        of the trusted bins (``isolation_onset`` [Hz] among them), NaN where undefined.
    reasons : dict
        Why each NaN metric is undefined.
    stats : dict
        The lanes' statistics (:data:`qzs.engine.batch.STATS`: ``stick_events``,
        ``motor_force_rms`` [N], ``stop_contacts``, ``locked_fraction``, ...).
    """

    label: str
    frequency: np.ndarray
    magnitude: np.ndarray
    trusted: np.ndarray
    metrics: dict = field(default_factory=dict)
    reasons: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def summary(self) -> str:
        """The case as text: its bins, its trusted peak, its metrics and statistics.

        Returns
        -------
        str
        """
        from qzs.workflows.findings.tables import case_text

        return case_text(self, _unit)

    def curve(self) -> dict[str, Any]:
        """The curve as the figures and the curves' files take it (``label``,
        ``frequency`` [Hz], ``magnitude`` [1], ``trusted``).

        Returns
        -------
        dict
        """
        return {"label": self.label, "frequency": self.frequency, "magnitude": self.magnitude,
                "trusted": self.trusted}

    def to_xarray(self) -> "xr.Dataset":
        """The curve as the paper's curves files lay it out
        (:func:`qzs.workflows.paper.curves.curves_dataset`: ``magnitude`` [1] and the
        ``trusted`` flag on ``case`` and ``frequency`` [Hz]); its metrics and statistics as
        global attributes with their ``_units``.

        Returns
        -------
        xarray.Dataset
        """
        from qzs.workflows.paper.curves import curves_dataset

        attrs: dict[str, Any] = {"title": f"transmissibility of {self.label}"}
        for name, value in (*self.metrics.items(), *self.stats.items()):
            attrs[name] = value
            if _unit(name):
                attrs[f"{name}_units"] = _unit(name)
        return curves_dataset([self.curve()], attrs)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> "Figure":
        """The curve in dB against frequency, trusted bins solid
        (:func:`qzs.viz.transmissibility.plot_transmissibility`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (a .png also as .svg).
        title : str, optional
            Figure title; default the case's label.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.transmissibility import plot_transmissibility

        return plot_transmissibility([self.curve()],
                                     frequency_range=(0.0, float(self.frequency[-1])),
                                     frequency_scale=frequency_scale,
                                     title=self.label if title is None else title, path=path)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray)

    save.__doc__ = save_doc("``.nc`` (NetCDF, CF-1.10), ``.csv`` (one row per bin) or "
                            "``.mat`` (MATLAB) of :meth:`to_xarray`: the curve, its metrics "
                            "and statistics")


def _unit(name):
    """The unit of a case's metric or statistic ("1" a ratio or a count), "" if none."""
    from qzs.engine.batch import STATS

    return metric_unit(name) or STATS.get(name, ("",))[0]


def band_transmissibility(curve, band):
    """RMS of a case's transmissibility over the trusted bins of ``band`` [-] (NaN if none).

    Parameters
    ----------
    curve : CaseCurve
        The case.
    band : tuple of float
        ``(low, high)`` [Hz].

    Returns
    -------
    float
    """
    return band_rms(curve.frequency, curve.magnitude, band, trusted=curve.trusted)


def run_chirp_cases(labels, cases, plan, *, workers=None, progress=False):
    """Simulate ``cases`` under ``plan``'s chirp in one lockstep batch; one curve per case.

    Parameters
    ----------
    labels : sequence of str
        A label per case.
    cases : sequence of (IsolatorParameters, ControllerParameters)
        The cases (controllers with blocks too).
    plan : ChirpPlan
        The chirp, step and Welch estimate.
    workers : int, optional
        Threads of the batch; default all cores.
    progress : bool
        Show the batch's progress bar.

    Returns
    -------
    list of CaseCurve
        In the order of ``cases``.

    Raises
    ------
    SimulationError
        A case that diverged, named by its label.
    """
    from qzs.engine.batch import STATS, simulate_batch

    batch = simulate_batch(list(cases), plan.excitation, dt=plan.dt,
                           sample_rate=plan.sample_rate,
                           channels=("base_acceleration", "payload_acceleration"),
                           workers=workers, progress=progress)
    top = plan.excitation.f1
    curves = []
    for index, label in enumerate(labels):
        if batch.messages[index]:
            raise SimulationError(f"{label}: {batch.messages[index]}")
        estimate = transmissibility(batch.channels["base_acceleration"][index],
                                    batch.channels["payload_acceleration"][index],
                                    plan.sample_rate, fft_length=plan.fft_length,
                                    overlap=ANALYSIS["overlap"],
                                    coherence_min=ANALYSIS["coherence_min"],
                                    base_share_min=ANALYSIS["base_share_min"])
        keep = band_mask(estimate.frequency, 0.0, top)
        frequency, magnitude = estimate.frequency[keep], estimate.magnitude[keep]
        trusted = estimate.trusted[keep]
        metrics = transmissibility_metrics(frequency, magnitude, trusted=trusted)
        curves.append(CaseCurve(label, frequency, magnitude, trusted, metrics.to_dict(),
                                dict(metrics.reasons),
                                {name: float(batch.stats[name][index]) for name in STATS}))
    return curves


def finite(*values):
    """All ``values`` are finite numbers."""
    return all(isinstance(v, (int, float, np.floating)) and math.isfinite(v) for v in values)


def check_step(dt):
    """Refuse an integration step that is not a positive finite number of seconds.

    Parameters
    ----------
    dt : float
        The step [s].

    Raises
    ------
    ParameterError
        Naming ``dt``, its value and the paper's step.
    """
    if isinstance(dt, bool) or not (isinstance(dt, (int, float)) and math.isfinite(dt)
                                    and dt > 0):
        raise ParameterError(f"`dt` must be a positive step [s], got {dt!r}; the paper's is "
                             "1e-4.", "dt")
