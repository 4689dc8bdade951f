"""The isolator plant: parameters and force laws (docs/model.md §2-3, paper eqs. 1-3).

Coordinates (docs/model.md §1): ``y`` base position, ``x`` payload position, ``z = x - y``
relative position (encoder), ``v = xd - yd`` relative (slip) velocity; upward positive.

    m * xdd = F_spring(z) + F_friction(v) + F_stop(z, v) + F_motor - m * g
"""
import dataclasses
from dataclasses import dataclass
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from qzs._validation import (choice, non_negative_real, optional, parameter, positive_real, real,
                             validate_fields)
from qzs.errors import ParameterError
from qzs.model.springs import SpringLaw, TanhSpring

__all__ = [
    "IsolatorParameters",
    "InitialState",
    "STOP_MODELS",
    "spring_force",
    "spring_stiffness",
    "spring_energy",
    "friction_level",
    "friction_force",
    "friction_slope",
    "passive_natural_frequency",
    "refuse_spring_law",
    "other_spring_law",
]

#: Hard-stop contact models: a stiff spring-damper, or a perfectly plastic stop.
STOP_MODELS = ("compliant", "plastic")
#: Share of the plateau force ``a`` the spring may fall short of inside its constant-force
#: region [-] (docs/model.md §3).
CONSTANT_FORCE_TOLERANCE = 0.01


