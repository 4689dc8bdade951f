"""The isolator's controller as a value: PI position loop plus active damping (paper Fig. 6),
and the blocks a user adds to it (docs/model.md §5).

:class:`ControllerParameters` (also named :class:`PIDamping`) is today's controller and the
default. Blocks add to it (``PIDamping() + FrictionCompensation(fraction=0.8)``), each with
its own force recorded as a channel:

* :class:`FrictionCompensation`: a feedforward of the friction law on the measured relative
  velocity, a fraction in [0, 1.5] of it, with a velocity deadband and an optional
  first-order observer of the friction left;
* :class:`Dither`: a sinusoidal force of set amplitude and frequency;
* :class:`LinearController`: any proper linear time-invariant controller (a python-control
  ``StateSpace`` or ``TransferFunction``, matrices, numerator and denominator), continuous or
  discrete, its inputs chosen by name from what the rig measures (:data:`SENSORS`), its
  output the motor force.

The PI + damping laws::

    e       = z_ref - z
    F_pi    = Kp*e + Ki*integral(e)            (anti-windup: the integral is frozen
                                                while the motor saturates and e pushes
                                                further into saturation)
    F_d     = -Kd * v_payload_measured         (accelerometer integrated by the charge
                                                amplifier, with its first-order high-pass)
    F_motor = clip(F_pi + F_d, -F_max, F_max)

Continuous, or sampled at ``controller_rate`` with zero-order hold (dSPACE DS1104).
"""
import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from qzs._validation import (non_negative_real, optional, parameter, positive_real, real,
                             validate_fields)
from qzs.errors import ParameterError
from qzs.model.isolator import IsolatorParameters, spring_stiffness
from qzs.model.sensors import MAX_STATES, SENSORS

__all__ = ["ControllerParameters", "PIDamping", "FrictionCompensation", "Dither",
           "LinearController", "SENSORS", "MAX_STATES", "BLOCKS", "BLOCK_CLASSES",
           "block_parameters",
           "refuse_blocks",
           "closed_loop_natural_frequency"]

#: The blocks a controller may carry beyond PI + damping: field name -> class name.
BLOCKS = ("compensation", "dither", "linear")
#: Default anti-windup tracking time of a linear controller [s] (docs/model.md §5).
TRACKING_TIME = 0.1


def _fraction(name, value):
    return real(name, value, minimum=0.0, maximum=1.5,
                fix="0 is none, 1 cancels the friction law, up to 1.5 over-compensates")


