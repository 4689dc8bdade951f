"""What both open-question studies share: the verdict, the chirp batch and its curves.

Every case of a study runs in one lockstep batch through the lanes
(:func:`qzs.engine.batch.simulate_batch`: the numbers :func:`qzs.simulate` gives each, to the
last bit), under one chirp, and is reduced to its transmissibility curve over its trusted bins
(:func:`qzs.analysis.spectral.transmissibility`, docs/model.md §10) and the lanes' statistics.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from qzs.analysis.damping import band_rms
from qzs.analysis.spectral import band_mask, transmissibility, transmissibility_metrics
from qzs.defaults import ANALYSIS
from qzs.errors import ParameterError, SimulationError

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