@dataclass(frozen=True, kw_only=True)
class IsolatorParameters:
    """Physical parameters of the single-axis isolator (docs/model.md §11, paper Table 1).

    Parameters
    ----------
    mass : float
        Moving mass of the payload and all moving parts, m [kg]. Default 6.4.
    gravity : float
        Gravitational acceleration, g [m/s^2]; 0 for a horizontal or bench-top set-up.
    spring_force : float
        MagSpring constant-force amplitude, a [N] (eq. 2, ``F = -a*tanh(b*z)``).
    spring_shape : float
        MagSpring transition coefficient, b [1/m]. A tiny value makes the spring
        linear with stiffness ``a*b`` over the stroke.
    stiction_force : float
        Breakaway (static) friction force, Fs [N]; must be >= ``coulomb_force``.
    coulomb_force : float
        Coulomb (kinetic) friction force, Fc [N].
    stribeck_decay : float
        Decay rate from stiction to Coulomb friction, Cbc [s/m].
    viscous_damping : float
        Viscous friction coefficient, Cv [N*s/m].
    friction_regularisation : float
        Regularisation velocity of the friction law, v_reg [m/s]; 0 (default) is the
        exact stick-slip model. A positive value replaces it, for comparisons with
        solvers that cannot handle stick-slip events, by the smooth law
        ``-[Fc + (Fs - Fc)*exp(-Cbc*|v|)]*tanh(v/v_reg) - Cv*v``: the payload never
        locks (no stick events) and slips at a small speed where the exact model
        sticks. Needs the compliant stops (docs/model.md §3).
    stroke_half : float
        Half the guide's stroke: the stops are at ``stop_center +- stroke_half`` [m].
    stop_center : float or None
        Centre of the stroke in relative position z [m]; ``None`` (default) centres
        the stops on the controller's position setpoint.
    stop_stiffness : float
        Contact stiffness of the compliant hard stop [N/m].
    stop_damping : float
        Contact damping of the compliant hard stop [N*s/m].
    stop_model : {"compliant", "plastic"}
        Hard-stop model [-]: compliant spring-damper contact, or a perfectly plastic
        stop that absorbs the relative velocity on impact and holds the payload at the limit.
    motor_force_max : float
        Motor force saturation [N] (LinMot PS01-23x80: 44 N).
    spring : SpringLaw or None
        The spring law (docs/model.md §3.1): None (default) is the MagSpring's tanh of
        ``spring_force`` and ``spring_shape``; a :class:`~qzs.model.springs.TanhSpring` sets
        those two fields (left at their defaults, or equal to its own); another law
        (:class:`~qzs.model.springs.ObliqueSpringQZS`,
        :class:`~qzs.model.springs.PolynomialSpring`,
        :class:`~qzs.model.springs.TabulatedSpring`) replaces the tanh in the run.
    """

    mass: float = parameter(6.4, "kg", "moving mass m")
    gravity: float = parameter(9.81, "m/s^2", "gravitational acceleration g")
    spring_force: float = parameter(60.84, "N", "MagSpring force amplitude a")
    spring_shape: float = parameter(78.10, "1/m", "MagSpring shape coefficient b")
    stiction_force: float = parameter(10.0, "N", "stiction (breakaway) force Fs")
    coulomb_force: float = parameter(1.0, "N", "Coulomb friction force Fc")
    stribeck_decay: float = parameter(100.0, "s/m", "Stribeck decay coefficient Cbc")
    viscous_damping: float = parameter(100.0, "N*s/m", "viscous friction coefficient Cv")
    friction_regularisation: float = parameter(
        0.0, "m/s", "friction regularisation velocity v_reg (0: exact stick-slip)")
    stroke_half: float = parameter(0.080, "m", "half stroke of the linear guide")
    stop_center: float | None = parameter(None, "m", "centre of the stops in z (None: the setpoint)")
    stop_stiffness: float = parameter(1e6, "N/m", "hard-stop contact stiffness")
    stop_damping: float = parameter(1e3, "N*s/m", "hard-stop contact damping")
    stop_model: str = parameter("compliant", "-", "hard-stop model: compliant or plastic")
    motor_force_max: float = parameter(44.0, "N", "motor force saturation")
    # a value of its own (its parameters are no registry parameters, as a controller's blocks)
    spring: SpringLaw | None = dataclasses.field(default=None, metadata={
        "block": True, "unit": "-",
        "doc": "spring law (None: the MagSpring's tanh of spring_force, spring_shape)"})

    def __post_init__(self):
        validate_fields(self, {
            "mass": positive_real,
            "gravity": non_negative_real,
            "spring_force": non_negative_real,
            "spring_shape": positive_real,
            "stiction_force": non_negative_real,
            "coulomb_force": non_negative_real,
            "stribeck_decay": non_negative_real,
            "viscous_damping": non_negative_real,
            "friction_regularisation": non_negative_real,
            "stroke_half": positive_real,
            "stop_center": optional(real),
            "stop_stiffness": positive_real,
            "stop_damping": non_negative_real,
            "stop_model": lambda n, v: choice(n, v, STOP_MODELS),
            "motor_force_max": non_negative_real,
        })
        self._check_spring()
        if self.coulomb_force > self.stiction_force:
            raise ParameterError(
                f"`stiction_force` ({self.stiction_force!r} N) must be >= `coulomb_force` "
                f"({self.coulomb_force!r} N): the breakaway force cannot be below the sliding "
                "friction. Set both equal for friction without a Stribeck peak, or both 0 "
                "for a frictionless guide."
            )
        if self.friction_regularisation > 0.0 and self.stop_model == "plastic":
            raise ParameterError(
                f"`friction_regularisation` ({self.friction_regularisation!r} m/s) needs "
                "`stop_model='compliant'`: a plastic stop holds the payload at rest, which "
                "the regularised friction model has no state for. Use the compliant stops, "
                "or `friction_regularisation=0` (exact stick-slip)."
            )

    def _check_spring(self):
        """``spring`` a law or None; a TanhSpring's numbers are the fields' (set or agreeing)."""
        law = self.spring
        if law is None:
            return
        if not isinstance(law, SpringLaw):
            raise ParameterError(
                f"`spring` must be a spring law (TanhSpring, ObliqueSpringQZS, "
                f"PolynomialSpring, TabulatedSpring) or None for the MagSpring of "
                f"`spring_force` and `spring_shape`, got {law!r}.", ("spring",))
        if not isinstance(law, TanhSpring):
            return
        defaults = {f.name: f.default for f in dataclasses.fields(self)}
        for name, value in (("spring_force", law.plateau), ("spring_shape", law.shape)):
            given = getattr(self, name)
            if given != value and given != defaults[name]:
                raise ParameterError(
                    f"`spring` ({law.describe()}) and `{name}` ({given!r}) disagree: a "
                    f"TanhSpring sets `{name}` to {value!r}; give the tanh's numbers once, "
                    "in the law or in the fields.", ("spring", name))
            object.__setattr__(self, name, value)

    @property
    def spring_law(self) -> SpringLaw:
        """The run's spring law: ``spring``, or the MagSpring's tanh of the fields."""
        if self.spring is not None:
            return self.spring
        return TanhSpring(plateau=self.spring_force, shape=self.spring_shape)

    @property
    def weight_deficit(self) -> float:
        """``m*g - a`` [N]: how much of the weight the spring's plateau cannot carry."""
        return self.mass * self.gravity - self.spring_force

    @property
    def constant_force_edge(self) -> float:
        """Edge of the spring's constant-force region [m]: ``z`` below it is compressed so far
        that ``|F_spring| >= 0.99 a`` (docs/model.md §3); ``-atanh(0.99)/b``."""
        return -float(np.arctanh(1.0 - CONSTANT_FORCE_TOLERANCE)) / self.spring_shape

    def to_dict(self) -> dict[str, Any]:
        """Return the parameters as a plain ``dict`` (``None`` values omitted; a spring law
        as :meth:`~qzs.model.springs.SpringLaw.to_dict`'s ``{"law": kind, ...}``)."""
        data = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        if self.spring is not None:
            data["spring"] = self.spring.to_dict()
        return {k: v for k, v in data.items() if v is not None}