@dataclass(frozen=True, kw_only=True)
class FrictionCompensation:
    """Friction compensation by the motor: a feedforward of the friction law (docs/model.md §5).

    ``F_ff = fraction * [Fc + (Fs - Fc) exp(-Cbc |v|)] sign(v) + fraction * Cv v`` for
    ``|v| > deadband``, else 0, on the measured relative velocity ``v`` (the encoder's), so
    nothing while the payload sticks; with an observer, the friction left after it
    (``r``, first order: ``r' = 2 pi f_o (r_measured - r)``) is cancelled too:
    ``F_comp = F_ff - r``. Over-compensation (``fraction > 1``) is allowed: it is where
    the loop starts to hunt.

    Parameters
    ----------
    fraction : float
        Fraction of the friction law compensated [-], in [0, 1.5].
    stiction_force, coulomb_force : float, optional
        The compensator's friction levels Fs, Fc [N]; default the plant's own (a perfectly
        identified law), or from a fit (:meth:`from_fit`).
    stribeck_decay : float, optional
        The compensator's Stribeck decay coefficient Cbc [s/m]; default the plant's.
    viscous_damping : float, optional
        The compensator's viscous coefficient Cv [N*s/m]; default 0: the viscous friction is
        the loop's damping, and cancelling it makes the default PI loop unstable
        (docs/model.md §5); None takes the plant's.
    deadband : float
        Velocity deadband [m/s]: no feedforward while ``|v|`` is at most this.
    observer_bandwidth : float
        Bandwidth of the first-order observer of the friction left [Hz]; 0 (default): none.
    """

    fraction: float = parameter(1.0, "-", "fraction of the friction law compensated")
    stiction_force: float | None = parameter(None, "N", "compensator's stiction force Fs")
    coulomb_force: float | None = parameter(None, "N", "compensator's Coulomb force Fc")
    stribeck_decay: float | None = parameter(None, "s/m", "compensator's Stribeck decay Cbc")
    viscous_damping: float | None = parameter(0.0, "N*s/m", "compensator's viscous damping Cv")
    deadband: float = parameter(0.0, "m/s", "velocity deadband of the compensation")
    observer_bandwidth: float = parameter(0.0, "Hz", "friction observer bandwidth (0 = none)")

    def __post_init__(self):
        validate_fields(self, {
            "fraction": _fraction,
            "stiction_force": optional(non_negative_real),
            "coulomb_force": optional(non_negative_real),
            "stribeck_decay": optional(non_negative_real),
            "viscous_damping": optional(non_negative_real),
            "deadband": non_negative_real,
            "observer_bandwidth": non_negative_real,
        })
        if (self.stiction_force is not None and self.coulomb_force is not None
                and self.coulomb_force > self.stiction_force):
            raise ParameterError(
                f"`coulomb_force` ({self.coulomb_force!r} N) must not exceed `stiction_force` "
                f"({self.stiction_force!r} N) in a FrictionCompensation; swap them.",
                ("coulomb_force", "stiction_force"))

    @classmethod
    def from_fit(cls, fit: Any, **options: Any) -> "FrictionCompensation":
        """The compensation of a friction law identified by :func:`qzs.fit_friction`.

        Parameters
        ----------
        fit : FrictionFit
            The fit; its Fs, Fc and Cbc become the compensator's (its Cv only if
            ``viscous_damping=fit.viscous_damping`` is given: see the class).
        **options
            The other fields (``fraction``, ``deadband``, ``observer_bandwidth``,
            ``viscous_damping``).

        Returns
        -------
        FrictionCompensation
        """
        values = {name: float(getattr(fit, name)) for name in
                  ("stiction_force", "coulomb_force", "stribeck_decay")
                  if getattr(fit, name, None) is not None}
        return cls(**values, **options)

    def law(self, isolator: IsolatorParameters) -> tuple[float, float, float, float]:
        """The compensator's ``(Fs [N], Fc [N], Cbc [s/m], Cv [N*s/m])``, the plant's where unset.

        Parameters
        ----------
        isolator : IsolatorParameters
            The plant, for the values left unset.

        Returns
        -------
        tuple of float
        """
        fs, fc, cbc, cv = (float(getattr(isolator, name) if getattr(self, name) is None
                                 else getattr(self, name))
                           for name in ("stiction_force", "coulomb_force", "stribeck_decay",
                                        "viscous_damping"))
        return fs, fc, cbc, cv

    def __add__(self, other):
        return _add(self, other)

    __radd__ = __add__


@dataclass(frozen=True, kw_only=True)
class Dither:
    """A dither: the sinusoidal motor force ``amplitude * sin(2 pi frequency t)`` [N].

    The classic way to keep a contact from sticking; its cost in motor effort and in payload
    acceleration is in a run's summary (docs/model.md §5).

    Parameters
    ----------
    amplitude : float
        Force amplitude [N].
    frequency : float
        Frequency [Hz].
    """

    amplitude: float = parameter(1.0, "N", "dither force amplitude")
    frequency: float = parameter(50.0, "Hz", "dither frequency")

    def __post_init__(self):
        validate_fields(self, {"amplitude": non_negative_real, "frequency": positive_real})

    def __add__(self, other):
        return _add(self, other)

    __radd__ = __add__


#: What each dimension of a linear controller's matrix counts (for the messages).
_SHAPES = {"a": "states x states", "b": "states x inputs",
           "c": "one output (the motor force) x states", "d": "one output x inputs"}


def _matrix(name, value, shape):
    try:
        array = np.array(value, dtype=float, ndmin=2)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be a matrix of numbers, got {value!r}.", (name,))
    if array.size == 0 and 0 in shape:
        array = np.zeros(shape)
    if array.shape != shape:
        raise ParameterError(
            f"`{name}` must have shape {shape} ({_SHAPES[name]}), got {array.shape}: "
            f"{np.asarray(value).tolist()!r}; check the controller's state, input (one sensor "
            "per column of b and entry of d) and output (one row of c) counts.", (name,))
    if not np.isfinite(array).all():
        raise ParameterError(f"`{name}` has non-finite (NaN or inf) entries: "
                             f"{array.tolist()!r}; every entry of a controller's matrices "
                             "must be a finite number.", (name,))
    return tuple(tuple(float(x) for x in row) for row in array)


