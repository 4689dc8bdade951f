"""Fixed-step simulation of the isolator: validated entry point around the kernels.

>>> from qzs import simulate, Chirp
>>> result = simulate(Chirp(duration=20.0, f1=5.0), dt=1e-4, sample_rate=500.0)
>>> result.summary()  # doctest: +SKIP
"""
import signal
import threading
import time as _time
from concurrent.futures import ThreadPoolExecutor, wait

import numpy as np

from qzs import defaults
from qzs.analysis.statistics import SummaryStatistics
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.prepare import chunk_steps, divergence_message, prepare_run
from qzs.engine.results import SimulationResult, named_block
from qzs.errors import ResultTooLargeError, SimulationError, Terminated

__all__ = ["simulate", "result_bytes"]

#: Bytes one output sample takes in memory: every channel as float64, the flags as bool.
BYTES_PER_SAMPLE = 8 * K.N_CHANNELS + 2
#: Rows a streamed run keeps in memory for its plot: all samples up to this many, else the
#: min/max envelope of groups of k samples in at most this many rows.
PREVIEW_SAMPLES = 200_000
#: Integration steps per chunk at most: the unit of progress, streaming and Ctrl-C.
CHUNK_STEPS = 2_000_000
#: Output samples per chunk at most: the buffer of a streamed run (12 MB).
CHUNK_SAMPLES = 65_536
#: Share of the available memory a result may take before a run without a sink is refused.
MEMORY_SHARE = 0.5