@dataclass(frozen=True, kw_only=True)
class InitialState:
    """Initial state of a run.

    Parameters
    ----------
    relative_position : float or None
        z(0) [m]; ``None`` (default) starts at the position setpoint.
    relative_velocity : float
        v(0) [m/s]; default 0 (moving with the base).
    locked : bool or None
        Start stuck to the base (True) or slipping (False); ``None`` (default)
        decides from the forces: stuck if friction can hold the payload.
    pi_integral : float or None
        Initial value of the PI integral of the position error [m*s]; ``None``
        (default) preloads it so that the motor holds the payload at rest
        (bumpless start); it stays 0 when ``pi_ki`` is 0.
    """

    relative_position: float | None = None
    relative_velocity: float = 0.0
    locked: bool | None = None
    pi_integral: float | None = None

    def __post_init__(self):
        validate_fields(self, {
            "relative_position": optional(real),
            "relative_velocity": real,
            "pi_integral": optional(real),
        })
        if self.locked is not None and not isinstance(self.locked, (bool, np.bool_)):
            raise ParameterError(f"`locked` must be True, False or None, got {self.locked!r}.")
        if self.locked and self.relative_velocity != 0.0:
            raise ParameterError(
                "`relative_velocity` must be 0 when `locked` is True (a stuck payload moves "
                f"with the base), got {self.relative_velocity!r} m/s."
            )


@overload
def spring_force(relative_position: float, params: "IsolatorParameters") -> float: ...
@overload
def spring_force(relative_position: ArrayLike,
                 params: "IsolatorParameters") -> float | NDArray[np.float64]: ...


def spring_force(relative_position: ArrayLike,
                 params: "IsolatorParameters") -> float | NDArray[np.float64]:
    """Spring force [N] at relative position ``z`` [m]: the MagSpring's ``-a*tanh(b*z)``
    (eq. 2), or the isolator's own law (``spring``, docs/model.md §3.1).

    Parameters
    ----------
    relative_position : float or array_like
        Relative position z [m].
    params : IsolatorParameters
        Supplies ``spring_force`` (a) and ``spring_shape`` (b), or its ``spring`` law.

    Returns
    -------
    float or ndarray
        Spring force on the payload [N].
    """
    law = other_spring_law(params)
    if law is not None:
        return law.force(relative_position)
    z = np.asarray(relative_position, dtype=float)
    return -params.spring_force * np.tanh(params.spring_shape * z)


