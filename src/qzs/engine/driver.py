"""The run driver: every run of the engine is integrated here, chunk by chunk.

One loop (scipy ``solve_ivp`` style: the driver loops, the method steps) serves the
single run (:func:`qzs.simulate`), the lockstep batch (:func:`qzs.simulate_batch`), the
six-leg platform (:func:`qzs.simulate_hexapod`) and the steady-state response's periodic
stepping (:mod:`qzs.engine.periodic`). The dynamics are plugged in as a *stepper*, an
object that advances its kernel by a number of steps and records the output samples that
fall in them (:class:`Stepper`); the driver owns what is the same for all of them:

- the plan (:func:`plan_run`): the number of steps, refused before anything starts when
  the run would take absurdly long (:class:`~qzs.errors.RunTooLongError`), and chunks
  bounded in output samples *and* in steps, so that each kernel call ends within a
  fraction of a second whatever the step;
- where the samples go (:class:`Recorder`): all of them in memory, refused before the run
  when they would not fit (:class:`~qzs.errors.ResultTooLargeError`, the same for every
  driver), or a sink (a streamed file) plus a min/max envelope preview for figures;
- the loop itself (:func:`drive`): the kernel runs in a thread (it holds no GIL) while
  the main thread writes the previous chunk, shows progress, and handles Ctrl-C and
  SIGTERM between chunks (:class:`DeferredInterrupt`), so that rows stay whole and a
  signal is honoured within a chunk's time.

Chunking changes no bit: the kernels compute the excitation's sine and cosine exactly on
multiples of :data:`~qzs.engine.kernels.PHASE_PERIOD` steps, and every chunk is a
multiple of it (docs/model.md §9).
"""
import math
import os
import signal
import threading
import time as _time
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass

import numpy as np

from qzs.errors import ResultTooLargeError, RunTooLongError, Terminated

__all__ = ["Stepper", "RunPlan", "plan_run", "Recorder", "Outcome", "drive",
           "DeferredInterrupt", "available_memory", "check_memory", "envelope_rows",
           "PHASE_PERIOD"]

#: Steps on which the kernels compute the excitation's sine and cosine exactly; every chunk
#: starts on a multiple of it (:data:`qzs.engine.kernels.PHASE_PERIOD`, repeated here so that
#: the driver does not load the kernels; a test checks that both agree).
PHASE_PERIOD = 256
#: Integration steps per chunk at most, for one case: the unit of progress, streaming and
#: Ctrl-C (about 0.1-0.3 s of the single-axis kernel). A batch divides it by the cases each
#: thread steps, a costlier kernel by its cost relative to the single axis.
CHUNK_STEPS = 2_000_000
#: Output samples per chunk at most: the buffer of a streamed run (12 MB of the single axis).
CHUNK_SAMPLES = 65_536
#: Rows a streamed run keeps in memory for its plot: all samples up to this many, else the
#: min/max envelope of groups of k samples in at most this many rows.
PREVIEW_SAMPLES = 200_000
#: Share of the available memory a result may take before a run without a sink is refused.
MEMORY_SHARE = 0.5
#: Longest run qzs starts [s], at the best speed its kernel steps at
#: (:data:`BEST_STEP_SECONDS`): a run estimated longer is refused before it starts.
LONGEST_RUN = 86_400.0
#: Wall time of one step of one case at the best speed measured on the development machines
#: [s], by kernel: the single axis, a lane of the lockstep batch, the six-leg platform. The
#: refusal of absurd runs takes them as a lower bound of what a run will take.
BEST_STEP_SECONDS = {"single": 30e-9, "lanes": 10e-9, "hexapod": 300e-9}


class Stepper:
    """What the driver needs of a kernel: the dynamics plugged into the one run loop.

    A subclass holds its kernel's state and output buffers and implements
    :meth:`advance`; the driver calls it from a worker thread, one chunk at a time.

    Attributes
    ----------
    diverged : bool
        Set by :meth:`advance` when the state diverged; the run then ends.
    """

    diverged = False

    def advance(self, steps, buffer, row0):
        """Advance ``steps`` integration steps, recording into ``buffer`` from row ``row0``.

        Parameters
        ----------
        steps : int
            Integration steps [-] (0 compiles or loads the kernel and does nothing).
        buffer : int
            Which of the recorder's buffers the kernel writes.
        row0 : int
            First row to write.

        Returns
        -------
        int
            Output rows written.
        """
        raise NotImplementedError

    def divergence(self):
        """The error to raise after :attr:`diverged` was set (a :class:`SimulationError`)."""
        raise NotImplementedError


