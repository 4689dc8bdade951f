"""Hunting at rest of a whole population at once: the stick-slip relay solved directly.

:func:`qzs.analysis.control_design.hunting.predict_hunting` asks python-control's
``describing_function_response`` for the intersection of the relay's ``-1/N`` with the
integral loop's Nyquist curve, one design at a time: a search over every pair of segments
of the two curves, each candidate refined by ``scipy.optimize.minimize``. For the relay with
hysteresis (output ``+-d``, switching at ``+-h``) the locus is a horizontal half-line,

    -1/N(A) = -(pi/(4 d)) * (sqrt(A^2 - h^2) + j h),       A >= h,

so an intersection is a frequency where ``Im G(jw) = -pi h/(4 d)`` (a root search in ``w``,
bracketed on python-control's own frequency grid and refined by bisection, every design of
the population at once with numpy) at which ``Re G(jw) <= 0``; its amplitude follows in
closed form, ``A = sqrt(h^2 + (4 d Re G(jw)/pi)^2)``. The verdicts are those of the scalar
path: an intersection counts only inside the grids the scalar path hands python-control
(frequencies ``1e-5..1e3`` rad/s, amplitudes up to ``h + 20 (h + 2 d)``), and the first one is
the one of least amplitude. The slip jump ``J`` (:func:`slip_jumps`) integrates the same slip
equations as :func:`~qzs.analysis.control_design.hunting.slip_jump` for every design side
by side (scipy's RK45 tableau and step control, a step of each design's own, the stop
located on the step's dense output), instead of one LSODA integration per design.

Agreement with the scalar path (tests, on a table spanning the shipped problem's bounds): the
same "no cycle" verdicts; the slip jump and the plateau ``d/K`` within 1e-6 relative (1e-6
of ``Fs`` where the jump is a small difference; a tight reference integration is closer to
these than to the scalar path's LSODA). The intersection solves ``1 + G N = 0`` to round-off;
the scalar path's, refined by ``minimize`` at its default tolerance, lies within about 1e-4.
"""
from dataclasses import dataclass

import numpy as np

from qzs.analysis.control_design.hunting import (RELAY_AMPLITUDE_SPAN, RELAY_FREQUENCIES,
                                                 SLIP_JUMP_FLOOR, _slip)
from qzs.analysis.linear import loop_constants
from qzs.errors import ParameterError
from qzs.model.registry import model_inputs

__all__ = ["PopulationHunting", "predict_hunting_population", "slip_jumps",
           "population_constants"]

#: Relative tolerance of the slip integration, per lane (the scalar path's LSODA: 1e-8) [-].
_SLIP_RTOL = 1e-8
#: Bisection steps refining an intersection's frequency in ``log(w)`` (to round-off) [-].
_BISECTIONS = 64
#: Steps side by side after which the designs still slipping are taken for stiff: each is
#: then integrated alone by the scalar path's LSODA [-].
_MAX_STEPS = 2000
#: Stiffness ratio ``(Cv + Kd)^2/(m K)`` (the creep's time scale over the damping's) above
#: which a design goes to the scalar path's LSODA at once (shipped problem: at most 3400) [-].
_STIFF = 2e4
#: scipy's step control (scipy.integrate._ivp.rk): safety factor, least and largest change.
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0


def population_constants(isolators, controllers, relative_position=None):
    """The loop constants and friction of a population, one array per quantity.

    Parameters
    ----------
    isolators : sequence of IsolatorParameters
        Plant parameters per design.
    controllers : sequence of ControllerParameters
        PI and damping loops per design, as many as ``isolators``.
    relative_position : float, optional
        Operating point z [m]; default each controller's setpoint.

    Returns
    -------
    dict of str to ndarray, shape (n,)
        ``mass`` [kg], ``viscous_damping`` [N*s/m], ``spring_stiffness`` [N/m], ``pi_kp``
        [N/m], ``pi_ki`` [N/(m*s)], ``damping_gain`` [N*s/m], ``highpass`` [rad/s],
        ``stiction_force``, ``coulomb_force`` [N], ``stribeck_decay`` [s/m] and
        ``controller_rate`` [Hz].

    Raises
    ------
    ParameterError
        The two sequences differ in length.
    """
    isolators, controllers = list(isolators), list(controllers)
    if len(isolators) != len(controllers):
        raise ParameterError(f"`isolators` has {len(isolators)} entries and `controllers` "
                             f"{len(controllers)}: give one controller per isolator.")
    names = ("mass", "viscous_damping", "spring_stiffness", "pi_kp", "pi_ki",
             "damping_gain", "highpass")
    rows = []
    for isolator, controller in zip(isolators, controllers):
        isolator, controller = model_inputs(isolator, controller)
        if controller.has_blocks:
            raise ParameterError(
                "`controllers` holds a controller with blocks: a population's closed forms "
                "are PI + damping's; analyse it alone (loop_stability, loop_margins, "
                "predict_hunting).", ("controllers",))
        rows.append((*loop_constants(isolator, controller, relative_position),
                     isolator.stiction_force, isolator.coulomb_force,
                     isolator.stribeck_decay, controller.controller_rate))
    table = np.array(rows, dtype=float).reshape(len(rows), len(names) + 4)
    names += ("stiction_force", "coulomb_force", "stribeck_decay", "controller_rate")
    return {name: table[:, i].copy() for i, name in enumerate(names)}