def _inputs(value):
    names = (value,) if isinstance(value, str) else tuple(value)
    if not names:
        raise ParameterError("`inputs` must name at least one sensor; choose from "
                             f"{', '.join(SENSORS)}.", ("inputs",))
    for name in names:
        if name not in SENSORS:
            raise ParameterError(f"`inputs` names an unknown sensor {name!r}; choose from "
                                 f"{', '.join(SENSORS)}.", ("inputs",))
    if len(set(names)) != len(names):
        raise ParameterError(f"`inputs` names a sensor twice: {list(names)}; give each once.",
                             ("inputs",))
    return names


@dataclass(frozen=True, kw_only=True)
class LinearController:
    """A user's linear time-invariant controller: ``x' = A x + B u``, ``F = C x + D u``.

    Its inputs ``u`` are sensors chosen by name (:data:`SENSORS`, SI units), its output the
    motor force [N], added to the other blocks' and saturated at ``motor_force_max`` with
    anti-windup by back-calculation: ``x' = A x + B u + L (F_motor - F_command)`` with
    ``L = C^T / (C C^T T_t)``, so the command tracks the saturated force with the time
    constant ``T_t`` (``tracking_time``; discrete: ``L`` times ``min(T_s/T_t, 1)``)
    (docs/model.md §5). Continuous (``sample_time = 0``): its states join the plant's and
    are stepped by the same Runge-Kutta scheme. Discrete (``sample_time > 0``, a whole number
    of integration steps): ``x <- A x + B u`` every ``sample_time``, output held (zero-order
    hold). Build it with :meth:`from_system` from python-control, or from matrices.

    Parameters
    ----------
    a : sequence of sequence of float
        State matrix A, shape (n, n), n <= :data:`MAX_STATES` [1/s; discrete: -].
    b : sequence of sequence of float
        Input matrix B, shape (n, len(inputs)) [state per input unit].
    c : sequence of float
        Output row C, shape (n,) [N per state unit].
    d : sequence of float
        Feedthrough D, shape (len(inputs),) [N per input unit].
    inputs : sequence of str
        The sensors, in the order of B's columns (:data:`SENSORS`).
    sample_time : float
        0: continuous; else the sampling period of a discrete controller [s].
    tracking_time : float
        Anti-windup tracking time T_t [s].
    name : str
        What the controller is called in summaries and records.
    """

    a: ArrayLike = parameter((), "1/s", "state matrix A")
    b: ArrayLike = parameter((), "-", "input matrix B")
    c: ArrayLike = parameter((), "N", "output matrix C")
    d: ArrayLike = parameter((), "N", "feedthrough D")
    inputs: tuple = parameter(("measured_payload_velocity",), "-", "sensors the controller reads")
    sample_time: float = parameter(0.0, "s", "sampling period (0 = continuous)")
    tracking_time: float = parameter(TRACKING_TIME, "s", "anti-windup tracking time")
    name: str = parameter("linear", "-", "name of the controller")

    def __post_init__(self):
        inputs = _inputs(self.inputs)
        object.__setattr__(self, "inputs", inputs)
        try:
            n = np.array(self.a, dtype=float, ndmin=2).shape[0] if np.size(self.a) else 0
        except (TypeError, ValueError):
            raise ParameterError(f"`a` must be a square matrix of numbers, got {self.a!r}.",
                                 ("a",)) from None
        if n > MAX_STATES:
            raise ParameterError(
                f"a LinearController may have at most {MAX_STATES} states, got {n}; reduce "
                "its order (e.g. control.balred or control.minreal).", ("a",))
        object.__setattr__(self, "a", _matrix("a", self.a if n else np.zeros((0, 0)), (n, n)))
        object.__setattr__(self, "b", _matrix("b", self.b if n else np.zeros((0, len(inputs))),
                                              (n, len(inputs))))
        object.__setattr__(self, "c", _matrix("c", self.c if n else np.zeros((1, 0)), (1, n))[0])
        object.__setattr__(self, "d", _matrix("d", self.d, (1, len(inputs)))[0])
        validate_fields(self, {"sample_time": non_negative_real,
                               "tracking_time": positive_real})
        if not isinstance(self.name, str) or not self.name:
            raise ParameterError(f"`name` must be a non-empty string, got {self.name!r}.",
                                 ("name",))
        if (self.sample_time == 0.0 and "payload_acceleration" in inputs
                and self.d[inputs.index("payload_acceleration")] != 0.0):
            raise ParameterError(
                "a continuous LinearController must not feed the payload acceleration straight "
                f"through (its D entry is {self.d[inputs.index('payload_acceleration')]!r}): the "
                "motor force would depend on the acceleration it causes (an algebraic loop). "
                "Give that input a low-pass (an accelerometer has a bandwidth), e.g. "
                "K(s) * w/(s + w), or make the controller discrete.", ("d",))

    @property
    def states(self) -> int:
        """Number of states [-]."""
        return int(np.shape(self.a)[0])

    @property
    def discrete(self) -> bool:
        """True for a discrete (sampled) controller."""
        return self.sample_time > 0.0

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C, D)`` as arrays of shapes (n, n), (n, m), (1, n), (1, m)."""
        n, m = self.states, len(self.inputs)
        return (np.array(self.a, dtype=float).reshape(n, n),
                np.array(self.b, dtype=float).reshape(n, m),
                np.array(self.c, dtype=float).reshape(1, n),
                np.array(self.d, dtype=float).reshape(1, m))

    def antiwindup_gain(self) -> np.ndarray:
        """The back-calculation gain ``L`` [state per N], shape (n,) (docs/model.md §5)."""
        c = np.array(self.c, dtype=float)
        norm = float(c @ c)
        if norm == 0.0:
            return np.zeros(self.states)
        rate = min(self.sample_time / self.tracking_time, 1.0) if self.discrete \
            else 1.0 / self.tracking_time
        return c / norm * rate

    @classmethod
    def from_system(cls, system: Any, inputs: Any = ("measured_payload_velocity",),
                    **options: Any) -> "LinearController":
        """A controller from a python-control ``StateSpace`` or ``TransferFunction``.

        Parameters
        ----------
        system : control.StateSpace or control.TransferFunction
            One output (the motor force [N]), one input per entry of ``inputs``; continuous
            (``dt`` 0) or discrete (its ``dt`` the sample time [s]).
        inputs : sequence of str
            The sensors it reads (:data:`SENSORS`).
        **options
            ``tracking_time`` [s], ``name``.

        Returns
        -------
        LinearController

        Raises
        ------
        ParameterError
            Not a python-control system, improper, wrong input or output counts, non-finite
            entries, more than :data:`MAX_STATES` states.
        """
        import control

        inputs = _inputs(inputs)
        if isinstance(system, control.TransferFunction):
            for i in range(system.noutputs):
                for j in range(system.ninputs):
                    num, den = np.trim_zeros(system.num[i][j], "f"), np.trim_zeros(
                        system.den[i][j], "f")
                    if len(num) > len(den):
                        raise ParameterError(
                            f"`system` is improper (numerator of degree {len(num) - 1} over a "
                            f"denominator of degree {len(den) - 1}); a controller must be "
                            "proper: add poles (e.g. a low-pass) until the degrees match.",
                            ("system",))
            system = control.ss(system)
        if not isinstance(system, control.StateSpace):
            raise ParameterError(f"`system` must be a python-control StateSpace or "
                                 f"TransferFunction, got {type(system).__name__}.", ("system",))
        if system.noutputs != 1:
            raise ParameterError(f"`system` must have one output (the motor force), got "
                                 f"{system.noutputs}.", ("system",))
        if system.ninputs != len(inputs):
            raise ParameterError(f"`system` has {system.ninputs} inputs but `inputs` names "
                                 f"{len(inputs)} ({', '.join(inputs)}); name one sensor per "
                                 "input, in order.", ("inputs",))
        dt = system.dt
        sample_time = 0.0 if dt in (None, 0, False) else float(dt)
        if dt is True:
            raise ParameterError("`system` is discrete with an unspecified sample time "
                                 "(dt=True); give it its sample time in seconds.", ("system",))
        return cls(a=np.asarray(system.A), b=np.asarray(system.B),
                   c=np.asarray(system.C).ravel(), d=np.asarray(system.D).ravel(),
                   inputs=inputs, sample_time=sample_time, **options)

    @classmethod
    def from_transfer_function(cls, numerator: Any, denominator: Any,
                               inputs: Any = ("measured_payload_velocity",), *,
                               sample_time: float = 0.0, **options: Any) -> "LinearController":
        """A single-input controller ``F(s) = num(s)/den(s) u(s)`` (or in z if discrete).

        Parameters
        ----------
        numerator, denominator : sequence of float
            Polynomial coefficients, highest power first [SI].
        inputs : str or sequence of str
            The one sensor it reads.
        sample_time : float
            0: continuous, else the sample time [s].
        **options
            ``tracking_time`` [s], ``name``.

        Returns
        -------
        LinearController
        """
        import control

        sample_time = non_negative_real("sample_time", sample_time)
        for name, value in (("numerator", numerator), ("denominator", denominator)):
            array = np.atleast_1d(np.asarray(value, dtype=float))
            if array.size == 0 or not np.isfinite(array).all():
                raise ParameterError(f"`{name}` must be finite polynomial coefficients, got "
                                     f"{value!r}.", (name,))
        if not np.any(np.asarray(denominator, dtype=float)):
            raise ParameterError("`denominator` must not be zero.", ("denominator",))
        num, den = (np.trim_zeros(np.atleast_1d(np.asarray(v, dtype=float)), "f")
                    for v in (numerator, denominator))
        if len(num) > len(den):
            raise ParameterError(
                f"the transfer function is improper: `numerator` {list(map(float, num))} has "
                f"degree {len(num) - 1}, above the degree {len(den) - 1} of `denominator` "
                f"{list(map(float, den))}; a controller must be proper: add poles (e.g. a "
                "low-pass) until the degrees match.", ("numerator", "denominator"))
        system = control.tf(list(np.atleast_1d(numerator)), list(np.atleast_1d(denominator)),
                            sample_time if sample_time else 0)
        return cls.from_system(system, inputs, **options)

    def to_system(self) -> Any:
        """The controller as a python-control ``StateSpace`` (``dt`` its sample time).

        Returns
        -------
        control.StateSpace
        """
        import control

        a, b, c, d = self.matrices()
        return control.ss(a, b, c, d, self.sample_time if self.discrete else 0,
                          inputs=list(self.inputs), outputs=["motor_force"])

    def __add__(self, other):
        return _add(self, other)

    __radd__ = __add__



@dataclass(frozen=True, kw_only=True, repr=False)
class ControllerParameters:
    """The controller: PI position loop, active damping, and the blocks added to them.

    Also named :class:`PIDamping`: today's controller, the default. Blocks add to it with
    ``+`` (``PIDamping() + FrictionCompensation(fraction=0.8) + Dither(amplitude=2)``);
    each block is one of its fields, None when absent.

    Parameters
    ----------
    position_setpoint : float
        Encoder position setpoint z_ref [m]; default -0.060 m, the middle of the
        MagSpring's constant-force region (docs/model.md §1, operating point).
    pi_kp : float
        Proportional gain Kp [N/m]; Kp = 50 N/m moves the resonance to about 0.45 Hz.
    pi_ki : float
        Integral gain Ki [N/(m*s)].
    damping_gain : float
        Active damping gain Kd [N*s/m] on the measured payload velocity.
    velocity_highpass : float
        Corner of the charge amplifier's first-order high-pass on the payload
        velocity [Hz]; 0 switches it off.
    controller_rate : float
        Sampling rate of a discrete controller with zero-order hold [Hz];
        0 (default) runs the controller in continuous time. The compensation and dither
        follow it; a :class:`LinearController` has its own ``sample_time``.
    compensation : FrictionCompensation, optional
        Friction compensation block.
    dither : Dither, optional
        Dither block.
    linear : LinearController, optional
        The user's linear controller.
    """

    position_setpoint: float = parameter(-0.060, "m", "encoder position setpoint z_ref")
    pi_kp: float = parameter(50.0, "N/m", "PI proportional gain Kp")
    pi_ki: float = parameter(20.0, "N/(m*s)", "PI integral gain Ki")
    damping_gain: float = parameter(0.0, "N*s/m", "active damping gain Kd")
    velocity_highpass: float = parameter(1.0, "Hz", "charge-amplifier high-pass corner (0 = off)")
    controller_rate: float = parameter(0.0, "Hz", "controller sampling rate (0 = continuous)")
    compensation: FrictionCompensation | None = dataclasses.field(
        default=None, metadata={"block": True, "unit": "-", "doc": "friction compensation block"})
    dither: Dither | None = dataclasses.field(
        default=None, metadata={"block": True, "unit": "-", "doc": "dither block"})
    linear: LinearController | None = dataclasses.field(
        default=None, metadata={"block": True, "unit": "-", "doc": "the user's linear controller"})

    def __post_init__(self):
        validate_fields(self, {
            "position_setpoint": real,
            "pi_kp": non_negative_real,
            "pi_ki": non_negative_real,
            "damping_gain": non_negative_real,
            "velocity_highpass": non_negative_real,
            "controller_rate": non_negative_real,
        })
        for name, kind in BLOCK_CLASSES.items():
            value = getattr(self, name)
            if value is not None and not isinstance(value, kind):
                raise ParameterError(f"`{name}` must be a {kind.__name__} or None, got "
                                     f"{type(value).__name__}.", (name,))

    def __repr__(self) -> str:
        shown = [f"{field.name}={getattr(self, field.name)!r}"
                 for field in dataclasses.fields(self)
                 if not field.metadata.get("block") or getattr(self, field.name) is not None]
        return f"{type(self).__name__}({', '.join(shown)})"

    @property
    def sample_rates(self) -> tuple[float, ...]:
        """The rates [Hz] the controller samples at: its own (``controller_rate``) and a
        discrete linear controller's; empty for a continuous controller. The integration
        step divides the period of each."""
        rates = [self.controller_rate] if self.controller_rate > 0 else []
        if self.linear is not None and self.linear.discrete:
            rates.append(1.0 / self.linear.sample_time)
        return tuple(dict.fromkeys(rates))

    @property
    def has_blocks(self) -> bool:
        """Whether the controller has blocks beyond PI + damping."""
        return any(getattr(self, name) is not None for name in BLOCKS)

    def describe(self) -> str:
        """One line naming the controller's loops and blocks with their main settings."""
        parts = []
        if self.pi_kp or self.pi_ki:
            parts.append(f"PI (Kp {self.pi_kp:g} N/m, Ki {self.pi_ki:g} N/(m*s))")
        if self.damping_gain:
            parts.append(f"damping (Kd {self.damping_gain:g} N*s/m)")
        if self.compensation is not None:
            observer = self.compensation.observer_bandwidth
            parts.append(f"friction compensation (fraction {self.compensation.fraction:g}"
                         + (f", deadband {self.compensation.deadband:g} m/s"
                            if self.compensation.deadband else "")
                         + (f", observer {observer:g} Hz" if observer else "") + ")")
        if self.dither is not None:
            parts.append(f"dither ({self.dither.amplitude:g} N at {self.dither.frequency:g} Hz)")
        if self.linear is not None:
            timing = (f"sampled every {self.linear.sample_time:g} s" if self.linear.discrete
                      else "continuous")
            parts.append(f"linear controller '{self.linear.name}' ({self.linear.states} states, "
                         f"{timing}, on {', '.join(self.linear.inputs)})")
        rate = (f"; sampled at {self.controller_rate:g} Hz" if self.controller_rate > 0
                else "")
        return (" + ".join(parts) or "none (the motor gives no force)") + rate

    def to_dict(self) -> dict[str, Any]:
        """Return the parameters as a plain ``dict`` (a block only when present)."""
        record = {field.name: getattr(self, field.name) for field in dataclasses.fields(self)
                  if not field.metadata.get("block")}
        for name in BLOCKS:
            block = getattr(self, name)
            if block is not None:
                record[name] = dataclasses.asdict(block)
        return record

    def __add__(self, other):
        return _add(self, other)


