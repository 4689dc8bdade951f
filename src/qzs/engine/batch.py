"""Many parameter sets through the same kernel at once: the engine of sweeps.

Each case is validated and packed exactly as :func:`qzs.simulate` does it, and
:func:`qzs.engine.lanes.run_lanes` advances all cases by the same step, several cases
per vector instruction, with a share of the cases on each core: per case the
numbers are identical to ``simulate``'s (see :mod:`qzs.engine.lanes`). Output is
reduced while integrating: only the requested channels are kept, and per-case
statistics (stroke, stop contacts, RMS motor force, time locked) are
accumulated chunk by chunk.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs import defaults
from qzs._validation import worker_count
from qzs.analysis.statistics import SATURATION, STATISTICS, RunStatistics
from qzs.engine import driver
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.prepare import divergence_message, prepare_run, stack_models
from qzs.engine.channels import (BLOCK_CHANNELS, FLAGS, run_channels, sample_bytes,
                                 simulation_schema, unrecorded)
from qzs.engine.metadata import _now
from qzs.errors import CaseError, ParameterError
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension, save_doc
from qzs.iotools.schema import Schema, Variable, to_dataset
from qzs.model.controller import BLOCKS
from qzs.model.registry import (ALL_PARAMETERS, BLOCK_PARAMETERS, SPRING_PARAMETERS,
                                law_parameters, parameter_value)

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.isolator import IsolatorParameters

__all__ = ["BatchResult", "simulate_batch", "batch_schema", "STATS"]

#: Per-case statistics: name -> (unit, description).
STATS = {
    "stop_contacts": ("1", "number of hard-stop contacts"),
    **STATISTICS,
    **SATURATION,
    "stick_events": ("1", "number of stick events"),
    "steps": ("1", "integration steps done"),
}
_COUNTS = ("stop_contacts", "stick_events", "steps")  # statistics stored as int64
#: Output rows held at once, over all cases (8 MB per channel the kernel records): the kernel
#: writes them, each chunk's kept channels and statistics are taken out. A buffer of 4e6 rows
#: (770 MB) cost `qzs paper` about 0.9 s of first touch in a fresh process (17.2-17.5 s against
#: 16.0-16.5 s with 1e6 rows; 2.5e5 rows gave the same as 1e6).
_ROWS_PER_CHUNK = 1_000_000
#: The channels the statistics read (:meth:`_Lanes.absorb`), recorded whatever is kept; the
#: kernel computes and stores no other channel (the flags it always records).
_STATISTICS_COLUMNS = (K.C_Z, K.C_F_MOTOR)
#: Samples (cases x rows) whose statistics are taken at once. Over a whole chunk (4 MB per
#: temporary at 128 cases x 3906 rows) numpy's temporaries were mapped fresh from the system
#: at every call (glibc unmaps or trims large blocks when they are freed) and their first
#: touch cost this VM more than the arithmetic: 12.8 ns a sample, against 3.0 ns in groups
#: of 2**17 samples (1 MB temporaries, reused from the heap).
_GROUP_SAMPLES = 1 << 17


@dataclass
class BatchResult:
    """Outputs of :func:`simulate_batch`.

    Attributes
    ----------
    time : ndarray, shape (n_samples,)
        Sample times [s].
    channels : dict of str to ndarray, shape (n_cases, n_samples)
        The requested channels (names and units of :data:`qzs.engine.channels.CHANNELS`;
        the flags of :data:`qzs.engine.channels.FLAGS` as boolean arrays).
    stats : dict of str to ndarray, shape (n_cases,)
        Per-case statistics, see :data:`STATS`.
    status : ndarray of int8, shape (n_cases,)
        0 for a completed case, 1 for a failed one.
    messages : list of str
        '' or the failure message (time and state) of each case.
    elapsed : float
        Wall time of the integration [s].
    cases : list of (IsolatorParameters, ControllerParameters)
        The parameter sets simulated, in the order of the rows.
    stop_limits : ndarray, shape (n_cases, 2)
        Each case's lower and upper hard stop in relative position z [m].
    """

    time: np.ndarray
    channels: dict[str, np.ndarray]
    stats: dict[str, np.ndarray]
    status: np.ndarray
    messages: list[str]
    elapsed: float = 0.0
    cases: list[tuple[IsolatorParameters, ControllerParameters]] = field(default_factory=list)
    stop_limits: np.ndarray | None = None

    @property
    def steps_per_second(self) -> float:
        """Simulated steps per second over all cases [steps/s]."""
        return float(self.stats["steps"].sum()) / max(self.elapsed, 1e-12)

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def summary(self) -> str:
        """The batch as text: its size, its failures, each case's statistics
        (:func:`qzs.analysis.summary.batch_text`).

        Returns
        -------
        str
        """
        from qzs.analysis.summary import batch_text

        return batch_text(self, STATS)

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> Figure:
        """The kept channels against time, one line per case
        (:func:`qzs.viz.simulation.plot_batch`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there too, atomically (format from the suffix).
        title : str, optional
            Figure title; default one naming the cases and the failures.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.simulation import plot_batch

        return plot_batch(self, path=path, title=title)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray)

    save.__doc__ = save_doc("``.nc`` (NetCDF, CF-1.10), ``.csv`` (one row per case and "
                            "sample) or ``.mat`` (MATLAB) of :meth:`to_xarray`")

    def to_xarray(self) -> xr.Dataset:
        """The batch as an ``xarray.Dataset`` on dimensions ``case`` and ``time``, CF-1.10.

        The kept channels on ``(case, time)``, the statistics and ``status`` (int8
        flag, 0 completed, 1 failed) and ``message`` on ``case``, and every parameter
        of each case as a coordinate on ``case`` (registry name, unit in ``units``;
        a ``None`` value as NaN, a choice as a string). Counts are integers. The
        conventions are those of a single run's file (docs/model.md §7;
        :func:`batch_schema`).

        Returns
        -------
        xarray.Dataset
        """
        from qzs._version import __version__

        parameters = _parameter_values(self.cases, len(self.status))
        values = {"case": np.arange(len(self.status)), "time": self.time, **self.channels,
                  **self.stats, "status": self.status,
                  "message": [str(m) for m in self.messages],
                  **{name: [np.nan if v is None else v for v in column]
                     for name, column in parameters.items()}}
        n = len(self.status)
        attrs = {"title": f"qzs batch of {n} simulations of the semi-active QZS isolator",
                 "source": f"qzs {__version__}: fixed-step simulations of the semi-active "
                           "quasi-zero-stiffness isolator (model: docs/model.md)",
                 "history": f"{_now()} qzs {__version__}: simulate_batch, {n} cases, "
                            f"{int(np.sum(self.status))} failed",
                 "qzs_version": __version__, "elapsed": float(self.elapsed),
                 "elapsed_units": "s"}
        return to_dataset(batch_schema(self), values, attrs)


