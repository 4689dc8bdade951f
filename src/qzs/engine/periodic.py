"""Periodic stepping: a run advanced one excitation period per call (docs/response.md §1).

The steady-state response (:mod:`qzs.workflows.response`) simulates a sine one period at a
time and compares the state at the period boundaries. :class:`PeriodicRun` is that run: it
is prepared like any other (:func:`qzs.engine.prepare.prepare_run`), optionally continues
from the final state of another run (:class:`CarriedState`), and each :meth:`PeriodicRun.advance`
integrates one period into an output buffer. The state at the boundary is read by name
(:data:`STATE_VARIABLES`), the output columns by channel name
(:data:`qzs.engine.channels.CHANNELS`), so that callers need no kernel index.

A period of a whole number of :data:`~qzs.engine.kernels.PHASE_PERIOD` steps makes the
numbers those of one uncut run to the last bit (docs/model.md §9).

>>> import math
>>> from qzs import Sine
>>> from qzs.engine.periodic import PeriodicRun
>>> run = PeriodicRun(Sine(amplitude=0.01, frequency=2.0, phase=0.5 * math.pi, fade_in=0.0),
...                   period=0.5, dt=0.5 / 512, sample_rate=512.0)
>>> rows, marks = run.output_buffers()
>>> run.advance(rows[0], marks[0])
False
"""
from dataclasses import dataclass

import numpy as np

from qzs import defaults
from qzs.engine import kernels as K
from qzs.engine.prepare import divergence_message, prepare_run
from qzs.engine.single import SingleAxis
from qzs.errors import ParameterError

__all__ = ["PeriodicRun", "CarriedState", "STATE_VARIABLES"]

#: The period-boundary state that :meth:`PeriodicRun.state_of` reads, by name.
STATE_VARIABLES = {
    "relative_position": K.S_Z,    # z [m]
    "relative_velocity": K.S_V,    # v [m/s]
    "highpass_state": K.S_HP,      # the charge amplifier's filter state [m/s]
    "pi_integral": K.S_INT,        # the PI loop's integral [m*s]
}


@dataclass(frozen=True)
class CarriedState:
    """The final state of a :class:`PeriodicRun`, to continue another run from.

    Attributes
    ----------
    state : ndarray, shape (N_STATE,)
        The kernels' state vector (ODE state, held controller outputs, holding margin).
    flags : ndarray of int64, shape (N_FLAGS,)
        The kernels' integer flags (stick/slip mode, direction, counters).
    """

    state: np.ndarray
    flags: np.ndarray