@dataclass(frozen=True, kw_only=True)
class PopulationHunting:
    """The stick-slip relay's prediction for every design of a population.

    The fields of :class:`~qzs.analysis.control_design.hunting.HuntingPrediction` that
    concern the relay, one entry per design (the memoryless friction law's intersections,
    the re-stick level and the reasons are the scalar path's alone).

    Attributes
    ----------
    slip_jump : ndarray
        ``J`` [N] (0: no slip).
    relay_output : ndarray
        ``d = J/2`` [N].
    switching_force : ndarray
        ``h = Fs - d`` [N].
    stiffness : ndarray
        ``K = k + Kp`` [N/m].
    hunts : ndarray of bool
        The relay's ``-1/N`` meets the integral loop's Nyquist curve.
    integral_force_amplitude : ndarray
        Amplitude of the integral force at the intersection [N] (NaN if none).
    frequency : ndarray
        Predicted hunting frequency [Hz] (NaN if none).
    period : ndarray
        ``1/frequency`` [s] (NaN if none).
    amplitude : ndarray
        Plateau ``d/K`` [m] (NaN without a slip jump).
    first_harmonic_amplitude : ndarray
        First harmonic of the position at the intersection [m] (NaN if none).
    relay_period : ndarray
        ``4*h*K/(Ki*d)`` [s] (NaN without integral, slip jump or stiffness).
    in_regime : ndarray of bool
        The intersection's amplitude is below ``h + 2*d``.
    """

    slip_jump: np.ndarray
    relay_output: np.ndarray
    switching_force: np.ndarray
    stiffness: np.ndarray
    hunts: np.ndarray
    integral_force_amplitude: np.ndarray
    frequency: np.ndarray
    period: np.ndarray
    amplitude: np.ndarray
    first_harmonic_amplitude: np.ndarray
    relay_period: np.ndarray
    in_regime: np.ndarray

    @property
    def hunting_amplitude(self):
        """The design space's metric: the plateau where the loop hunts, else 0 [m]."""
        return np.where(self.hunts, self.amplitude, 0.0)


def _slip_rates(y, out, m, cv, k_total, kd, w, fs, fc, cbc):
    """Rates of the slip equations into ``out``, rows ``(v, F, lagged)``, shape (3, n)."""
    v, force, lagged = y
    friction = fc + (fs - fc) * np.exp(-cbc * np.maximum(v, 0.0))
    out[0] = (force - friction - cv * v - kd * (v - lagged)) / m
    out[1] = -k_total * v
    out[2] = w * (v - lagged)
    return out