def _parameter_values(cases, n):
    """Every registry parameter's value in each case: name -> list (none if ``cases`` is not
    one pair per case); a block's parameters where a case has that block, a spring law's
    where a case's law has it (None in the others)."""
    if len(cases) != n:
        return {}
    blocks = {name for pair in cases for name in BLOCKS if getattr(pair[1], name) is not None}
    laws = {name for pair in cases for name in law_parameters(pair[0].spring)}

    def recorded(name):  # a law's parameter where a case's law has it, a block's likewise
        if name in SPRING_PARAMETERS:
            return name in laws
        return name not in BLOCK_PARAMETERS or name.split(".", 1)[0] in blocks

    return {name: [parameter_value(*pair, name) for pair in cases]
            for name in ALL_PARAMETERS if recorded(name)}


def batch_schema(batch):
    """The CF-1.10 layout of a batch's dataset (:meth:`BatchResult.to_xarray`).

    Dimensions ``case`` and ``time``; the kept channels as in a single run's file
    (:func:`qzs.engine.channels.simulation_schema`) on ``(case, time)``; the statistics of
    :data:`STATS` (counts int64), ``status`` (int8 flag) and ``message`` on ``case``; the
    coordinates ``case``, ``time`` and every parameter (a string where all cases give one,
    else float64 with NaN for none).

    Parameters
    ----------
    batch : BatchResult
        The batch (its channels, statistics, cases and sizes).

    Returns
    -------
    Schema
    """
    single = simulation_schema(every_block=True)
    n = len(batch.status)
    variables = [dataclasses.replace(single[name], dims=("case", "time"))
                 for name in batch.channels]
    variables += [Variable(name=name, dims=("case",), units=STATS[name][0],
                           long_name=STATS[name][1],
                           dtype="int64" if name in _COUNTS else "float64")
                  for name in batch.stats]
    variables += [Variable(name="status", dims=("case",), units="1", long_name="case status",
                           dtype="int8", flag_meanings="completed failed"),
                  Variable(name="message", dims=("case",), dtype="str",
                           long_name="failure message ('' if completed)")]
    coordinates = [Variable(name="case", dims=("case",), units="1", long_name="case index",
                            dtype="int64", order=("long_name", "units")), single["time"]]
    for name, column in _parameter_values(batch.cases, n).items():
        info = ALL_PARAMETERS[name]
        text = all(isinstance(v, str) for v in column)
        none = ("NaN: no such block in the case, or the plant's value" if name in
                BLOCK_PARAMETERS else "NaN: no such parameter in the case's spring law"
                if name in SPRING_PARAMETERS else "NaN: none")
        coordinates.append(Variable(
            name=name, dims=("case",), units=info.unit, long_name=info.doc,
            dtype="str" if text else "float64",
            attributes=({"comment": none} if not text and any(v is None for v in column)
                        else {})))
    return Schema(kind="a batch", dimensions={"case": n, "time": len(batch.time)},
                  coordinates=coordinates, variables=variables)


