"""The six-axis drivers: :func:`simulate_hexapod` (one platform) and
:func:`simulate_hexapods` (several, in threads).

Validated and packed by :mod:`qzs.engine.hexapod.prepare`, integrated in chunks by the
kernels of :mod:`qzs.engine.hexapod.stepping`, returned as a
:class:`~qzs.engine.hexapod.result.HexapodResult` (or streamed to a sink).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs import defaults
from qzs._validation import known_keys, worker_count
from qzs.engine.hexapod.layout import (CT_CONTACTS, CT_EVENTS, CT_STEP, CT_STICKS, LEG_COUNT,
                                       N_BASE_CHANNELS, N_BUF, N_CHANNELS, N_COUNTERS, N_FLAGS,
                                       N_ODE, N_WORK, S_C, S_V, STATUS_OK, STATUS_OUTSIDE,
                                       V_Z, V_ZHIGH, V_ZLOW, W_OUTSIDE)
from qzs.engine.hexapod.prepare import _prepare, has_blocks
from qzs.engine.prepare import table_exit_message
from qzs.engine.hexapod.result import HexapodResult
from qzs.engine.hexapod.statistics import _Statistics
from qzs.engine.hexapod.stepping import _run, _start
from qzs.engine import driver
from qzs.errors import CaseError, ParameterError, SimulationError

if TYPE_CHECKING:
    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.hexapod import CartesianController, HexapodGeometry, PlatformParameters
    from qzs.model.isolator import IsolatorParameters

#: Output samples per kernel call at most (the hexapod's 99 channels: 158 MB).
PREVIEW_CHUNK = 200_000

__all__ = ["simulate_hexapod", "simulate_hexapods"]


def simulate_hexapod(geometry: HexapodGeometry, platform: PlatformParameters,
                     isolator: IsolatorParameters | Sequence[IsolatorParameters] | None = None,
                     controller: ControllerParameters | Sequence[ControllerParameters]
                     | None = None, *, excitation: Mapping[str, Excitation] | None = None,
                     duration: float | None = None, dt: float = defaults.SIMULATION["dt"],
                     sample_rate: float = defaults.SIMULATION["sample_rate"],
                     solver: str = defaults.SIMULATION["solver"],
                     cartesian: CartesianController | None = None, progress: bool = False,
                     sink: Callable[[Any, Any], Any] | None = None,
                     interruptible: bool = False) -> HexapodResult:
    """Simulate a six-leg platform of isolator legs under a base moving in up to six axes.

    A rigid platform on six single-axis isolator legs (docs/hexapod.md, "Dynamics"): each
    leg's MagSpring, Stribeck friction with exact stick-slip, compliant stops and its own PI
    loop with active damping through the amplifier's high-pass, exactly the laws of
    docs/model.md §3-5; the platform by Newton-Euler with gravity; the legs' moving masses
    lumped into the platform. Every argument is checked before any integration.

    Parameters
    ----------
    geometry : HexapodGeometry
        Joints and legs' stroke (:func:`~qzs.model.hexapod.cubic_geometry`,
        :func:`~qzs.model.hexapod.radial_geometry`).
    platform : PlatformParameters
        Mass (platform, payload and the legs' moving parts), inertia about the centre of
        mass, centre of mass and gravity.
    isolator : IsolatorParameters or sequence of six, optional
        Each leg's plant; Table 1 defaults if omitted. Its ``mass`` and ``gravity`` are not
        used (the platform's are); ``stroke_half`` must equal the geometry's; compliant stops
        only. Its ``spring`` may be any law (docs/model.md §3.1), each leg its own; a law
        other than the tanh must hold the leg's static load in its stroke, as the single
        axis's must hold the payload's weight.
    controller : ControllerParameters or sequence of six, optional
        Each leg's loop (one for every leg, or one per leg); defaults if omitted. Continuous
        (``controller_rate`` 0) or sampled with zero-order hold, every leg at the same rate
        (one controller), as the single axis's (docs/model.md §5). Each leg's blocks beyond
        PI + damping (friction compensation with its observer, dither, a linear controller,
        continuous or discrete at its own period: docs/model.md §5.1) act on that leg alone,
        from its own sensors (docs/hexapod.md §9.5a); their forces are the channels
        ``compensation_force``, ``friction_estimate``, ``dither_force`` and ``linear_force``
        (0 on a leg without that block). With ``cartesian``, its ``position_setpoint``,
        ``velocity_highpass`` and ``controller_rate`` are used and its gains are not, and
        blocks are refused.
    excitation : dict, optional
        Base motion: axis name (``"x"``, ``"y"``, ``"z"`` [m], ``"rx"``, ``"ry"``, ``"rz"``
        [rad]) to a Chirp, Sine, RandomExcitation or DisplacementRecord (its amplitude in that
        axis's unit). The base pose is the displacement of the base point under the top frame
        origin at home and the base's rotation ``Rz Ry Rx`` about it. Default: no base motion.
    duration : float, optional
        Simulated time [s]; default the shortest excitation's length (required when none
        defines one).
    dt : float
        Integration step [s]; default 1e-4.
    sample_rate : float
        Output sample rate [Hz]; ``1/dt`` must be a whole multiple of it.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator (Bogacki-Shampine 3rd order by default).
    cartesian : CartesianController, optional
        Centralised control: the PI and damping loops on the platform's six axes, mapped
        through the Jacobian (docs/hexapod.md §9.5); default None, a loop per leg.
    progress : bool
        Show a progress bar over the simulated time.
    sink : callable, optional
        ``sink(data, flags)`` receives every output sample, chunk by chunk, in time order
        (``data`` with :data:`~qzs.engine.hexapod.result.HEXAPOD_CHANNELS`' columns, ``flags``
        with :data:`~qzs.engine.hexapod.result.HEXAPOD_FLAGS`'); memory then stays bounded
        however long the run, and the result holds every sample only up to 200,000 of them,
        else per group of k samples (``run["preview_every"]``) one row of each channel's
        minimum and one of its maximum, the flags' all and any (the run driver's preview,
        :class:`qzs.engine.driver.Recorder`, as a single run's); its summary covers every sample
        (:class:`qzs.engine.hexapod.result.HexapodWriter` is such a sink).
    interruptible : bool
        Ctrl-C ends the run after the chunk under way; the result (and the sink) then hold
        what was simulated, and ``run["completed"]`` is False.

    Returns
    -------
    HexapodResult

    Raises
    ------
    ParameterError
        Invalid argument (names it, its value and the fix); ``StabilityError`` if ``dt``
        exceeds the largest stable step.
    SimulationError
        The state diverged (the message names the time and state).
    """
    run = _prepare(geometry, platform, isolator, controller, excitation, duration, dt,
                   sample_rate, solver, progress, cartesian)
    if sink is not None and not callable(sink):
        raise ParameterError(f"`sink` must be a callable sink(data, flags) or None, got "
                             f"{type(sink).__name__}.")
    if not isinstance(interruptible, (bool, np.bool_)):
        raise ParameterError(f"`interruptible` must be True or False, got {interruptible!r}.")
    plan = driver.plan_run(run.duration, run.dt, run.decimation, kernel="hexapod",
                           max_samples=PREVIEW_CHUNK, phase_period=1)
    statistics = _Statistics([0.5 * (run.V[V_ZLOW + i] + run.V[V_ZHIGH + i])
                              for i in range(LEG_COUNT)], run.controllers)
    recorder = driver.Recorder(
        plan, N_CHANNELS if has_blocks(run.controllers) else N_BASE_CHANNELS, N_FLAGS,
        statistics=statistics.add, sink=sink,
        duration=run.duration, sample_rate=run.sample_rate,
        remedy="stream it to a file instead (`qzs hexapod simulate --out FILE.nc`, "
               "qzs.workflows.hexapod.setups.simulate_setup(..., out=...)), or lower the "
               "`sample_rate` or the `duration`")
    stepper = _SixLegs(run, recorder.buffers)
    data, marks = recorder.buffers[0]
    _start(stepper.s, *stepper.arrays, *stepper.work, data[0], marks[0])
    recorder.absorb(0, 0, 1)
    outcome = driver.drive(stepper, plan, recorder,
                           progress="simulating hexapod" if progress else None,
                           interruptible=interruptible)
    counters, V = stepper.counters, run.V
    info = dict(solver=run.solver, dt=run.dt, sample_rate=run.sample_rate, duration=run.duration,
                steps=int(counters[CT_STEP]), elapsed=outcome.elapsed, samples=recorder.rows,
                events=int(counters[CT_EVENTS]),
                stick_events=[int(v) for v in counters[CT_STICKS:CT_STICKS + LEG_COUNT]],
                stop_contacts=[int(v) for v in counters[CT_CONTACTS:CT_CONTACTS + LEG_COUNT]],
                stops=[(float(V[V_ZLOW + i]), float(V[V_ZHIGH + i])) for i in range(LEG_COUNT)],
                control="centralised" if run.cartesian is not None else "per leg",
                controller_rate=run.controllers[0].controller_rate,
                completed=outcome.completed, preview_every=recorder.every)
    data, data_flags = recorder.result()
    return HexapodResult(data, data_flags, geometry=run.geometry, platform=run.platform,
                         isolators=run.isolators, controllers=run.controllers,
                         excitation=run.excitation, run=info, statistics=statistics.result())


class _SixLegs(driver.Stepper):
    """The six-leg kernel (:func:`qzs.engine.hexapod.stepping._run`) as the driver's stepper.

    Holds the kernel's workspaces; the state, modes, counters and the excitation's phase
    persist in them between calls, so that cutting a run into calls changes nothing.
    """

    def __init__(self, run, buffers):
        self.run = run
        self.buffers = buffers
        self.s = run.state
        self.counters = np.zeros(N_COUNTERS, dtype=np.int64)
        self.arrays = (run.plat, run.models, run.ex, run.tables, run.toff)
        self.work = (np.zeros((N_BUF, self.s.size)), np.zeros((2, LEG_COUNT)), np.zeros(N_WORK),
                     run.V, np.zeros((LEG_COUNT, LEG_COUNT)), np.zeros(LEG_COUNT, dtype=np.int64),
                     np.zeros((2, LEG_COUNT)), np.zeros(LEG_COUNT, dtype=np.int64), self.counters)
        self.diverged = False
        self.status = STATUS_OK

    def advance(self, steps, buffer, row0):
        """Advance ``steps`` steps; returns the rows written into ``buffers[buffer]``."""
        data, marks = self.buffers[buffer]
        status, written = _run(self.run.solver_code, steps, self.run.decimation, self.run.dt,
                               self.s, *self.arrays, *self.work, data, marks, row0)
        self.diverged = status != STATUS_OK
        self.status = status
        return written

    def divergence(self):
        """The :class:`~qzs.errors.SimulationError` of a diverged run (time and last state)."""
        s, V = self.s, self.run.V
        failed = int(self.counters[CT_STEP])
        if self.status == STATUS_OUTSIDE:  # a leg's refusing spring table, as the single axis
            ww = self.work[2]
            leg = int(ww[W_OUTSIDE]) - 1
            return SimulationError(table_exit_message(
                self.run.models[leg], ww[W_OUTSIDE + 1], ww[W_OUTSIDE + 2],
                failed * self.run.dt, who=f"leg {leg + 1}", at="reached"))
        blocks = ""
        if s.size > N_ODE:
            blocks = (f", the controller blocks' largest state {np.max(np.abs(s[N_ODE:])):.6g} "
                      "(an unstable linear controller or over-compensation grows: "
                      "qzs.loop_margins of the leg's loop says so)")
        return SimulationError(
            f"the hexapod simulation diverged at t = {failed * self.run.dt:.6g} s (last state: "
            f"centre of mass {s[S_C:S_C + 3].tolist()} m and velocity "
            f"{s[S_V:S_V + 3].tolist()} m/s relative to the base, leg positions "
            f"{V[V_Z:V_Z + LEG_COUNT].tolist()} m{blocks}); check the gains and parameters, or "
            "reduce `dt`.")


def simulate_hexapods(runs: Sequence[Mapping[str, Any]], *, workers: int | None = None,
                      progress: bool = False) -> list[HexapodResult]:
    """Simulate several platforms at once, in threads (the hexapod kernel holds no GIL).

    Every run is checked before any integration starts (a bad one is named by its index);
    each gives the very numbers :func:`simulate_hexapod` gives it alone. The six legs of
    one platform already fill the kernel's vector lanes
    (:data:`~qzs.engine.hexapod.layout.LANES`), so platforms are batched across cores, one
    thread each, rather than in lanes.

    Parameters
    ----------
    runs : sequence of dict
        Keyword arguments of :func:`simulate_hexapod`, one dict per platform (``geometry``
        and ``platform`` required); ``progress`` and ``sink`` are not accepted.
    workers : int, optional
        Threads; default the machine's core count (at most the number of runs).
    progress : bool
        A progress bar over the platforms.

    Returns
    -------
    list of HexapodResult
        In the order of ``runs``.

    Raises
    ------
    CaseError
        A run's arguments are invalid (attributes ``index`` and ``reason``).
    ParameterError
        ``runs`` is empty or holds no dicts, or ``workers`` is not a positive integer.
    """
    from concurrent.futures import ThreadPoolExecutor

    runs = list(runs)
    if not runs:
        raise ParameterError("`runs` is empty: give at least one dict of simulate_hexapod "
                             "arguments.")
    workers = worker_count(workers, len(runs))  # checked before any run is set up
    names = ("geometry", "platform", "isolator", "controller", "excitation", "duration", "dt",
             "sample_rate", "solver", "cartesian")
    for i, arguments in enumerate(runs):
        if not isinstance(arguments, dict):
            raise ParameterError(f"`runs[{i}]` must be a dict of simulate_hexapod arguments, "
                                 f"got {type(arguments).__name__}.")
        known_keys(arguments, names, f"`runs[{i}]`", required=names[:2], noun="argument",
                   fix="give simulate_hexapod's arguments")
        try:  # every run checked before any integration (it packs again when it starts: cheap)
            _prepare(arguments["geometry"], arguments["platform"], arguments.get("isolator"),
                     arguments.get("controller"), arguments.get("excitation"),
                     arguments.get("duration"),
                     arguments.get("dt", defaults.SIMULATION["dt"]),
                     arguments.get("sample_rate", defaults.SIMULATION["sample_rate"]),
                     arguments.get("solver", defaults.SIMULATION["solver"]), False,
                     arguments.get("cartesian"))
        except ParameterError as error:
            raise CaseError(i, str(error)) from error
    bar = None
    if progress:
        from qzs.engine.progress import progress_bar

        bar = progress_bar(total=len(runs), unit="platform", desc="simulating hexapods")

    def one(arguments):
        result = simulate_hexapod(**arguments)
        if bar is not None:
            bar.update()
        return result

    try:
        with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="qzs-hexapod") as pool:
            return list(pool.map(one, runs))
    finally:
        if bar is not None:
            bar.close()