def simulate(excitation=None, isolator=None, controller=None, *, duration=None,
             dt=defaults.SIMULATION["dt"], sample_rate=defaults.SIMULATION["sample_rate"],
             solver=defaults.SIMULATION["solver"], initial_state=None, progress=False,
             interruptible=False, sink=None):
    """Simulate the isolator under a base excitation with a fixed-step integrator.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default the paper's 10 mm, 0-20 Hz, 2000 s chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults of docs/model.md §11 if omitted.
    duration : float, optional
        Simulated time [s]; default the excitation's length (required for a sine).
    dt : float
        Integration step [s]; default 1e-4 (the paper's 2e7 steps for 2000 s).
    sample_rate : float
        Output sample rate [Hz]; ``1/dt`` must be a whole multiple of it. Output
        is decimated while integrating, so memory grows with the output only.
    solver : {"ode3", "rk4", "euler"}
        Bogacki-Shampine 3rd order (Simulink ode3, default), classic RK4, or explicit Euler.
    initial_state : InitialState, optional
        Default: at rest at the setpoint, stuck if friction can hold the payload.
    progress : bool
        Show a progress bar.
    interruptible : bool
        If True, Ctrl-C ends the run early and returns what was simulated
        (``result.completed`` is False) instead of raising ``KeyboardInterrupt``.
    sink : callable, optional
        ``sink(data, flags)`` receives every output sample, chunk by chunk, in time order
        (``data`` of shape (n, N_CHANNELS) in the columns of
        :data:`~qzs.engine.results.CHANNELS`, ``flags`` of shape (n, 2); both are reused
        buffers: consume or copy them). The result then keeps every sample if there are
        at most :data:`PREVIEW_SAMPLES`, else a preview for figures: per group of k
        consecutive samples (``result.run["preview_every"]``) one row of each channel's
        minimum and one of its maximum (the flags' all and any), so memory stays bounded
        however long the run and a plot shows the true envelope, never an aliased pick
        (:class:`qzs.iotools.files.ResultWriter` is such a sink). The summary's
        statistics always come from every sample.

    Returns
    -------
    SimulationResult

    Raises
    ------
    ParameterError
        Invalid argument; ``StabilityError`` if ``dt`` exceeds the largest stable step;
        ``ResultTooLargeError`` if, without a ``sink``, the result would not fit in memory.
    SimulationError
        The state diverged or became non-finite (the message names time and state).
    """
    run = prepare_run(excitation, isolator, controller, duration=duration, dt=dt,
                      sample_rate=sample_rate, solver=solver, initial_state=initial_state)
    excitation, isolator, controller = run.excitation, run.isolator, run.controller
    p, packed, s, flags = run.params, run.packed, run.state, run.flags
    duration, decimation, solver_code = run.duration, run.decimation, run.solver_code
    dt, sample_rate = run.dt, run.sample_rate
    n_steps = int(round(duration / dt))
    n_out = n_steps // decimation + 1
    chunk = chunk_steps(decimation, CHUNK_STEPS, CHUNK_SAMPLES)
    if sink is None:
        _check_memory(n_out, duration, sample_rate)
        every = 1
        out = np.empty((n_out, K.N_CHANNELS))
        out_flags = np.zeros((n_out, 2), dtype=np.bool_)
    else:
        every = 1 if n_out <= PREVIEW_SAMPLES else -(-n_out // (PREVIEW_SAMPLES // 2))
        out = np.empty((chunk // decimation + 1, K.N_CHANNELS))
        out_flags = np.zeros((out.shape[0], 2), dtype=np.bool_)
        preview, preview_flags = [], []
    K.evaluate(0.0, s, flags, p, *packed, out[0], out_flags[0])
    statistics = SummaryStatistics(0.5 * (p[K.P_Z_LOW] + p[K.P_Z_HIGH]), isolator.motor_force_max)

    buffers = [(out, out_flags)]
    if sink is not None:  # two buffers: the kernel fills one while the other is written
        buffers.append((np.empty_like(out), np.zeros_like(out_flags)))

    def absorb(buffer, first, rows, total):
        """Rows ``first:first+rows`` of a buffer are new; ``total`` were written before."""
        data, marks = buffers[buffer]
        block, block_flags = data[first:first + rows], marks[first:first + rows]
        statistics.add(named_block(block, block_flags))
        if sink is not None:
            sink(block, block_flags)
            if every == 1:
                preview.append(block.copy())
                preview_flags.append(block_flags.copy())
            elif rows:
                low, high = _envelope_rows(block, block_flags, total, every)
                preview.append(low)
                preview_flags.append(high)

    def integrate(n, row0, buffer):
        data, marks = buffers[buffer]
        return _lanes.run_single(solver_code, n, decimation, s, flags, p, *packed, data, marks,
                                 row0)[0]

    absorb(0, 0, 1, 0)
    rows, done, completed, start, interrupted = 1, 0, True, None, False
    bar = _progress_bar(n_steps, progress)
    # The kernel holds no GIL: it integrates the next chunk in a thread while this one writes
    # the last (statistics, sink, preview), so writing costs no integration time.
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="qzs-kernel")

    def launch(chunk_index, done, rows):
        n = min(chunk, n_steps - done)
        buffer = chunk_index % len(buffers)
        row0 = rows if sink is None else 0
        return pool.submit(integrate, n, row0, buffer), n, row0, buffer

    deferred = _DeferredInterrupt() if interruptible else None
    try:
        if deferred is not None:  # Ctrl-C stops the run between chunks: rows stay whole
            deferred.install()
        # a zero-step call compiles (or loads) the kernel: the clock counts integration only
        pool.submit(integrate, 0, 1, 0).result()
        start = _time.perf_counter()
        pending = launch(0, done, rows) if done < n_steps else None
        index = 0
        while pending is not None:
            future, n, row0, buffer = pending
            status, stopped = _collect(future)
            interrupted = interrupted or stopped or (deferred is not None and deferred.requested)
            written = int(flags[K.I_STEP]) // decimation - done // decimation
            done = int(flags[K.I_STEP])
            index += 1
            pending = None
            if status == K.STATUS_OK and not interrupted and done < n_steps:
                pending = launch(index, done, rows + written)
            absorb(buffer, row0, written, rows)
            rows += written
            if status != K.STATUS_OK:
                _raise_diverged(s, flags, p)
            if bar is not None:
                bar.update(n)
        if deferred is not None and deferred.terminated:
            raise Terminated(deferred.terminated)
        if interrupted:
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        if not interruptible:
            raise
        completed = False
    finally:
        if deferred is not None:
            deferred.restore()
        pool.shutdown(wait=True)
        if bar is not None:
            bar.close()
    elapsed = 0.0 if start is None else _time.perf_counter() - start
    run = dict(solver=solver, dt=dt, sample_rate=sample_rate, duration=duration,
               steps=int(flags[K.I_STEP]), elapsed=elapsed, completed=completed,
               stop_contacts=int(flags[K.I_N_CONTACTS]), stick_events=int(flags[K.I_N_STICKS]),
               stop_low=float(p[K.P_Z_LOW]), stop_high=float(p[K.P_Z_HIGH]), samples=rows,
               preview_every=every)
    if sink is None:
        data, data_flags = out[:rows], out_flags[:rows]
    else:
        data, data_flags = np.concatenate(preview), np.concatenate(preview_flags)
    return SimulationResult(data, data_flags, isolator=isolator, controller=controller,
                            excitation=excitation, run=run, statistics=statistics.result())


class _DeferredInterrupt:
    """While an interruptible run goes on, Ctrl-C asks it to stop after the chunk under way.

    A KeyboardInterrupt raised in the middle of writing a chunk would leave the chunk
    half-written (its statistics counted, its rows not in the file); the handler only
    sets :attr:`requested`, which the run checks between chunks. Where SIGTERM has a
    Python handler (the command line turns it into :class:`~qzs.errors.Terminated`), it
    is deferred the same way and :attr:`terminated` holds its number, for the run to
    raise between chunks: raised at an arbitrary point it could land in a weakref
    callback, where Python prints it and carries on. Installed only in the main thread
    (where Python runs signal handlers), restored afterwards.
    """

    def __init__(self):
        self.requested = False
        self.terminated = 0
        self._previous = {}

    def _handler(self, signum, frame):
        self.requested = True
        if signum == signal.SIGTERM:
            self.terminated = signum

    def install(self):
        """Take over SIGINT, and SIGTERM where it has a Python handler (main thread only)."""
        if threading.current_thread() is not threading.main_thread():
            return
        self._previous[signal.SIGINT] = signal.signal(signal.SIGINT, self._handler)
        if callable(signal.getsignal(signal.SIGTERM)):
            self._previous[signal.SIGTERM] = signal.signal(signal.SIGTERM, self._handler)

    def restore(self):
        """Give the signals back to the handlers they had."""
        for signum, previous in self._previous.items():
            signal.signal(signum, previous)
        self._previous = {}


def _collect(future):
    """The kernel's status once it has ended, and whether Ctrl-C came meanwhile.

    The kernel cannot be stopped (it holds no GIL and checks no signal): after Ctrl-C it
    is waited for, so that the rows it wrote are kept; a KeyboardInterrupt raised in its
    own thread leaves its rows written as well.
    """
    stopped = False
    while True:
        try:
            wait([future])
            break
        except KeyboardInterrupt:
            stopped = True
    error = future.exception()
    if isinstance(error, KeyboardInterrupt):
        return K.STATUS_OK, True
    return future.result(), stopped


def _envelope_rows(data, flags, first, every):
    """A block's min/max envelope: per group of ``every`` samples (counted from the run's
    start, sample ``first`` being the block's first), a row of each channel's minimum (at
    the group's first time) and one of its maximum (at its last time); the flags are
    all/any. Returns ``(rows, flags)``, two rows per group, in time order."""
    group = (first + np.arange(data.shape[0])) // every
    starts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
    rows = np.empty((2 * starts.size, data.shape[1]))
    rows[0::2] = np.minimum.reduceat(data, starts, axis=0)
    rows[1::2] = np.maximum.reduceat(data, starts, axis=0)
    marks = np.empty((2 * starts.size, flags.shape[1]), dtype=np.bool_)
    marks[0::2] = np.logical_and.reduceat(flags, starts, axis=0)
    marks[1::2] = np.logical_or.reduceat(flags, starts, axis=0)
    return rows, marks


def result_bytes(duration, sample_rate):
    """Memory [bytes] a run's result takes: every channel and flag at every output sample.

    Parameters
    ----------
    duration : float
        Simulated time [s].
    sample_rate : float
        Output sample rate [Hz].

    Returns
    -------
    int
    """
    return int((int(round(duration * sample_rate)) + 1) * BYTES_PER_SAMPLE)


def _available_memory():
    """Memory the system can give without swapping [bytes] (None where unknown)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        import os

        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def _check_memory(n_out, duration, sample_rate):
    needed = n_out * BYTES_PER_SAMPLE
    available = _available_memory()
    if available is not None and needed > MEMORY_SHARE * available:
        raise ResultTooLargeError(needed, available, duration, sample_rate)


def _progress_bar(total, enabled):
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, unit="step", unit_scale=True, desc="simulating", leave=False)


def _raise_diverged(s, flags, p):
    raise SimulationError(divergence_message(s, flags[K.I_STEP], p[K.P_DT]))