#: Today's controller, the default: PI position loop plus active damping (the same class).
PIDamping = ControllerParameters

#: The class of each block: field name of :class:`ControllerParameters` -> block class.
BLOCK_CLASSES = {"compensation": FrictionCompensation, "dither": Dither,
                 "linear": LinearController}
_SLOT = {cls: name for name, cls in BLOCK_CLASSES.items()}


def _add(left, right):
    """``left + right`` of a controller and a block, or two blocks (docs/model.md §5)."""
    if isinstance(right, ControllerParameters) and not isinstance(left, ControllerParameters):
        left, right = right, left
    if not isinstance(left, ControllerParameters):
        raise ParameterError(
            f"a {type(left).__name__} adds to a controller, not to a "
            f"{type(right).__name__}; start from PIDamping(): PIDamping() + "
            f"{type(left).__name__}(...) (PIDamping(pi_kp=0, pi_ki=0) for no position loop).")
    slot = _SLOT.get(type(right))
    if slot is None:
        return NotImplemented
    if getattr(left, slot) is not None:
        raise ParameterError(f"the controller already has a `{slot}` block; a controller "
                             f"holds one of each (combine linear loops into one system with "
                             "control.parallel).", (slot,))
    return dataclasses.replace(left, **{slot: right})


def refuse_blocks(controller: Any, what: str, fix: str, argument: str = "controller") -> None:
    """Refuse a controller with blocks where only PI + damping is modelled.

    Parameters
    ----------
    controller : ControllerParameters or sequence of them
        The controller(s).
    what : str
        What models PI + damping alone (``"the harmonic balance"``).
    fix : str
        What to do instead.
    argument : str
        How the caller names the controller.

    Raises
    ------
    ParameterError
        A controller with blocks.
    """
    for one in (controller if isinstance(controller, (list, tuple)) else (controller,)):
        if isinstance(one, ControllerParameters) and one.has_blocks:
            raise ParameterError(
                f"{what} models PI + damping alone; `{argument}` has blocks beyond them "
                f"({one.describe()}); {fix}.", (argument,))