class PeriodicRun:
    """A run of the single-axis isolator advanced one period per call.

    Built through :func:`~qzs.engine.prepare.prepare_run` (same validation, same initial
    state). With ``carried`` the run continues from another run's final state instead:
    the ODE state, held controller outputs, stick/slip mode and slip direction are kept;
    the energy ledger starts from zero, the holding margin is worked out again (the base's
    acceleration changed), the step and the contact and stick counters start from zero.

    Parameters
    ----------
    excitation : Sine, Chirp, RandomExcitation or DisplacementRecord
        Base motion; its time starts at 0 with this run.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    period : float
        Simulated time of one :meth:`advance` [s]; a whole number of steps ``dt`` and of
        output samples.
    dt : float
        Integration step [s].
    sample_rate : float
        Output sample rate [Hz]; ``1/dt`` must be a whole multiple of it.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    carried : CarriedState, optional
        Continue from this state (see above); default the prepared initial state (at rest
        at the setpoint).

    Attributes
    ----------
    dt : float
        Integration step [s].
    steps_per_period : int
        Integration steps per :meth:`advance` [-].
    samples_per_period : int
        Output samples per :meth:`advance` [samples].
    decimation : int
        Integration steps per output sample [-].

    Raises
    ------
    ParameterError
        Invalid input (as :func:`qzs.simulate`), or a ``period`` that is no whole number of
        output samples.
    StabilityError
        ``dt`` too large for a stable integration.
    """

    def __init__(self, excitation, isolator=None, controller=None, *, period, dt,
                 sample_rate, solver=defaults.SIMULATION["solver"], carried=None):
        run = prepare_run(excitation, isolator, controller, duration=period, dt=dt,
                          sample_rate=sample_rate, solver=solver)
        ratio = period / run.dt
        steps = int(round(ratio))
        if steps < 1 or abs(ratio - steps) > 1e-6 * ratio or steps % run.decimation:
            raise ParameterError(
                f"`period` ({period!r} s) must hold a whole number of output samples of "
                f"{run.decimation} steps of dt = {run.dt!r} s each; got {ratio:g} steps. Use "
                f"dt = period/n with n a multiple of {run.decimation}.")
        self._run = run
        self._state, self._flags = run.state, run.flags
        # the one-case stepper of the run driver (qzs.engine.driver), one period per call
        self._buffers = [None]
        self._stepper = SingleAxis(run, self._buffers)
        if carried is not None:
            self._state[:] = carried.state
            self._state[K.S_W_BASE:K.S_D_STOP + 1] = 0.0  # a fresh energy ledger
            self._state[K.A_MARGIN] = np.nan  # the base acceleration changed: work it out again
            self._flags[:] = carried.flags
            self._flags[K.I_STEP] = self._flags[K.I_N_CONTACTS] = self._flags[K.I_N_STICKS] = 0
        self.dt = run.dt
        self.decimation = run.decimation
        self.steps_per_period = steps
        self.samples_per_period = steps // run.decimation

    def output_buffers(self, periods=1):
        """Empty output buffers for ``periods`` periods (one :meth:`advance` each).

        Parameters
        ----------
        periods : int
            Periods the buffers hold [-].

        Returns
        -------
        rows : ndarray, shape (periods, samples_per_period, n_channels)
            Output rows; columns as :data:`qzs.engine.channels.CHANNELS`.
        marks : ndarray of bool, shape (periods, samples_per_period, n_flags)
            Boolean outputs; columns as :data:`qzs.engine.channels.FLAGS`.
        """
        rows = np.empty((periods, self.samples_per_period, K.N_CHANNELS))
        marks = np.zeros((periods, self.samples_per_period, 2), dtype=np.bool_)
        return rows, marks

    def advance(self, rows, marks):
        """Integrate one period, writing its output samples.

        The kernel records at the end of each block of ``decimation`` steps: the last row
        is the state at the period's end.

        Parameters
        ----------
        rows : ndarray, shape (samples_per_period, n_channels)
            Output rows, overwritten (one period of :meth:`output_buffers`).
        marks : ndarray of bool, shape (samples_per_period, n_flags)
            Boolean outputs, overwritten.

        Returns
        -------
        bool
            True if the integration diverged; then the state is the last finite one and
            :meth:`divergence` says where.
        """
        return self._advance(self.steps_per_period, rows, marks)

    def _advance(self, steps, rows, marks):
        """``steps`` steps from the current state through the single-axis stepper of the run
        driver (:class:`qzs.engine.single.SingleAxis`); True if it diverged."""
        self._buffers[0] = (rows, marks)
        self._stepper.advance(steps, 0, 0)
        return self._stepper.diverged

    def state_of(self, names):
        """The state now (at a period boundary) by name.

        Parameters
        ----------
        names : sequence of str
            Keys of :data:`STATE_VARIABLES`.

        Returns
        -------
        ndarray
            The values, in the order of ``names`` (a copy).
        """
        return self._state[[STATE_VARIABLES[name] for name in names]]

    @property
    def mode(self):
        """The stick/slip mode now: slipping, stuck, or resting on a low or high plastic
        stop (:data:`qzs.engine.kernels.MODE_SLIP` ...) [-]."""
        return int(self._flags[K.I_MODE])

    @property
    def stop_contacts(self):
        """Hard-stop contacts since the start of this run [-]."""
        return int(self._flags[K.I_N_CONTACTS])

    def divergence(self):
        """Where a diverged run failed: the time [s] of the failing step and the last
        finite state, as a sentence.

        Returns
        -------
        str
        """
        return divergence_message(self._state, self._flags[K.I_STEP], self.dt)

    def carry(self):
        """The state now, to continue another run from (``PeriodicRun(..., carried=...)``).

        Returns
        -------
        CarriedState
            Copies of the state and flags.
        """
        return CarriedState(state=self._state.copy(), flags=self._flags.copy())