def other_spring_law(params):
    """``params``' spring law when it is not the MagSpring's tanh, else None.

    The tanh (``spring`` None or a :class:`~qzs.model.springs.TanhSpring`) is evaluated
    from ``spring_force`` and ``spring_shape``, bit for bit as before laws; a model without
    a ``spring`` law (a smooth model's copy of the fields) has the tanh.

    Parameters
    ----------
    params : IsolatorParameters or any object with the spring fields
        The plant.

    Returns
    -------
    SpringLaw or None
        The law other than the tanh, or None.
    """
    law = getattr(params, "spring", None)
    if isinstance(law, SpringLaw) and not isinstance(law, TanhSpring):
        return law
    return None


def refuse_spring_law(isolator, what, where="",
                      fix="simulate one axis with this law (qzs.simulate)"):
    """Refuse a spring law other than the tanh where only the tanh is evaluated yet.

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant.
    what : str
        What evaluates the tanh only (``"the hexapod"``, ``"the C model"``), for the message.
    where : str
        A prefix naming the part (``"leg 6: "``).
    fix : str
        The way out, after "give spring=None or a TanhSpring, or".

    Raises
    ------
    ParameterError
        ``spring`` neither None nor a TanhSpring, naming the fix.
    """
    law = other_spring_law(isolator)
    if law is not None:
        raise ParameterError(
            f"{where}`spring` ({law.describe()}) is not supported by {what} yet: it evaluates "
            "the MagSpring's tanh of `spring_force` and `spring_shape` only (docs/model.md "
            f"§3.1); give spring=None or a TanhSpring, or {fix}.", ("spring",))


@overload
def spring_stiffness(relative_position: float, params: "IsolatorParameters") -> float: ...
@overload
def spring_stiffness(relative_position: ArrayLike,
                     params: "IsolatorParameters") -> float | NDArray[np.float64]: ...


def spring_stiffness(relative_position: ArrayLike,
                     params: "IsolatorParameters") -> float | NDArray[np.float64]:
    """Tangent stiffness ``-dF/dz`` [N/m] at ``z`` [m]: the MagSpring's ``a*b/cosh(b*z)^2``,
    or the isolator's own law's (``spring``, docs/model.md §3.1).

    Parameters
    ----------
    relative_position : float or array_like
        Relative position z [m].
    params : IsolatorParameters
        Supplies ``spring_force`` (a) and ``spring_shape`` (b), or its ``spring`` law.

    Returns
    -------
    float or ndarray
        Tangent stiffness [N/m], positive restoring.
    """
    law = other_spring_law(params)
    if law is not None:
        return law.stiffness(relative_position)
    z = np.asarray(relative_position, dtype=float)
    return params.spring_force * params.spring_shape / np.cosh(params.spring_shape * z) ** 2


def spring_energy(relative_position, params):
    """Potential energy [J] stored in the spring: the MagSpring's ``(a/b)*ln(cosh(b*z))``,
    0 at z = 0, or the isolator's own law's (``spring``, zero at the law's reference
    position, docs/model.md §3.1).

    Parameters
    ----------
    relative_position : float or array_like
        Relative position z [m].
    params : IsolatorParameters
        Supplies ``spring_force`` (a) and ``spring_shape`` (b), or its ``spring`` law.

    Returns
    -------
    float or ndarray
        Stored energy [J].
    """
    law = other_spring_law(params)
    if law is not None:
        return law.energy(relative_position)
    u = np.abs(params.spring_shape * np.asarray(relative_position, dtype=float))
    return params.spring_force / params.spring_shape * (u + np.log1p(np.exp(-2 * u)) - np.log(2))


def friction_level(relative_velocity, params):
    """Dry-friction level ``Fc + (Fs - Fc)*exp(-Cbc*|v|)`` [N] at slip velocity ``v`` [m/s] (eq. 3).

    The size of the friction force before its direction and the viscous part: Fs at rest,
    decaying to Fc (the Stribeck curve).

    Parameters
    ----------
    relative_velocity : float or array_like
        Relative (slip) velocity v [m/s].
    params : IsolatorParameters
        Supplies ``stiction_force``, ``coulomb_force`` and ``stribeck_decay``.

    Returns
    -------
    float or ndarray
        Dry-friction level [N], between Fc and Fs.
    """
    return _friction_level(np.asarray(relative_velocity, dtype=float), params)[0]