def block_parameters(controller: ControllerParameters) -> dict[str, tuple[Any, str]]:
    """The parameters of a controller's blocks with their units: ``{"block.name": (value, unit)}``.

    Scalars as they are; a linear controller's matrices flattened row by row (their shapes
    are its ``states`` and the count of its ``inputs``), its inputs joined by spaces; an
    unset compensation level is the plant's (``None``). Empty without blocks.

    Parameters
    ----------
    controller : ControllerParameters
        The controller.

    Returns
    -------
    dict of str to (object, str)
    """
    meta: dict[str, tuple[Any, str]] = {}
    for name in BLOCKS:
        block = getattr(controller, name, None)
        if block is None:
            continue
        for field in dataclasses.fields(block):
            value = getattr(block, field.name)
            if field.name in ("a", "b", "c", "d"):
                value = [float(x) for x in np.ravel(np.array(value, dtype=float))]
            elif field.name == "inputs":
                value = " ".join(value)
            meta[f"{name}.{field.name}"] = (value, field.metadata.get("unit", ""))
        if name == "linear":
            meta["linear.states"] = (block.states, "1")
    return meta


def closed_loop_natural_frequency(isolator: IsolatorParameters | None = None,
                                  controller: "ControllerParameters | None" = None,
                                  relative_position: float | None = None) -> float:
    """Undamped natural frequency [Hz] of the payload with the PI loop closed.

    ``sqrt((k_spring(z) + Kp)/m) / (2*pi)`` with ``k_spring`` the MagSpring's
    tangent stiffness at ``relative_position`` (default: the setpoint). The
    integral and damping terms shift it only slightly; the full linearised
    model is :func:`qzs.analysis.linear.linearize`.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Controller parameters; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default ``controller.position_setpoint``.

    Returns
    -------
    float
        Natural frequency [Hz].
    """
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    z = controller.position_setpoint if relative_position is None else relative_position
    stiffness = float(spring_stiffness(z, isolator)) + controller.pi_kp
    return float(np.sqrt(stiffness / isolator.mass) / (2 * np.pi))