def simulate_batch(cases: Sequence[tuple[IsolatorParameters, ControllerParameters]],
                   excitation: Excitation | None = None, *, duration: float | None = None,
                   dt: float = defaults.SIMULATION["dt"],
                   sample_rate: float = defaults.SIMULATION["sample_rate"],
                   solver: str = defaults.SIMULATION["solver"],
                   channels: Sequence[str] = ("base_acceleration", "payload_acceleration"),
                   workers: int | None = None, progress: bool = False) -> BatchResult:
    """Simulate many parameter sets under one excitation, in parallel.

    Parameters
    ----------
    cases : sequence of (IsolatorParameters, ControllerParameters)
        The parameter sets; each starts from the default initial state.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Shared base motion; default the paper's chirp.
    duration : float, optional
        Simulated time [s]; default the excitation's length, as in :func:`qzs.simulate`.
    dt : float
        Integration step [s], as in :func:`qzs.simulate`.
    sample_rate : float
        Output sample rate [Hz], as in :func:`qzs.simulate`.
    solver : {"ode3", "rk4", "euler"}
        Integrator, as in :func:`qzs.simulate`.
    channels : sequence of str
        Time series to keep: names of :data:`qzs.engine.channels.CHANNELS`, of a block's
        force (:data:`qzs.engine.channels.BLOCK_CHANNELS`: ``"compensation_force"`` [N],
        ...; every case's controller must have that block), or of the boolean flags
        :data:`qzs.engine.channels.FLAGS` (``"locked"``, ``"stop_contact"``); may be empty.
    workers : int, optional
        Threads, each running a share of the cases in the kernel (which releases
        the GIL); default all cores.
    progress : bool
        Show a progress bar over simulated time.

    Returns
    -------
    BatchResult

    Raises
    ------
    ParameterError
        An invalid argument.
    CaseError
        A case that is invalid; its ``index`` attribute says which, ``reason`` why.
    """
    cases = list(cases)
    if not cases:
        raise ParameterError("`cases` must hold at least one (isolator, controller) pair.")
    if isinstance(channels, str):
        raise ParameterError(f"`channels` must be a sequence of channel names, got the string "
                             f"{channels!r}; write ({channels!r},).")
    recordable = run_channels(every_block=True)
    unknown = [c for c in channels if c not in recordable and c not in FLAGS]
    if unknown:
        raise ParameterError(f"unknown channel(s) {unknown}; channels are "
                             f"{[*recordable, *FLAGS]}.", options=("channels",))
    prepared = []
    for index, pair in enumerate(cases):
        try:
            isolator, controller = pair
            prepared.append(prepare_run(excitation, isolator, controller, duration=duration,
                                        dt=dt, sample_rate=sample_rate, solver=solver))
        except (TypeError, ValueError) as error:
            raise CaseError(index, error) from error
    _check_block_channels(channels, [controller for _, controller in cases])
    first = prepared[0]
    n = len(prepared)
    decimation = first.decimation
    ex, table = first.packed
    workers = worker_count(workers, n)
    plan = driver.plan_run(first.duration, first.dt, decimation, kernel="lanes", cases=n,
                           workers=workers, max_samples=max(1, _ROWS_PER_CHUNK // n),
                           max_steps=int(round(first.duration / first.dt)))
    driver.check_memory(n * plan.samples * sample_bytes(channels), first.duration,
                        first.sample_rate,
                        remedy="keep fewer `channels`, lower the `sample_rate`, or run the cases "
                               "in several batches")
    lanes = _Lanes(prepared, channels, workers, plan)
    sample, marks = np.empty(K.N_CHANNELS), np.zeros(2, dtype=np.bool_)
    for c in range(n):
        K.evaluate(0.0, lanes.states[c], lanes.flags[c], lanes.params[c],
                   K.kernel_model(lanes.models[c]), ex, table, sample, marks)
        # only the channels kept or read by the statistics: a write to any other would
        # fault in (and zero) a page of the chunk buffer that nothing reads, huge pages of
        # 2 MB for numpy's large arrays (the whole 190 MB buffer for 24 channels)
        lanes.buffer[lanes.columns, c, 0] = sample[lanes.columns]
        lanes.out_flags[c, 0] = marks
    lanes.absorb(1, 0, 0)
    recorder = _Rows()
    recorder.rows = 1
    try:
        outcome = driver.drive(lanes, plan, recorder,
                               progress=f"{n} cases" if progress else None)
    finally:
        lanes.close()
    states, flags, status = lanes.states, lanes.flags, lanes.status
    messages = ["" if status[c] == K.STATUS_OK else
                divergence_message(states[c], lanes.failed_at[c], first.dt, status[c],
                                   lanes.models[c]) for c in range(n)]
    stats = {"stop_contacts": flags[:, K.I_N_CONTACTS].astype(float),
             **lanes.statistics.result(),
             "stick_events": flags[:, K.I_N_STICKS].astype(float),
             "steps": flags[:, K.I_STEP].astype(float)}
    stats = {name: stats[name] for name in STATS}
    time = (np.arange(plan.samples) * decimation) * first.dt  # step * dt: the kernel's time
    return BatchResult(time, lanes.kept, stats, (status != K.STATUS_OK).astype(np.int8),
                       messages, outcome.elapsed, cases,
                       lanes.params[:, [K.P_Z_LOW, K.P_Z_HIGH]].copy())


def _check_block_channels(channels, controllers):
    """Refuse a block's channel (``compensation_force``, ...) that a case has no block for."""
    missing = [unrecorded(channels, controller) for controller in controllers]
    for name in channels:
        lacking = [index for index, names in enumerate(missing) if name in names]
        if lacking:
            block = BLOCK_CHANNELS[name][3]
            what = ("a friction compensation with an observer (`observer_bandwidth` > 0)"
                    if block == "observer" else f"the `{block}` block")
            cases = ", ".join(str(index) for index in lacking[:10])
            more = f" and {len(lacking) - 10} more" if len(lacking) > 10 else ""
            raise ParameterError(
                f"`channels` holds {name!r}, which only a controller with {what} records; "
                f"case {cases}{more} has none. Give every case that block, or keep "
                f"{name!r} out of `channels`.", options=("channels",))


class _Rows:
    """The batch's recorder for the driver: the lanes keep their channels themselves (each
    thread its share, see :class:`_Lanes`), so that the next chunk may start at once."""

    rows: int  # set by simulate_batch

    def target(self, chunk_index, rows):
        return 0, 0

    def absorb(self, buffer, first, count):
        self.rows += count


class _Lanes(driver.Stepper):
    """The lockstep kernel (:func:`qzs.engine.lanes.run_lanes`) as the driver's stepper.

    The cases are shared over ``workers`` threads; each thread advances its share and then
    takes its rows out of the chunk buffer into the kept channels and statistics (so that
    the statistics do not wait for the slowest share). A share of one case runs the
    one-case kernel (the same numbers, without the lanes' bookkeeping). A case that
    diverges keeps what it finished; the rest of its rows are NaN.

    The chunk buffer is channel-major, ``(channel, case, row)``, and only the channels kept
    and those the statistics read (:data:`_STATISTICS_COLUMNS`) are computed and written;
    ``out`` and ``out_flags`` are its views as ``(case, row, channel)``.
    """

    def __init__(self, prepared, channels, workers, plan):
        first = prepared[0]
        n = len(prepared)
        self.solver, self.decimation, self.plan = first.solver_code, first.decimation, plan
        self.ex, self.table = first.packed
        self.states = np.stack([r.state for r in prepared])
        self.flags = np.stack([r.flags for r in prepared])
        self.params = np.stack([r.params for r in prepared])
        self.models = stack_models([r.model for r in prepared])
        self.status = np.zeros(n, dtype=np.int64)
        self.written = np.zeros(n, dtype=np.int64)
        self.failed_at = np.full(n, -1, dtype=np.int64)
        recordable = run_channels(every_block=True)
        self.kept = {c: (np.empty((n, plan.samples)) if c in recordable
                         else np.zeros((n, plan.samples), dtype=bool)) for c in channels}
        self.values = [(c, recordable[c][0]) for c in channels if c in recordable]
        self.flag_columns = [(c, FLAGS[c][0]) for c in channels if c in FLAGS]
        self.columns = np.array(sorted({col for _, col in self.values}
                                       | set(_STATISTICS_COLUMNS)), dtype=np.int64)
        rows = min(plan.samples, plan.chunk_samples)
        self.buffer = np.empty((K.N_CHANNELS, n, rows))  # the channels not kept: never touched
        self.flag_buffer = np.zeros((2, n, rows), dtype=np.bool_)
        self.out = np.moveaxis(self.buffer, 0, -1)
        self.out_flags = np.moveaxis(self.flag_buffer, 0, -1)
        self.single = {}  # case -> the one-case kernel's row-major buffers
        self.statistics = RunStatistics(0.5 * (self.params[:, K.P_Z_LOW]
                                               + self.params[:, K.P_Z_HIGH]),
                                        force_limits=self.params[:, K.P_FMAX])
        self.bounds = np.linspace(0, n, workers + 1).astype(int)
        self.pool = ThreadPoolExecutor(max_workers=workers) if workers > 1 else None
        self.done = 0  # steps done
        self.row = 1  # rows kept
        self.diverged = False  # a failing case fails alone: the batch goes on

    def close(self):
        if self.pool is not None:
            self.pool.shutdown()

    def absorb(self, rows, start_row, first_row, a=0, b=None):
        """Rows ``first_row..`` of cases ``a..b-1`` into the kept channels and statistics.

        A group of cases at a time (:data:`_GROUP_SAMPLES`): the statistics are per case, so
        the grouping changes no bit, and their numpy temporaries stay small enough to be
        reused from the heap and to stay in cache.
        """
        b = len(self.status) if b is None else b
        group = max(1, _GROUP_SAMPLES // max(rows, 1))
        for g in range(a, b, group):
            cases = slice(g, min(g + group, b))
            block = self.out[cases, first_row:first_row + rows]
            marks = self.out_flags[cases, first_row:first_row + rows]
            for name, col in self.values:
                self.kept[name][cases, start_row:start_row + rows] = block[:, :, col]
            for name, col in self.flag_columns:
                self.kept[name][cases, start_row:start_row + rows] = marks[:, :, col]
            self.statistics.add(block[:, :, K.C_Z], block[:, :, K.C_F_MOTOR],
                                marks[:, :, K.O_LOCKED], cases)

    def _kernel(self, steps, a, b):
        """Advance cases ``a..b-1`` by ``steps`` steps from step ``self.done``."""
        if b - a == 1:  # the one-case kernel: the same numbers, without lane bookkeeping
            if self.status[a] == K.STATUS_OK:
                if a not in self.single:
                    self.single[a] = (np.empty((self.buffer.shape[2], K.N_CHANNELS)),
                                      np.zeros((self.buffer.shape[2], 2), dtype=np.bool_))
                data, marks = self.single[a]
                self.status[a], self.written[a] = _lanes.single_kernel(self.models[a])(
                    self.solver, steps, self.decimation, self.states[a], self.flags[a],
                    self.params[a], self.models[a], self.ex, self.table, data, marks, 0)
                written = self.written[a]
                self.buffer[self.columns, a, :written] = data[:written, self.columns].T
                self.flag_buffer[:, a, :written] = marks[:written].T
            return
        for first in range(a, b, _lanes.MAX_LANES):
            last = min(first + _lanes.MAX_LANES, b)
            code = _lanes.run_lanes(self.solver, self.done, steps, self.decimation,
                                    self.states[first:last], self.flags[first:last],
                                    self.params[first:last], self.models[first:last],
                                    self.ex, self.table,
                                    self.columns, self.buffer, self.flag_buffer, first, 0,
                                    self.status[first:last], self.written[first:last])
            if code != K.STATUS_OK:  # pragma: no cover - the slices above are never too long
                raise RuntimeError(f"the batch kernel refused {last - first} cases (at most "
                                   f"{_lanes.MAX_LANES} per call)")

    def _share(self, steps, rows, a, b):
        """One thread's share of a chunk: advance cases a..b-1, then keep their rows."""
        self._kernel(steps, a, b)
        ok = self.status[a:b] == K.STATUS_OK
        if np.any(self.written[a:b][ok] != rows):  # pragma: no cover
            raise RuntimeError("batch kernel wrote an unexpected number of rows")
        for c in a + np.flatnonzero(~ok):  # keep the part that finished
            self.out[c, self.written[c]:rows] = np.nan
            self.out_flags[c, self.written[c]:rows] = False
        self.absorb(rows, self.row, 0, a, b)

    def advance(self, steps, buffer, row0):
        """Advance every case ``steps`` steps; returns the rows each kept."""
        if steps == 0:  # compile (or load) only the kernels the shares will use
            sizes = {int(b - a) for a, b in zip(self.bounds[:-1], self.bounds[1:]) if b > a}
            if 1 in sizes:
                self._kernel(0, 0, 1)
            if any(size > 1 for size in sizes):
                self._kernel(0, 0, min(len(self.status), _lanes.MAX_LANES))
            return 0
        rows = (self.done + steps) // self.decimation - self.done // self.decimation
        before = self.status.copy()
        shares = range(len(self.bounds) - 1)
        if self.pool is None:
            self._share(steps, rows, 0, len(self.status))
        else:
            list(self.pool.map(lambda i: self._share(steps, rows, self.bounds[i],
                                                     self.bounds[i + 1]), shares))
        newly = (before == K.STATUS_OK) & (self.status != K.STATUS_OK)
        self.failed_at[newly] = self.flags[newly, K.I_STEP]
        self.row += rows
        self.done += steps
        return rows
