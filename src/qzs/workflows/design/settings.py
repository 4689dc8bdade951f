"""The design's defaults and search sizes, and the validated settings every stage shares."""
import dataclasses
from dataclasses import dataclass

import numpy as np

from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters

__all__ = ["DesignSettings", "COSTS", "FAMILIES", "SAMPLE_RATE", "FFT_LENGTH", "QUICK_CHIRP", "KP_GRID",
           "BISECTIONS", "HUNTING_MAX", "DAMPING_POINTS", "DAMPING_GAIN_MAX",
           "STROKE_STEP_MAX", "TRUSTED_SHARE_MIN", "RATES", "DELAYS"]


#: Transmissibility costs over the band: RMS of the amplitude ratio over the trusted bins
#: (equally spaced in frequency: the payload's RMS acceleration per RMS of a base acceleration
#: white over the band), or its largest value.
COSTS = ("rms", "peak")
#: Case families (see the module's text).
FAMILIES = ("base", "step", "hunting")
#: Output rate of the design's runs [Hz] (ten times the default band's top).
SAMPLE_RATE = 200.0
#: Welch segment length of the cost [samples]: quick and full.
FFT_LENGTH = {True: 2048, False: 8192}
#: Length of the quick runs' chirp [s] (the same sweep, ten times faster than the paper's).
QUICK_CHIRP = 200.0
#: Proportional gains tried first [N/m]: quick and full.
KP_GRID = {True: tuple(np.geomspace(1.0, 1000.0, 7)), False: tuple(np.geomspace(1.0, 1000.0, 10))}
#: Bisection steps between the bracketing gains: quick and full.
BISECTIONS = {True: 3, False: 5}
#: Longest hunting run [s]: quick and full.
HUNTING_MAX = {True: 600.0, False: 1500.0}
#: Damping gains tried in the coarse pass (besides 0) and the refinement: quick and full.
DAMPING_POINTS = {True: (5, 3), False: (7, 4)}
#: Largest damping gain tried by default [N*s/m]: ten times the guide's viscous friction.
#: The model has no sensor noise, motor bandwidth or structural mode, which bound a real
#: gain: beyond this it is not to be trusted.
DAMPING_GAIN_MAX = 1000.0
#: Largest step of the PI search's runs [s] (see _stroke_step).
STROKE_STEP_MAX = 2.5e-3
#: Least share of the band's bins that must be trusted for a cost to be defined [-].
TRUSTED_SHARE_MIN = 0.5
#: Controller rates [Hz] of the margin table and the rate experiments.
RATES = (20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0)
#: Delays [s] of the linear delay experiment.
DELAYS = (0.0, 0.001, 0.002, 0.005)


@dataclass(frozen=True, kw_only=True)
class DesignSettings:
    """The design's plan: its validated inputs and its steps, resolved once and shared by
    every stage (made by :func:`qzs.workflows.design.inputs._design_settings`).

    Frozen: the steps are chosen before it is made (``dt`` [s], ``dt_note``, ``stroke_dt``
    [s]), and a stage that needs other gains builds its controller with
    :meth:`controller_at`, never by changing the plan. The ranges, band and rates carry
    the units of :func:`~qzs.workflows.design.design_controller`'s arguments.

    Attributes
    ----------
    isolator : IsolatorParameters
        The plant.
    controller : ControllerParameters
        The controller whose Ki/Kp ratio the search keeps.
    excitation : Chirp, RandomExcitation or DisplacementRecord
        The base motion of the cost's runs.
    duration : float
        Its length [s].
    stiction_range, mass_range : tuple of float
        Stiction forces [N, N] and moving masses [kg, kg] of the cases.
    force_steps : tuple of float
        Payload force steps [N], upward positive.
    band : tuple of float
        The cost's band [Hz, Hz].
    cost : {"rms", "peak"}
        The transmissibility cost over the band.
    controller_rate : float
        Controller rate [Hz]; 0 continuous.
    delay : float
        Loop delay [s].
    quick : bool
        Short runs and a coarse search.
    dt : float
        The accuracy-driven (or given) step of the cost's runs [s].
    dt_note : str
        How ``dt`` was chosen.
    sample_rate : float
        Output rate of the runs [Hz].
    fft_length : int
        Welch segment length of the cost [samples].
    ratio : float
        The kept ratio Ki/Kp [1/s].
    stroke_band : tuple of float
        The constant-force band of the stroke [m, m].
    stroke_dt : float
        The step of the PI search's runs [s] (``_stroke_step``).
    damping_gain_max : float
        Largest damping gain tried [N*s/m].
    gain_margin_min : float
        Least gain margin [dB].
    phase_margin_min : float
        Least phase margin [deg].
    workers : int
        Threads [-].
    progress : bool
        Show progress bars.
    """

    isolator: IsolatorParameters
    controller: ControllerParameters
    excitation: object
    duration: float
    stiction_range: tuple
    mass_range: tuple
    force_steps: tuple
    band: tuple
    cost: str
    controller_rate: float
    delay: float
    quick: bool
    dt: float
    dt_note: str
    sample_rate: float
    fft_length: int
    ratio: float
    stroke_band: tuple
    stroke_dt: float
    damping_gain_max: float
    gain_margin_min: float
    phase_margin_min: float
    workers: int
    progress: bool

    def controller_at(self, kp, kd=None):
        """The design's controller at other gains, the ratio Ki/Kp and the rate kept.

        Parameters
        ----------
        kp : float
            Proportional gain [N/m]; ``Ki = ratio * kp`` [N/(m*s)].
        kd : float, optional
            Damping gain [N*s/m]; default the controller's.

        Returns
        -------
        ControllerParameters
        """
        return dataclasses.replace(self.controller, pi_kp=float(kp), pi_ki=float(self.ratio * kp),
                                   damping_gain=self.controller.damping_gain if kd is None
                                   else float(kd), controller_rate=self.controller_rate)
