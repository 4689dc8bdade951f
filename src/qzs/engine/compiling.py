"""Say so while the kernels compile: a notice at once, then the seconds, until they are cached.

numba compiles a kernel the first time it runs on this machine (an empty cache: the first run
after installing qzs, or after an edit of a kernel source dropped the cache, see
:mod:`qzs.engine.arithmetic`), which takes 10-25 s per family of kernels, and caches it on
disk; later runs load it in well under a second. :func:`compile_notice` listens to numba's
compile events (``numba:compile``, sent only when a kernel really compiles, never when it is
loaded from the cache): the first compile of a qzs kernel prints, at once, ::

    qzs: compiling the kernels once (about 15 s; later runs start in about 1 s): 1 2 3 s

and while any kernel compiles the seconds since then follow, one a second: at the end of
that line (`` 1 2 3 ...``, the line ends with the compile), or, while a progress bar is
shown, in the bar's postfix (``compiling the kernels once, 7 s of about 15``; the estimate
grows when the first kernels took longer than expected, as on a busy machine). A run from
a warm cache prints nothing and costs nothing (no event comes).

The estimate is the sum of :data:`COMPILE_SECONDS` over the family's entry kernels
(:data:`ENTRY_KERNELS`, the kernels Python calls; their callees compile within them) whose
cache holds no entry for this machine (:func:`cold_kernels`), times how much slower the
machine is now than quiet (:func:`slowdown`: a compile runs on one core, and shares it with
the other runnable processes). As each entry kernel is compiled, the estimate of the rest
follows from the seconds the ones done really took in compiling (the time between
compiles, when the run itself goes on, not counted).
"""
import importlib
import os
import sys
import threading
import time
from contextlib import contextmanager

__all__ = ["ENTRY_KERNELS", "COMPILE_SECONDS", "NOTICE", "cold_kernels", "estimate",
           "slowdown", "compile_notice"]

#: Kernel family -> the kernels Python calls (``module.function``), in the order a run
#: compiles them. ``single``: one case (:func:`qzs.simulate`, the response's periodic runs);
#: ``batch``: cases in lockstep (:func:`qzs.simulate_batch`: sweeps, studies, design);
#: ``single_blocks``: one case of a controller with blocks beyond PI + damping, or of a spring
#: law other than the tanh (the general
#: kernel, :func:`qzs.engine.lanes.run_single_blocks`); ``hexapod``: the six-leg platform
#: (:func:`qzs.simulate_hexapod`).
ENTRY_KERNELS = {
    "single": ("qzs.engine.base_motion._series", "qzs.engine.kernels.hold_force",
               "qzs.engine.kernels.evaluate", "qzs.engine.lanes.run_single"),
    "single_blocks": ("qzs.engine.base_motion._series", "qzs.engine.kernels.hold_force",
                      "qzs.engine.kernels.evaluate", "qzs.engine.lanes.run_single_blocks"),
    "batch": ("qzs.engine.lanes.run_lanes",),
    "hexapod": ("qzs.engine.hexapod.dynamics._rest_frame",
                "qzs.engine.hexapod.dynamics._evaluate", "qzs.engine.hexapod.stepping._start",
                "qzs.engine.hexapod.stepping._run"),
}
#: Wall seconds each entry kernel takes to compile on a quiet 2-core VM (with what it calls
#: and what the kernels before it in :data:`ENTRY_KERNELS` left compiled): their compile CPU
#: seconds (numba's compile events) scaled to the cold commands measured on 2026-11-26
#: (benchmarks/README.md, "Cold start"); the batch kernel's from CONTRIBUTING.md's earlier
#: figure. Their ratios hold on a busy machine (each kernel 4-6 times slower at a load of 6
#: on 2 cores); the notice multiplies them by :func:`slowdown`. Checked cold on 2026-11-28 at
#: a load of 6 on 2 cores: ``qzs simulate`` said about 50 s and compiled for 45 s,
#: ``qzs hexapod study --quick`` said about 65 s and compiled for 87 s. ``run_single_blocks``:
#: ``run_single``'s times the ratio of their compile CPU seconds, each compiled alone with the
#: rest cached (59.8 s against 48.6 s at a load of 9 on 2 cores, 2026-11-29).
COMPILE_SECONDS = {
    "qzs.engine.base_motion._series": 0.6, "qzs.engine.kernels.hold_force": 1.2,
    "qzs.engine.kernels.evaluate": 1.7, "qzs.engine.lanes.run_single": 9.5,
    "qzs.engine.lanes.run_single_blocks": 11.7,
    "qzs.engine.lanes.run_lanes": 30.0,
    "qzs.engine.hexapod.dynamics._rest_frame": 0.2, "qzs.engine.hexapod.dynamics._evaluate": 9.0,
    "qzs.engine.hexapod.stepping._start": 4.0, "qzs.engine.hexapod.stepping._run": 6.0,
}
#: The notice, with the estimate in whole seconds.
NOTICE = "qzs: compiling the kernels once (about {seconds} s; later runs start in about 1 s)"
#: Seconds between two signs of life while compiling.
TICK = 1.0


