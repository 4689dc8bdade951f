"""The paper's transmissibility estimate for comparison: a slow chirp and a Welch ratio
(docs/response.md §7), set beside the steady state by ``compare_chirp``.
"""
from qzs import defaults
from qzs._validation import positive_real
from qzs.model.excitation import Chirp

__all__ = ["chirp_transmissibility", "PAPER_SWEEP_RATE"]

#: Chirp of the comparison: the paper's sweep rate [Hz/s] (0 -> 20 Hz over 2000 s).
PAPER_SWEEP_RATE = 0.01


def _run_chirp(task):
    """The chirp-and-Welch estimate (a worker task)."""
    return chirp_transmissibility(task["amplitude"], task["isolator"], task["controller"],
                                  top=task["top"], dt=task["dt"], solver=task["solver"])


def chirp_transmissibility(amplitude=defaults.EXCITATION["amplitude"], isolator=None,
                           controller=None, *, top=20.0, dt=defaults.SIMULATION["dt"],
                           solver=defaults.SIMULATION["solver"],
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

    top = max(20.0, positive_real("top", top))
    rate = defaults.ANALYSIS["sample_rate"]
    chirp = Chirp(amplitude=amplitude, f0=0.0, f1=top, duration=top / PAPER_SWEEP_RATE)
    result = simulate(chirp, isolator, controller, dt=dt, sample_rate=rate, solver=solver)
    return transmissibility(result.base_acceleration, result.payload_acceleration, rate,
                            fft_length=fft_length)