@overload
def friction_force(relative_velocity: float, params: "IsolatorParameters") -> float: ...
@overload
def friction_force(relative_velocity: ArrayLike,
                   params: "IsolatorParameters") -> float | NDArray[np.float64]: ...


def friction_force(relative_velocity: ArrayLike,
                   params: "IsolatorParameters") -> float | NDArray[np.float64]:
    """Sliding friction [N] at slip velocity ``v`` [m/s] (eq. 3, signs of docs/model.md §3).

    ``-[Fc + (Fs - Fc)*exp(-Cbc*|v|)]*sign(v) - Cv*v``: it always opposes slip.
    At ``v = 0`` it returns 0; the stuck state is handled by the simulator. With
    ``friction_regularisation`` v_reg > 0, ``tanh(v/v_reg)`` takes the place of
    ``sign(v)`` (the regularised model, docs/model.md §3).

    Parameters
    ----------
    relative_velocity : float or array_like
        Relative (slip) velocity v [m/s].
    params : IsolatorParameters
        Supplies the friction parameters (``stiction_force``, ``coulomb_force``,
        ``stribeck_decay``, ``viscous_damping``, ``friction_regularisation``).

    Returns
    -------
    float or ndarray
        Friction force on the payload [N].
    """
    v = np.asarray(relative_velocity, dtype=float)
    level = _friction_level(v, params)[0]
    return -level * _slip_direction(v, params) - params.viscous_damping * v


def friction_slope(relative_velocity, params):
    """Slope ``dF/dv`` [N*s/m] of :func:`friction_force` at slip velocity ``v`` [m/s].

    ``(Fs - Fc)*Cbc*exp(-Cbc*|v|)*|d| - level*d'(v) - Cv`` with ``d`` the direction
    (``sign(v)``, or ``tanh(v/v_reg)`` with regularisation) and ``d'`` its derivative:
    ``(1 - tanh^2)/v_reg`` regularised, 0 otherwise (the exact law's jump at ``v = 0`` is
    left out: there the slope is ``-Cv``). Regularised, the slope is continuous: the kink of
    ``|v|`` is multiplied by ``tanh(0) = 0``.

    Parameters
    ----------
    relative_velocity : float or array_like
        Relative (slip) velocity v [m/s].
    params : IsolatorParameters
        Supplies the friction parameters, as for :func:`friction_force`.

    Returns
    -------
    float or ndarray
        Slope of the friction force [N*s/m].
    """
    v = np.asarray(relative_velocity, dtype=float)
    p = params
    level, decay = _friction_level(v, p)
    direction = _slip_direction(v, p)
    slope = (p.stiction_force - p.coulomb_force) * p.stribeck_decay * decay * np.abs(direction)
    if p.friction_regularisation > 0.0:
        slope = slope - level * (1 - direction * direction) / p.friction_regularisation
    return slope - p.viscous_damping


def _friction_level(v, p):
    """``(level, decay)``: the dry-friction level [N] and ``exp(-Cbc*|v|)`` [-] at ``v`` [m/s]."""
    decay = np.exp(-p.stribeck_decay * np.abs(v))
    return p.coulomb_force + (p.stiction_force - p.coulomb_force) * decay, decay


def _slip_direction(v, p):
    """``sign(v)``, or ``tanh(v/v_reg)`` with a regularisation velocity v_reg > 0 [-]."""
    if p.friction_regularisation > 0.0:
        return np.tanh(v / p.friction_regularisation)
    return np.sign(v)


def passive_natural_frequency(params: "IsolatorParameters", relative_position: float) -> float:
    """Natural frequency [Hz] of the payload on the MagSpring alone, linearised at ``z`` [m].

    ``sqrt(k/m)/(2*pi)`` with ``k`` the tangent stiffness; about 0.08 Hz at the
    default operating point ``z = -0.060 m`` (paper, Section 3.1).

    Parameters
    ----------
    params : IsolatorParameters
        Supplies the MagSpring and the ``mass``.
    relative_position : float
        Operating point z [m].

    Returns
    -------
    float
        Natural frequency [Hz].
    """
    return float(np.sqrt(spring_stiffness(relative_position, params) / params.mass) / (2 * np.pi))