@dataclass(frozen=True, kw_only=True)
class RunPlan:
    """How a run is cut: its steps, samples and chunk.

    Attributes
    ----------
    steps : int
        Integration steps of the run [-].
    decimation : int
        Integration steps per output sample [-].
    samples : int
        Output samples, the one at t = 0 included [-].
    chunk : int
        Integration steps per kernel call [-]: a multiple of :data:`PHASE_PERIOD`, and of
        ``decimation`` where that fits in the step bound (then every call writes the same
        number of samples).
    """

    steps: int
    decimation: int
    samples: int
    chunk: int

    @property
    def chunk_samples(self):
        """Most output rows one kernel call writes [-]."""
        return self.chunk // self.decimation + 1


def chunk_steps(decimation, max_steps, max_samples, affordable=None, phase_period=PHASE_PERIOD):
    """Integration steps per kernel call [-]: the one rule for every driver.

    A whole number of :data:`PHASE_PERIOD` (the excitation's sine and cosine are exact
    on those steps), so that cutting a run into calls changes no bit; and a whole number
    of output samples, ``lcm(decimation, PHASE_PERIOD)`` steps, unless that many steps
    are more than a call can afford: then as many steps as it affords (a run with very
    few samples then writes some chunks without a sample).

    Parameters
    ----------
    decimation : int
        Integration steps per output sample [-].
    max_steps : int
        Most steps per call [-].
    max_samples : int
        Most output samples per call [-] (the buffer).
    affordable : int, optional
        Most steps a call may take whatever its samples [-] (progress and Ctrl-C
        granularity); default ``max_steps``.
    phase_period : int
        The kernel's exact-phase grid [steps]; 1 for a kernel that carries its phase
        across calls (the six-leg kernel).

    Returns
    -------
    int
        Positive.
    """
    decimation = int(decimation)
    affordable = int(max_steps if affordable is None else affordable)
    unit = math.lcm(decimation, phase_period)
    if unit > affordable:  # not even one sample's steps fit: bound the steps only
        return phase_period * max(1, affordable // phase_period)
    steps = min(int(max_steps), affordable, int(max_samples) * decimation)
    return unit * max(1, steps // unit)


def plan_run(duration, dt, decimation, *, kernel="single", cases=1, workers=1,
             max_samples=None, max_steps=None, phase_period=PHASE_PERIOD):
    """The plan of a run, refused before it starts if it would take absurdly long.

    Parameters
    ----------
    duration : float
        Simulated time [s].
    dt : float
        Integration step [s].
    decimation : int
        Integration steps per output sample [-].
    kernel : {"single", "lanes", "hexapod"}
        Which kernel steps (its best speed, :data:`BEST_STEP_SECONDS`, bounds the estimate
        and scales the chunk).
    cases : int
        Cases stepped together [-] (a batch's).
    workers : int
        Threads the cases are shared over [-].
    max_samples : int, optional
        Most output samples per chunk [-] (over all cases of a thread); default
        :data:`CHUNK_SAMPLES`.
    max_steps : int, optional
        Most steps per chunk [-], below the bound the kernel's cost sets. The batch gives
        its run's steps: its statistics are summed chunk by chunk, and the same cuts give
        the same bits.
    phase_period : int
        The kernel's exact-phase grid [steps] (:func:`chunk_steps`).

    Returns
    -------
    RunPlan

    Raises
    ------
    RunTooLongError
        The run would take more than :data:`LONGEST_RUN` even at the kernel's best speed.
    """
    steps = int(round(duration / dt))
    per_step = BEST_STEP_SECONDS[kernel] * cases / max(1, min(workers, cases))
    if steps * per_step > LONGEST_RUN:
        raise RunTooLongError(steps=steps, seconds=steps * per_step, limit=LONGEST_RUN,
                              duration=duration, dt=dt, cases=cases)
    # a thread's share of a chunk costs about what CHUNK_STEPS single-axis steps cost
    share = max(1, math.ceil(cases / max(1, workers)))
    relative = BEST_STEP_SECONDS[kernel] * share / BEST_STEP_SECONDS["single"]
    affordable = max(PHASE_PERIOD, int(CHUNK_STEPS / relative))
    chunk = chunk_steps(decimation, affordable if max_steps is None else max_steps,
                        max(1, CHUNK_SAMPLES if max_samples is None else max_samples),
                        affordable, phase_period)
    return RunPlan(steps=steps, decimation=int(decimation), samples=steps // decimation + 1,
                   chunk=chunk)


# ---------------------------------------------------------------- memory
def available_memory():
    """Memory the system can give without swapping [bytes] (None where unknown)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_memory(needed, duration, sample_rate, remedy=None):
    """Refuse a result of ``needed`` bytes that would take more than :data:`MEMORY_SHARE`.

    Parameters
    ----------
    needed : int
        Bytes the result would hold [bytes].
    duration : float
        The run's simulated time [s] (for the message).
    sample_rate : float
        The run's output rate [Hz] (for the message).
    remedy : str, optional
        What the caller can do instead (the message's end); default streaming to a file.

    Raises
    ------
    ResultTooLargeError
    """
    available = available_memory()
    if available is not None and needed > MEMORY_SHARE * available:
        raise ResultTooLargeError(needed, available, duration, sample_rate, remedy=remedy)


# ---------------------------------------------------------------- where the samples go
def envelope_rows(data, flags, first, every):
    """A block's min/max envelope, for the preview of a streamed run.

    Per group of ``every`` samples (counted from the run's start, sample ``first`` being
    the block's first), a row of each channel's minimum (at the group's first time) and one
    of its maximum (at its last time); the flags are all/any.

    Parameters
    ----------
    data : ndarray, shape (n, channels)
        The block's samples.
    flags : ndarray of bool, shape (n, flag count)
        Its flags.
    first : int
        Index of the block's first sample in the run [-].
    every : int
        Samples per group [-].

    Returns
    -------
    rows : ndarray, shape (2 * groups, channels)
    flags : ndarray of bool, shape (2 * groups, flag count)
        Two rows per group, in time order.
    """
    n = data.shape[0]
    # the groups: the end of one begun before the block, whole ones, the start of one more;
    # the whole ones reduced as a (groups, every, channels) view (reduceat over the block's
    # group starts gives the same values, in the same order of comparison, 1.6x slower)
    head = min((-first) % every, n)
    whole = (n - head) // every
    cuts = [(0, head, 1)] if head else []
    if whole:
        cuts.append((head, head + whole * every, whole))
    if head + whole * every < n:
        cuts.append((head + whole * every, n, 1))
    groups = sum(count for _, _, count in cuts)
    rows = np.empty((2 * groups, data.shape[1]))
    marks = np.empty((2 * groups, flags.shape[1]), dtype=np.bool_)
    at = 0
    for start, stop, count in cuts:
        values = data[start:stop].reshape(count, -1, data.shape[1])
        marked = flags[start:stop].reshape(count, -1, flags.shape[1])
        np.minimum.reduce(values, axis=1, out=rows[2 * at:2 * (at + count):2])
        np.maximum.reduce(values, axis=1, out=rows[2 * at + 1:2 * (at + count):2])
        np.logical_and.reduce(marked, axis=1, out=marks[2 * at:2 * (at + count):2])
        np.logical_or.reduce(marked, axis=1, out=marks[2 * at + 1:2 * (at + count):2])
        at += count
    return rows, marks


class Recorder:
    """Where a run's samples go: all in memory, or a sink and a min/max preview.

    Without a sink every sample is kept in one array, allocated once after
    :func:`check_memory` allowed it. With a sink each chunk is written to one of two
    buffers (the kernel fills one while the other is written) and handed to
    ``sink(data, flags)``; the result keeps every sample if there are at most
    :data:`PREVIEW_SAMPLES`, else per group of k samples one row of each channel's
    minimum and one of its maximum (a group that a chunk boundary cuts is merged), so
    that a figure shows the true envelope and never an aliased pick. The preview too is
    one array allocated at the start (at most :data:`PREVIEW_SAMPLES` rows), filled in
    place: a streamed run's memory does not grow with its duration, and its result is a
    view of it, never a copy.

    Parameters
    ----------
    plan : RunPlan
        The run's plan.
    channels, flags : int
        Float channels and boolean flags per sample [-].
    statistics : callable
        ``statistics(data, flags)`` receives every block of new samples (the summary's
        statistics cover every sample, also of a streamed run).
    sink : callable, optional
        ``sink(data, flags)`` receives every block of samples, in time order (reused
        buffers: consume or copy them).
    duration, sample_rate : float
        The run's simulated time [s] and output rate [Hz] (for the memory message).
    remedy : str, optional
        The memory message's advice (:func:`check_memory`).
    """

    def __init__(self, plan, channels, flags, *, statistics, sink=None, duration=0.0,
                 sample_rate=0.0, remedy=None):
        self.sink = sink
        self.statistics = statistics
        n_out = plan.samples
        if sink is None:
            check_memory(n_out * (8 * channels + flags), duration, sample_rate, remedy)
            self.every = 1
            rows = n_out
        else:
            self.every = 1 if n_out <= PREVIEW_SAMPLES else -(-n_out // (PREVIEW_SAMPLES // 2))
            rows = min(n_out, plan.chunk_samples)
            kept = n_out if self.every == 1 else 2 * -(-n_out // self.every)
            self._preview = (np.empty((kept, channels)),
                             np.zeros((kept, flags), dtype=np.bool_))
        self.buffers = [(np.empty((rows, channels)), np.zeros((rows, flags), dtype=np.bool_))]
        if sink is not None:  # two buffers: the kernel fills one while the other is written
            self.buffers.append((np.empty_like(self.buffers[0][0]),
                                 np.zeros_like(self.buffers[0][1])))
        self.rows = 0

    def target(self, chunk_index, rows):
        """Where the kernel writes a chunk: which buffer, from which row.

        Parameters
        ----------
        chunk_index : int
            The chunk's index in the run [-] (streamed chunks alternate buffers).
        rows : int
            Output rows written before the chunk [-].

        Returns
        -------
        (int, int)
            The buffer's index and the first row.
        """
        if self.sink is None:
            return 0, rows
        return chunk_index % 2, 0

    def absorb(self, buffer, first, count):
        """Take new samples: to the statistics, and to the sink and preview when streaming.

        Parameters
        ----------
        buffer : int
            The buffer the kernel wrote.
        first : int
            Its first new row [-].
        count : int
            New rows, which follow every sample taken before [-].
        """
        data, marks = self.buffers[buffer]
        block, block_flags = data[first:first + count], marks[first:first + count]
        self.statistics(block, block_flags)
        if self.sink is not None:
            self.sink(block, block_flags)
            preview, preview_flags = self._preview
            if self.every == 1:
                preview[self.rows:self.rows + count] = block
                preview_flags[self.rows:self.rows + count] = block_flags
            elif count:
                self._envelope(block, block_flags)
        self.rows += count

    def _envelope(self, block, block_flags):
        """Write a block's min/max envelope into the preview: rows 2g and 2g + 1 for group
        g of ``every`` samples, a group cut by a block boundary merged with its first
        part (already written there)."""
        rows, marks = envelope_rows(block, block_flags, self.rows, self.every)
        preview, preview_flags = self._preview
        at = 2 * (self.rows // self.every)
        if self.rows % self.every:  # the group the last block ended in goes on here
            rows[0] = np.minimum(rows[0], preview[at])
            rows[1] = np.maximum(rows[1], preview[at + 1])
            marks[0] &= preview_flags[at]
            marks[1] |= preview_flags[at + 1]
        preview[at:at + len(rows)] = rows
        preview_flags[at:at + len(rows)] = marks

    def result(self):
        """``(data, flags)``: every sample, or the preview of a streamed run (views)."""
        if self.sink is None:
            data, marks = self.buffers[0]
            return data[:self.rows], marks[:self.rows]
        preview, preview_flags = self._preview
        kept = self.rows if self.every == 1 else 2 * -(-self.rows // self.every)
        return preview[:kept], preview_flags[:kept]


# ---------------------------------------------------------------- signals
class DeferredInterrupt:
    """While a run goes on, Ctrl-C and SIGTERM ask it to stop after the chunk under way.

    A KeyboardInterrupt raised in the middle of writing a chunk would leave it
    half-written (its statistics counted, its rows not in the file); the handler only
    sets :attr:`requested`, which the driver checks between chunks. ``interruptible``
    runs take SIGINT over (Ctrl-C then ends the run early and keeps what was simulated);
    where SIGTERM has a Python handler (the command line turns it into
    :class:`~qzs.errors.Terminated`) it is deferred the same way and :attr:`terminated`
    holds its number, for the driver to raise between chunks. Installed only in the main
    thread (where Python runs signal handlers), restored afterwards.

    Parameters
    ----------
    interrupt : bool
        Take over SIGINT too (an interruptible run); else only SIGTERM is deferred.
    """

    def __init__(self, interrupt=True):
        self.interrupt = interrupt
        self.requested = False
        self.terminated = 0
        self._previous = {}

    def _handler(self, signum, frame):
        self.requested = True
        if signum == signal.SIGTERM:
            self.terminated = signum

    def install(self):
        """Take the signals over (main thread only)."""
        if threading.current_thread() is not threading.main_thread():
            return
        if self.interrupt:
            self._previous[signal.SIGINT] = signal.signal(signal.SIGINT, self._handler)
        if callable(signal.getsignal(signal.SIGTERM)):
            self._previous[signal.SIGTERM] = signal.signal(signal.SIGTERM, self._handler)

    def restore(self):
        """Give the signals back to the handlers they had."""
        for signum, previous in self._previous.items():
            signal.signal(signum, previous)
        self._previous = {}


def _collect(future):
    """The rows a kernel call wrote once it has ended, and whether Ctrl-C came meanwhile.

    The kernel cannot be stopped (it holds no GIL and checks no signal): after Ctrl-C it
    is waited for, which takes at most a chunk, so that the rows it wrote are kept.
    """
    stopped = False
    while True:
        try:
            wait([future])
            break
        except KeyboardInterrupt:
            stopped = True
    return future.result(), stopped


# ---------------------------------------------------------------- the loop
@dataclass(frozen=True, kw_only=True)
class Outcome:
    """How a run ended.

    Attributes
    ----------
    completed : bool
        False if Ctrl-C ended an interruptible run early.
    elapsed : float
        Wall time of the integration [s] (compiling or loading the kernel not counted).
    """

    completed: bool
    elapsed: float


def drive(stepper, plan, recorder, *, progress=None, interruptible=False):
    """Integrate a run, chunk by chunk: the one run loop of the engine.

    Parameters
    ----------
    stepper : Stepper
        The dynamics; its state carries the run between chunks.
    plan : RunPlan
        Steps and chunk (:func:`plan_run`).
    recorder : Recorder
        Where the samples go; the sample at t = 0 must already be in it.
    progress : str, optional
        A progress bar over the steps with this description; None for none.
    interruptible : bool
        Ctrl-C ends the run after the chunk under way (``completed`` False) instead of
        raising ``KeyboardInterrupt``.

    Returns
    -------
    Outcome

    Raises
    ------
    SimulationError
        The stepper diverged (:meth:`Stepper.divergence`).
    Terminated
        SIGTERM came (where it has a Python handler), after the chunk under way.
    """
    bar = None
    if progress:
        from qzs.engine.progress import progress_bar

        bar = progress_bar(total=plan.steps, unit="step", unit_scale=True, desc=progress,
                           leave=False)
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="qzs-kernel")
    deferred = DeferredInterrupt(interrupt=interruptible)
    completed, interrupted, start = True, False, None
    done, index = 0, 0

    def launch():
        steps = min(plan.chunk, plan.steps - done)
        buffer, row0 = recorder.target(index, recorder.rows + pending_rows)
        return pool.submit(stepper.advance, steps, buffer, row0), steps, buffer, row0

    try:
        deferred.install()
        # a zero-step call compiles (or loads) the kernel: the clock counts integration only
        _collect(pool.submit(stepper.advance, 0, 0, 0))
        start = _time.perf_counter()
        pending_rows = 0
        current = launch() if plan.steps > 0 else None
        while current is not None:
            future, steps, buffer, row0 = current
            written, stopped = _collect(future)
            interrupted = interrupted or stopped or deferred.requested
            done += steps
            index += 1
            current = None
            if not stepper.diverged and not interrupted and done < plan.steps:
                pending_rows = written  # the next chunk writes after this one's rows
                current = launch()
            recorder.absorb(buffer, row0, written)
            pending_rows = 0
            if stepper.diverged:
                raise stepper.divergence()
            if bar is not None:
                bar.update(steps)
        if deferred.terminated:
            raise Terminated(deferred.terminated)
        if interrupted and done < plan.steps:  # a signal during the last chunk ends nothing
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        if not interruptible:
            raise
        completed = False
    finally:
        deferred.restore()
        pool.shutdown(wait=True)
        if bar is not None:
            bar.close()
    elapsed = 0.0 if start is None else _time.perf_counter() - start
    return Outcome(completed=completed, elapsed=elapsed)