def _integrate_slips(lanes, constants, jump, duration):
    """Integrate the slips of ``lanes`` side by side; fill ``jump`` and ``duration`` in place.

    scipy's RK45 (Dormand-Prince 5(4): its tableau ``RK45.A, B, C, E`` and dense output
    ``RK45.P``, its step control) with a step of each lane's own, all lanes advanced by one
    numpy evaluation per stage. A lane stops where ``v + 1e-15`` falls through 0 (the
    scalar path's event), located on the step's dense output by bisection; it leaves the
    integration then, or when it passes its horizon without stopping (no jump). Lanes still
    slipping after :data:`_MAX_STEPS` steps are stiff for an explicit method: the scalar
    path's LSODA integrates each of them.
    """
    from scipy.integrate import RK45

    a_matrix, b, e, p = RK45.A, RK45.B, RK45.E, RK45.P
    exponent = -1.0 / (RK45.error_estimator_order + 1)
    c = {name: value[lanes] for name, value in constants.items()}
    floor_cv = np.maximum(c["viscous_damping"], 1e-9)
    w = c["highpass"]
    horizon = np.minimum(40 * (c["mass"] / floor_cv + floor_cv / c["k_total"]
                               + np.where(w > 0, 1 / np.where(w > 0, w, 1.0), 0.0)), 1e4)
    fs = c["stiction_force"]
    params = np.vstack((c["mass"], c["viscous_damping"], c["k_total"], c["damping_gain"],
                        w, fs, c["coulomb_force"], c["stribeck_decay"]))
    atol = np.vstack((np.full(lanes.size, 1e-12), 1e-9 * np.maximum(fs, 1.0),
                      np.full(lanes.size, 1e-12)))
    y = np.vstack((np.zeros(lanes.size), fs * (1 + 1e-6), np.zeros(lanes.size)))
    t = np.zeros(lanes.size)
    # a first step well inside the fastest time scale, m/(Cv + Kd); the control grows it
    h = 1e-4 * c["mass"] / (floor_cv + c["damping_gain"])
    rejected = np.zeros(lanes.size, dtype=bool)
    f = _slip_rates(y, np.empty_like(y), *params)
    ids = lanes.copy()  # the working arrays hold the lanes still slipping, compacted
    stops = []
    stages = np.empty((b.size + 1, 3, lanes.size))
    with np.errstate(divide="ignore"):
        for _ in range(_MAX_STEPS):
            if not ids.size:
                break
            step = np.minimum(h, horizon - t)
            stages[0, :, :ids.size] = f
            for k in range(1, b.size):
                increment = a_matrix[k, 0] * stages[0, :, :ids.size]
                for j in range(1, k):
                    increment += a_matrix[k, j] * stages[j, :, :ids.size]
                _slip_rates(y + step * increment, stages[k, :, :ids.size], *params)
            total = b[0] * stages[0, :, :ids.size]
            for j in range(1, b.size):
                total += b[j] * stages[j, :, :ids.size]
            y1 = y + step * total
            f1 = _slip_rates(y1, stages[b.size, :, :ids.size], *params)
            error = e[0] * stages[0, :, :ids.size]
            for j in range(1, b.size + 1):
                error += e[j] * stages[j, :, :ids.size]
            scale = atol + np.maximum(np.abs(y), np.abs(y1)) * _SLIP_RTOL
            norm = np.sqrt(np.mean((step * error / scale) ** 2, axis=0))
            accept = norm < 1
            factor = _SAFETY * norm ** exponent
            grow = np.where(norm == 0, _MAX_FACTOR, np.minimum(_MAX_FACTOR, factor))
            grow = np.where(rejected, np.minimum(1.0, grow), grow)
            h = step * np.where(accept, grow, np.maximum(_MIN_FACTOR, factor))
            rejected = ~accept
            crossed = accept & (y[0] + 1e-15 >= 0) & (y1[0] + 1e-15 <= 0)
            done = crossed | (accept & (t + step >= horizon))
            done |= step < 10 * np.spacing(np.maximum(t, 1.0))  # stuck: no stop
            if crossed.any():  # the stop's step, kept: every stop located at the end
                i = np.flatnonzero(crossed)
                stops.append((ids[i], t[i], step[i], y[:2, i], np.einsum(
                    "snk,sj->nkj", stages[:, :2, :ids.size][:, :, i], p)))  # (2, k, 4)
            y = np.where(accept, y1, y)
            f = np.where(accept, f1, f)
            t = np.where(accept, t + step, t)
            if done.any():
                keep = ~done
                ids, y, f, t, h, rejected = (ids[keep], y[:, keep], f[:, keep], t[keep],
                                             h[keep], rejected[keep])
                params, atol, horizon = params[:, keep], atol[:, keep], horizon[keep]
    for lane in ids:  # stiff after all: the scalar path's integration
        jump[lane], duration[lane] = _scalar_slip(constants, lane)
    if stops:
        lane, t0, step = (np.concatenate(x) for x in list(zip(*stops))[:3])
        start = np.concatenate([x[3] for x in stops], axis=1)
        dense = np.concatenate([x[4] for x in stops], axis=1)
        when = _dense_root(start[0], step, dense[0])
        force = start[1] + step * _powers(dense[1], when)
        jump[lane] = np.maximum(0.0, constants["stiction_force"][lane] - force)
        duration[lane] = t0 + when * step


def _scalar_slip(constants, lane):
    """The scalar path's slip (LSODA, implicit where stiff) of one lane: (jump, duration)."""
    return _slip(*(float(constants[name][lane]) for name in (
        "mass", "viscous_damping", "k_total", "damping_gain", "highpass", "stiction_force",
        "coulomb_force", "stribeck_decay")))