def _dispatcher(name):
    module, _, function = name.rpartition(".")
    return getattr(importlib.import_module(module), function)


def cold_kernels(families):
    """The entry kernels of ``families`` that would compile: neither loaded nor cached here.

    Reads each kernel's cache index (a few hundred bytes) and looks for an entry compiled
    for this machine (numba's target triple, CPU name and features); compiles nothing.

    Parameters
    ----------
    families : iterable of str
        Keys of :data:`ENTRY_KERNELS`.

    Returns
    -------
    list of str
        ``module.function`` names, in :data:`ENTRY_KERNELS` order; a kernel whose cache
        cannot be read counts as cold.
    """
    cold = []
    for name in dict.fromkeys(name for family in families for name in ENTRY_KERNELS[family]):
        try:  # a kernel two families share counts once
            dispatcher = _dispatcher(name)
            if dispatcher.overloads:
                continue
            index = dispatcher._cache._cache_file._load_index()
            machine = dispatcher.targetctx.codegen().magic_tuple()
            if any(key[1] == machine for key in index):
                continue
        except Exception:  # another numba's internals: say so rather than stay silent
            pass
        cold.append(name)
    return cold


def slowdown(load=None, cores=None):
    """How many times slower than on a quiet machine a compile runs now.

    A compile is one thread: with ``load`` runnable processes (the 1-minute load average)
    on ``cores`` cores it gets ``cores / (load + 1)`` of a core when that is below one.

    Parameters
    ----------
    load : float, optional
        Runnable processes on average; default the machine's 1-minute load average
        (:func:`os.getloadavg`; none where it is not known).
    cores : int, optional
        Cores this process may run on; default those of its affinity.

    Returns
    -------
    float
        At least 1.
    """
    if load is None:
        try:
            load = os.getloadavg()[0]
        except (AttributeError, OSError):  # not known here (Windows)
            return 1.0
    if cores is None:
        try:
            cores = len(os.sched_getaffinity(0))
        except AttributeError:
            cores = os.cpu_count() or 1
    return max(1.0, (load + 1.0) / max(cores, 1))


def estimate(kernels, *, factor=1.0):
    """Seconds the ``kernels`` take to compile, rounded as a person would say it.

    Parameters
    ----------
    kernels : iterable of str
        ``module.function`` names (:func:`cold_kernels`); an unknown one counts 5 s, none
        (a kernel outside :data:`ENTRY_KERNELS` compiles) 5 s.
    factor : float
        How much slower than :data:`COMPILE_SECONDS` (:func:`slowdown`).

    Returns
    -------
    int
        The sum of :data:`COMPILE_SECONDS` times ``factor``, at least 5, to the nearest
        multiple of 5 above 10 s.
    """
    seconds = factor * sum(COMPILE_SECONDS.get(name, 5.0) for name in kernels)
    if seconds <= 10.0:
        return max(5, int(round(seconds)))
    return int(5 * round(seconds / 5.0))


def _progress_bars(stream):
    """The tqdm bars shown on ``stream`` now (none when tqdm is not imported)."""
    tqdm = sys.modules.get("tqdm.std")
    if tqdm is None:
        return []
    return [bar for bar in list(tqdm.tqdm._instances)
            if getattr(bar, "fp", None) is not None and not getattr(bar, "disable", True)
            and getattr(bar.fp, "_wrapped", bar.fp) is stream]


