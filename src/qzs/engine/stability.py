"""Linear stability of the explicit integrators: is a step small enough? (docs/model.md §7)."""
import numpy as np

from qzs._validation import choice
from qzs.engine import kernels as K
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters, other_spring_law
from qzs.model.springs import EQUILIBRIUM_SAMPLES, TabulatedSpring

__all__ = ["SOLVERS", "largest_stable_step", "stability_test", "spring_stiffness_peak"]

#: Fixed-step integrators: name -> (kernel code, order of accuracy).
SOLVERS = {"euler": (K.SOLVER_EULER, 1), "ode3": (K.SOLVER_ODE3, 3), "rk4": (K.SOLVER_RK4, 4)}
_STABILITY_POLYNOMIALS = {  # |R(h*lambda)| <= 1 is linear stability (Taylor coefficients)
    "euler": [1, 1], "ode3": [1, 1, 1 / 2, 1 / 6], "rk4": [1, 1, 1 / 2, 1 / 6, 1 / 24]}


def spring_stiffness_peak(isolator, controller):
    """The spring's largest tangent stiffness over the stroke [N/m] (what the step must resolve).

    The MagSpring's ``a b`` (its peak, at ``z = 0``) for the tanh; for another law the
    largest of its stiffness at :data:`qzs.model.springs.EQUILIBRIUM_SAMPLES` positions over
    the stops' span (and a table's breakpoints there).

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant, its spring law.
    controller : ControllerParameters
        The controller (its setpoint centres the stops by default).

    Returns
    -------
    float
        Stiffness [N/m].
    """
    law = other_spring_law(isolator)
    if law is None:
        return isolator.spring_force * isolator.spring_shape
    center = (controller.position_setpoint if isolator.stop_center is None
              else isolator.stop_center)
    first, last = law.domain
    low = max(center - isolator.stroke_half, first)
    high = min(center + isolator.stroke_half, last)
    z = np.linspace(low, high, EQUILIBRIUM_SAMPLES)
    if isinstance(law, TabulatedSpring):
        z = np.union1d(z, law.positions[(law.positions >= low) & (law.positions <= high)])
    return float(np.max(law.stiffness(z)))


def _stiff_modes(isolator, controller):
    """Eigenvalues [1/s] of the fastest linear modes: free, and pressed on a compliant stop.

    Regularised friction adds its slope at ``v = 0``, ``Fs/v_reg`` [N*s/m], to the damping.
    """
    m = isolator.mass
    stiffness = spring_stiffness_peak(isolator, controller) + controller.pi_kp
    damping = isolator.viscous_damping + controller.damping_gain
    if controller.compensation is not None:  # its viscous part cancels damping
        compensation = controller.compensation
        damping -= compensation.fraction * compensation.law(isolator)[3]
    if isolator.friction_regularisation > 0.0:
        damping += isolator.stiction_force / isolator.friction_regularisation
    cases = [(stiffness, damping)]
    if isolator.stop_model == "compliant":
        cases.append((stiffness + isolator.stop_stiffness, damping + isolator.stop_damping))
    eigenvalues = [-2 * np.pi * controller.velocity_highpass]
    for k, c in cases:
        eigenvalues.extend(np.roots([m, c, k]))
    if controller.compensation is not None:
        eigenvalues.append(-2 * np.pi * controller.compensation.observer_bandwidth)
    linear = controller.linear
    if linear is not None and not linear.discrete and linear.states:
        a = linear.matrices()[0]  # its own modes, and how fast its anti-windup tracks
        eigenvalues.extend(np.linalg.eigvals(a))
        eigenvalues.append(-1.0 / linear.tracking_time)
    eigenvalues = np.asarray(eigenvalues, dtype=complex)
    # a growing mode (over-compensated friction, an unstable controller) grows for any step:
    # no step makes it stable, and it does not make the integration unstable
    return eigenvalues[eigenvalues.real <= 0.0]


def stability_test(isolator, controller, solver):
    """``stable(h)``: does a step ``h`` [s] keep every stiff mode's growth below 0.1 %/s?

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.

    Returns
    -------
    callable
        ``stable(h) -> bool`` for a step ``h`` [s].
    """
    choice("solver", solver, tuple(SOLVERS))
    coefficients = np.array(_STABILITY_POLYNOMIALS[solver][::-1])
    eigenvalues = _stiff_modes(isolator, controller)

    def stable(h):
        growth = np.log(np.abs(np.polyval(coefficients, h * eigenvalues)))
        return bool(np.all(growth <= 1e-3 * h))

    return stable


def largest_stable_step(isolator: IsolatorParameters | None = None,
                        controller: ControllerParameters | None = None,
                        solver: str = "ode3") -> float:
    """Largest time step [s] for which the explicit integrator stays stable.

    Linear stability of the stiffest modes (the payload on its spring, PI gain
    and dampers, and pressed against a compliant hard stop): the step ``h``
    must keep the solver's amplification ``|R(h*lambda)|`` from growing faster
    than 0.1 % per second for every eigenvalue ``lambda``.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator; default ode3.

    Returns
    -------
    float
        The largest stable step [s].
    """
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    stable = stability_test(isolator, controller, solver)
    low, high = 0.0, 1.0
    while stable(high) and high < 1e3:
        low, high = high, high * 2
    if stable(high):
        return float(high)
    for _ in range(200):  # bisection on a log scale to relative precision ~1e-6
        mid = np.sqrt(low * high) if low > 0 else high / 2
        if stable(mid):
            low = mid
        else:
            high = mid
        if low > 0 and high / low < 1 + 1e-6:
            break
    return float(low)