def _powers(coefficients, share):
    """``sum_j coefficients[:, j] * share**(j + 1)`` (Horner), the dense output's increment."""
    out = coefficients[:, -1] * share
    for j in range(coefficients.shape[1] - 2, -1, -1):
        out = (out + coefficients[:, j]) * share
    return out


def _dense_root(v0, step, dense_v):
    """Share of the step at which ``v + 1e-15`` falls through 0 (bisection on the dense output).

    The jump ``Fs - F`` is stationary there (``F' = -K v = 0``), so the share's last bits
    matter to second order only.
    """
    low, high = np.zeros(v0.size), np.ones(v0.size)
    for _ in range(_BISECTIONS):
        mid = 0.5 * (low + high)
        above = v0 + step * _powers(dense_v, mid) + 1e-15 > 0
        low, high = np.where(above, mid, low), np.where(above, high, mid)
    return high


def slip_jumps(isolators, controllers, relative_position=None, *, constants=None):
    """The slip jump of every design, integrated together (see the module's text).

    The same slip as :func:`~qzs.analysis.control_design.hunting.slip_jump` (from rest at
    ``F = Fs*(1 + 1e-6)``, the integral force held, until the payload stops), for all designs
    in one stacked system.

    Parameters
    ----------
    isolators : sequence of IsolatorParameters
        Plant parameters per design.
    controllers : sequence of ControllerParameters
        Loops per design.
    relative_position : float, optional
        Operating point z [m]; default each setpoint.
    constants : dict, optional
        :func:`population_constants` of these designs, if already at hand.

    Returns
    -------
    jump : ndarray
        ``Fs - F`` when the payload stops [N] (0: no slip, or a creep below
        :data:`~qzs.analysis.control_design.hunting.SLIP_JUMP_FLOOR` of ``Fs``).
    duration : ndarray
        Length of the slip [s] (NaN if it did not end within the time allowed).
    """
    if constants is None:
        constants = population_constants(isolators, controllers, relative_position)
    constants = dict(constants)
    constants["k_total"] = constants["spring_stiffness"] + constants["pi_kp"]
    fs = constants["stiction_force"]
    n = fs.size
    jump, duration = np.zeros(n), np.full(n, np.nan)
    slipping = (fs > 0) & (constants["k_total"] > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        stiffness = ((constants["viscous_damping"] + constants["damping_gain"]) ** 2
                     / (constants["mass"] * constants["k_total"]))
    lanes = np.flatnonzero(slipping & (stiffness <= _STIFF))
    if lanes.size:
        _integrate_slips(lanes, constants, jump, duration)
    for lane in np.flatnonzero(slipping & (stiffness > _STIFF)):
        jump[lane], duration[lane] = _scalar_slip(constants, lane)
    jump[jump < SLIP_JUMP_FLOOR * fs] = 0.0  # the start kick's own creep: no slip
    return jump, duration


def _integral_loop_response(c, omega):
    """``G(jw)`` of the integral loop on a grid, shape (n, len(omega))."""
    s = 1j * omega[None, :]
    w = c["highpass"][:, None]
    highpass = np.where(w > 0, s / (s + w), 1.0)
    denominator = (c["mass"][:, None] * s ** 2 + c["viscous_damping"][:, None] * s
                   + c["k_total"][:, None] + c["damping_gain"][:, None] * s * highpass)
    return c["pi_ki"][:, None] / (s * denominator)


def _relay_intersections(c, d, h):
    """Least-amplitude intersection of the relay's ``-1/N`` with ``G`` per design.

    Returns ``(amplitude [N], angular frequency [rad/s], |D(jw)|)``, NaN where none.
    """
    n = d.size
    amplitude, omega_cycle, size = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    if not n:
        return amplitude, omega_cycle, size
    omega = np.logspace(*RELAY_FREQUENCIES)
    response = _integral_loop_response(c, omega)
    level = -np.pi * h / (4 * d)
    gap = response.imag - level[:, None]
    top = h + 2 * d
    # the amplitudes the scalar path hands python-control: h*(1 + logspace(-9, log10(span)))
    amplitude_first = h * (1 + 1e-9)
    amplitudes_last = h * (1 + RELAY_AMPLITUDE_SPAN * top / h)
    real_first = -np.pi * np.sqrt(amplitude_first ** 2 - h ** 2) / (4 * d)
    real_last = -np.pi * np.sqrt(amplitudes_last ** 2 - h ** 2) / (4 * d)
    brackets = (gap[:, :-1] * gap[:, 1:] <= 0) & ~((gap[:, :-1] == 0) & (gap[:, 1:] == 0))
    # the crossing of the polyline, linearly interpolated, must lie on the -1/N polyline
    with np.errstate(divide="ignore", invalid="ignore"):
        share = gap[:, :-1] / (gap[:, :-1] - gap[:, 1:])
        real = response.real[:, :-1] + share * (response.real[:, 1:] - response.real[:, :-1])
    brackets &= (real <= real_first[:, None]) & (real >= real_last[:, None])
    design, segment = np.nonzero(brackets)
    if not design.size:
        return amplitude, omega_cycle, size
    sub = {name: value[design] for name, value in c.items()}
    low, high = np.log(omega[segment]), np.log(omega[segment + 1])
    rising = gap[design, segment] <= 0
    for _ in range(_BISECTIONS):
        mid = 0.5 * (low + high)
        g = _point_response(sub, np.exp(mid))[0].imag - level[design]
        below = (g <= 0) == rising
        low, high = np.where(below, mid, low), np.where(below, high, mid)
    root = np.exp(0.5 * (low + high))
    g, denominator = _point_response(sub, root)
    candidates = np.sqrt(h[design] ** 2 + (4 * d[design] * g.real / np.pi) ** 2)
    candidates = np.where(g.real <= 0, candidates, np.nan)
    finite = np.isfinite(candidates)
    design, candidates, root, denominator = (x[finite] for x in (design, candidates, root,
                                                                 denominator))
    order = np.lexsort((candidates, design))  # the least amplitude of each design wins
    first = np.ones(order.size, dtype=bool)
    first[1:] = design[order][1:] != design[order][:-1]
    pick = order[first]
    amplitude[design[pick]], omega_cycle[design[pick]] = candidates[pick], root[pick]
    size[design[pick]] = np.abs(denominator[pick])
    return amplitude, omega_cycle, size


def _point_response(c, omega):
    """``G(jw)`` and ``D(jw)`` at one frequency per design."""
    s = 1j * omega
    w = c["highpass"]
    highpass = np.where(w > 0, s / (s + w), 1.0)
    denominator = (c["mass"] * s ** 2 + c["viscous_damping"] * s + c["k_total"]
                   + c["damping_gain"] * s * highpass)
    return c["pi_ki"] / (s * denominator), denominator


def predict_hunting_population(isolators, controllers, relative_position=None, *,
                               constants=None):
    """The stick-slip relay's prediction for a population, vectorised (see the module).

    Parameters
    ----------
    isolators : sequence of IsolatorParameters
        Plant parameters per design.
    controllers : sequence of ControllerParameters
        PI and damping loops per design.
    relative_position : float, optional
        Operating point z [m]; default each setpoint.
    constants : dict, optional
        :func:`population_constants` of these designs, if already at hand.

    Returns
    -------
    PopulationHunting
    """
    if constants is None:
        constants = population_constants(isolators, controllers, relative_position)
    c = dict(constants)
    c["k_total"] = c["spring_stiffness"] + c["pi_kp"]
    jump, _ = slip_jumps(None, None, constants=constants)
    fs, ki, k_total = c["stiction_force"], c["pi_ki"], c["k_total"]
    d = 0.5 * jump
    h = fs - d
    n = fs.size
    may = (ki > 0) & (fs > 0) & (d > 0) & (k_total > 0)
    amplitude_u, omega, size = (np.full(n, np.nan) for _ in range(3))
    idx = np.flatnonzero(may)
    sub = {name: value[idx] for name, value in c.items()}
    amplitude_u[idx], omega[idx], size[idx] = _relay_intersections(sub, d[idx], h[idx])
    hunts = np.isfinite(amplitude_u)
    top = h + 2 * d
    frequency = omega / (2 * np.pi)
    with np.errstate(divide="ignore", invalid="ignore"):
        plateau = np.where((d > 0) & (k_total > 0), d / k_total, np.nan)
        relay_period = np.where((ki > 0) & (d > 0) & (k_total > 0),
                                4 * h * k_total / (ki * d), np.nan)
        period = np.where(hunts & (frequency > 0), 1 / frequency, np.nan)
        first = (4 * d / np.pi) / size
    return PopulationHunting(
        slip_jump=jump, relay_output=d, switching_force=h, stiffness=k_total, hunts=hunts,
        integral_force_amplitude=amplitude_u, frequency=frequency, period=period,
        amplitude=plateau, first_harmonic_amplitude=np.where(hunts, first, np.nan),
        relay_period=relay_period, in_regime=hunts & (amplitude_u < top))