class _Notice:
    """What :func:`compile_notice` runs: numba's compile events in, lines on ``stream`` out."""

    def __init__(self, families, stream, ticking):
        self.families = tuple(families)
        self.stream = stream
        self.ticking = ticking
        self.lock = threading.RLock()
        self.depth = 0  # compiles under way, nested (a kernel compiles what it calls)
        self.first = None  # time of the notice
        self.seconds = None  # the estimate said in the notice
        self.cold = []  # the entry kernels that were to compile
        self.about = None  # the estimate of the whole, rescaled as kernels finish
        self.factor = 1.0  # the machine's slowdown when the notice came
        self.burst = None  # when the compile under way started
        self.compiled = 0.0  # seconds spent compiling, bursts ended
        self.line_open = False  # our own line, ticks appended, not yet ended
        self.ticked = False  # a tick was written on it
        self.bars = []  # the progress bars whose postfix shows the seconds
        self.wake = threading.Event()
        self.stopped = False
        self.ticker = None

    def on_start(self, event):
        dispatcher = event.data.get("dispatcher")
        with self.lock:
            if self.depth == 0:
                module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
                if not module.startswith("qzs."):
                    return
                self.depth = 1
                self._burst_starts()
            else:
                self.depth += 1

    def on_end(self, event):
        with self.lock:
            if self.depth == 0:
                return
            self.depth -= 1
            if self.depth == 0:
                self._burst_ends()

    def _write(self, text):
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):  # a closed stderr: nothing to say it on
            pass

    def _burst_starts(self):
        self.burst = time.perf_counter()
        if self.first is None:
            self.first = self.burst
            self.cold = cold_kernels(self.families)
            self.factor = slowdown()
            self.seconds = self.about = estimate(self.cold, factor=self.factor)
            notice = NOTICE.format(seconds=self.seconds)
            bars = _progress_bars(self.stream)
            if bars or not self.ticking:
                self._write_above(bars, notice + "\n")
            else:
                self._write(notice)
                self.line_open = True
        self.wake.set()

    def _burst_ends(self):
        self.wake.clear()
        if self.burst is not None:
            self.compiled += time.perf_counter() - self.burst
            self.burst = None
        self._rescale()
        self._end_line()
        for bar in self.bars:
            try:
                bar.set_postfix_str("", refresh=True)
            except Exception:  # a bar closed meanwhile
                pass
        self.bars = []

    def _rescale(self):
        """The whole's estimate: the seconds so far, and the rest at the pace the kernels done
        took in compiling (against :data:`COMPILE_SECONDS`)."""
        try:
            done = [name for name in self.cold if _dispatcher(name).overloads]
        except Exception:  # another numba's internals: keep the estimate
            return
        expected = sum(COMPILE_SECONDS.get(name, 5.0) for name in done)
        if expected >= 0.5 and self.compiled > 0.0:
            elapsed = time.perf_counter() - self.first
            rest = sum(COMPILE_SECONDS.get(name, 5.0) for name in self.cold if name not in done)
            self.about = int(elapsed + rest * self.compiled / expected + 0.5)

    def _end_line(self):
        """End our own line: with the unit after the seconds, if any were written."""
        if self.line_open:
            self._write(" s\n" if self.ticked else "\n")
            self.line_open = self.ticked = False

    def _write_above(self, bars, text):
        """``text`` above the progress bars: clear them, write, draw them again (a bar still
        within its ``delay``, not drawn yet, is left alone: clearing it would write a line of
        its own before the text)."""
        now = time.time()  # tqdm's clock
        bars = [bar for bar in bars
                if not (getattr(bar, "delay", 0) and now - getattr(bar, "start_t", now) < bar.delay)]
        for bar in bars:
            bar.clear()
        self._write(text)
        for bar in bars:
            bar.refresh()

    def tick(self):
        """One sign of life: the seconds since the notice, on our line or on the bars."""
        with self.lock:
            if self.depth == 0 or self.first is None:
                return
            seconds = int(time.perf_counter() - self.first + 0.5)
            bars = _progress_bars(self.stream)
            if bars:
                self._end_line()
                for bar in bars:
                    bar.set_postfix_str(f"compiling the kernels once, {seconds} s of about "
                                        f"{max(self.about, seconds)}", refresh=True)
                self.bars = bars
            else:
                if not self.line_open:
                    self._write("qzs: compiling")
                    self.line_open = True
                self._write(f"{'' if self.ticked else ':'} {seconds}")
                self.ticked = True

    def run(self):
        """The ticker thread: :meth:`tick` every :data:`TICK` seconds while compiling."""
        while not self.stopped:
            self.wake.wait()
            if self.stopped:
                return
            time.sleep(TICK)
            self.tick()

    def start(self):
        if self.ticking:
            self.ticker = threading.Thread(target=self.run, name="qzs-compile-notice",
                                           daemon=True)
            self.ticker.start()

    def stop(self):
        with self.lock:
            self.stopped = True
            self.wake.set()
            self._end_line()


@contextmanager
def compile_notice(families, *, stream=None, ticking=True):
    """While inside, say so when a qzs kernel compiles (module docstring), else nothing.

    Parameters
    ----------
    families : iterable of str
        The kernel families (:data:`ENTRY_KERNELS`) the work inside runs: what the estimate
        counts (none: the notice still comes, saying about 5 s).
    stream : file, optional
        Where to write (default ``sys.stderr``).
    ticking : bool
        Show the seconds while compiling; False: the notice line only (``--quiet``).

    Yields
    ------
    None
    """
    from numba.core import event

    class Listener(event.Listener):
        def on_start(self, event):
            notice.on_start(event)

        def on_end(self, event):
            notice.on_end(event)

    notice = _Notice(families, stream or sys.stderr, ticking)
    listener = Listener()
    event.register("numba:compile", listener)
    notice.start()
    try:
        yield
    finally:
        event.unregister("numba:compile", listener)
        notice.stop()
