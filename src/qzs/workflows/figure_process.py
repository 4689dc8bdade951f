"""A run's figure drawn in a second process while this one integrates and writes the file.

A run streamed to a file (:func:`qzs.workflows.run.simulate_to_file`) keeps this process's
main thread busy writing while a thread integrates; its figure (matplotlib's import, then
layout, text and rendering: about a second) used to follow, matplotlib's import competing
with the writing for the interpreter. :func:`simulate_with_figure` forks a helper
(:class:`FigureProcess`) before the run: it imports matplotlib and warms its fonts and
mathtext on the second core while the run goes on, then draws the preview this process
sends it when the run ends (:meth:`SimulationResult.plot`'s figure, the same bytes), while
this process closes its file; the bytes come back and are written here, atomically. A
failed helper falls back to drawing here; an interrupted run is drawn here too.

The helper holds no file and ignores Ctrl-C (it reaches the whole process group); it is
killed, and waited for, whenever this process stops early, and dies with it on Linux
(``PR_SET_PDEATHSIG``), so an interrupt leaves neither a temporary file nor an orphan.

>>> from qzs.engine.run_spec import resolve
>>> from qzs.workflows.figure_process import simulate_with_figure
>>> result = simulate_with_figure(resolve(), out="run.nc",
...                               plot="run.png")  # doctest: +SKIP
"""
from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from qzs.workflows.run import simulate_to_file

if TYPE_CHECKING:
    from qzs.engine.result import SimulationResult
    from qzs.engine.run_spec import ResolvedRun

__all__ = ["simulate_with_figure", "FigureProcess"]

_PR_SET_PDEATHSIG = 1
#: What the helper draws once, while it waits, so that fonts, glyphs and the mathtext
#: parser are loaded before the run's figure (labels of :func:`plot_simulation`'s kind).
_WARM_UP_LABELS = ("displacement [mm]", "acceleration [m/s$^2$]", "time [s]")


def _usable_cpus():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def _die_with_parent():
    """Linux: the kernel sends this process SIGKILL when its parent dies."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover - another libc
        pass


def _warm_up(suffix):
    """Draw a throw-away figure: matplotlib's fonts, glyph and text caches are then warm."""
    import matplotlib.pyplot as plt

    from qzs.viz.figures import figure_bytes, new_figure

    fig, axes = new_figure(2)
    for ax, label in zip(axes, _WARM_UP_LABELS):
        ax.plot([0.0, 1.0], [0.0, 1.0], lw=0.7, label="x")
        ax.set_ylabel(label)
        ax.legend(loc="upper right", fontsize="small", ncols=4)
    axes[-1].set_xlabel(_WARM_UP_LABELS[-1])
    fig.suptitle("warm-up")
    figure_bytes(fig, suffix)
    plt.close(fig)


def _helper(connection, suffix):
    """The second process: import matplotlib and warm it up, receive the run, draw it, send
    ``("ok", bytes)`` back (``("error", text)`` on failure; nothing if told to stop)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C is the parent's to handle
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # it holds no file: it may simply die
    _die_with_parent()
    try:
        import matplotlib

        matplotlib.use("Agg")  # no window: the figure goes back as bytes
        from qzs.viz.figures import figure_bytes
        from qzs.viz.simulation import plot_simulation

        if not connection.poll():  # the run is not over yet: warm up while it goes on
            _warm_up(suffix)
        result = connection.recv()
        if result is not None:
            connection.send(("ok", figure_bytes(plot_simulation(result), suffix)))
    except BaseException as error:  # noqa: BLE001 - reported to the parent, which draws
        try:
            connection.send(("error", f"{type(error).__name__}: {error}"))
        except OSError:
            pass
    finally:
        connection.close()


class FigureProcess:
    """The forked helper that draws one run's figure (see the module's docstring).

    Parameters
    ----------
    suffix : str
        The figure's format, a file suffix (``".png"``, ``".svg"``, ``".pdf"``).
    """

    def __init__(self, suffix: str):
        context = multiprocessing.get_context("fork")
        self._connection, child = context.Pipe()
        for stream in (sys.stdout, sys.stderr):  # nothing buffered is written twice
            stream.flush()
        self._process = context.Process(target=_helper, name="qzs-figure", daemon=True,
                                        args=(child, suffix))
        self._process.start()
        child.close()
        self._sender: threading.Thread | None = None

    @staticmethod
    def available() -> bool:
        """Whether a helper can help: ``fork`` exists and two cores are usable."""
        return "fork" in multiprocessing.get_all_start_methods() and _usable_cpus() >= 2

    @property
    def pid(self) -> int | None:
        """The helper's process id."""
        return self._process.pid

    def draw(self, result: SimulationResult) -> None:
        """Send the run to the helper, which starts drawing it.

        Parameters
        ----------
        result : SimulationResult
            The run (a streamed run's preview: at most
            :data:`~qzs.engine.driver.PREVIEW_SAMPLES` rows).
        """
        def send():
            try:
                self._connection.send(result)
            except OSError:  # the helper is gone: :meth:`figure` says so
                pass

        # in a thread: the helper may still be importing, and this process closes its file
        sender = threading.Thread(target=send, name="qzs-figure-send", daemon=True)
        sender.start()
        self._sender = sender

    def figure(self) -> bytes | None:
        """The figure's file as the helper drew it, or None if it could not; ends the helper.

        Returns
        -------
        bytes or None
            The file's bytes (those :meth:`SimulationResult.plot` writes), or None (the
            helper failed, or :meth:`draw` was not called): draw here instead.
        """
        drawn = None
        try:
            if self._sender is not None:
                self._sender.join()
                status, payload = self._connection.recv()
                if status == "ok" and isinstance(payload, bytes):
                    drawn = payload
        except (EOFError, OSError):  # the helper ended without a figure
            pass
        finally:
            self.close()
        return drawn

    def close(self) -> None:
        """End the helper (killed if still running) and wait for it. Idempotent."""
        if self._process.is_alive():
            self._process.kill()
        self._process.join()
        if self._sender is not None:  # its send fails once the helper is gone
            self._sender.join()
        self._connection.close()


def simulate_with_figure(resolved: ResolvedRun, *, out: str | Path | None = None,
                         plot: str | Path | None = None, progress: bool = False,
                         interruptible: bool = False, argument: str = "--out",
                         parallel: bool | None = None) -> SimulationResult:
    """Simulate a resolved run, stream it to ``out`` and write its figure to ``plot``.

    With a file and a figure, the figure is drawn by a :class:`FigureProcess` on the second
    core (``parallel``; default where :meth:`FigureProcess.available`): matplotlib loads
    there while this process integrates and writes, and the figure is drawn there while
    this process closes the file. The figure's bytes are those of
    :meth:`SimulationResult.plot` either way.

    Parameters
    ----------
    resolved : ResolvedRun
        The run (:func:`qzs.engine.run_spec.resolve`).
    out : str or Path, optional
        The time series' file (``.nc``, ``.csv``, ``.mat``); none: the run stays in memory.
    plot : str or Path, optional
        The figure's file (``.png``, ``.svg``, ``.pdf``); none: no figure.
    progress : bool
        Show a progress bar.
    interruptible : bool
        Ctrl-C ends the run early and keeps what was simulated.
    argument : str
        How the caller names ``out`` in messages.
    parallel : bool, optional
        Draw the figure in a second process; default: when a file and a figure are asked
        for (a run in memory holds every sample: too many to send) and
        :meth:`FigureProcess.available`.

    Returns
    -------
    SimulationResult
        The run (a preview of its samples when streamed, as
        :func:`~qzs.workflows.run.simulate_to_file` returns).

    Raises
    ------
    OutputPathError
        ``out`` cannot be written.
    """
    from qzs._lazy import import_in_background

    if parallel is None:
        parallel = out is not None and FigureProcess.available()
    helper = FigureProcess(Path(plot).suffix) if parallel and plot is not None else None
    # without a helper, matplotlib (0.3-0.5 s) loads in a thread while the kernel integrates;
    # joined before returning, so that no import is left half done
    loading = (import_in_background("matplotlib.pyplot", "qzs.viz.simulation")
               if plot is not None and helper is None else None)

    def simulated(result):  # the samples are all in: drawing starts while the file closes
        if helper is not None and result.completed:
            helper.draw(result)

    drawn = None
    try:
        if out is not None:
            result = simulate_to_file(out, resolved=resolved, progress=progress,
                                      interruptible=interruptible, argument=argument,
                                      on_simulated=simulated)
        else:
            result = resolved.simulate(progress=progress, interruptible=interruptible)
            simulated(result)
        if helper is not None:
            drawn = helper.figure()
    finally:
        if helper is not None:
            helper.close()
        if loading is not None:
            loading.join()
    if plot is not None:
        if drawn is None:
            result.plot(path=plot)
        else:
            from qzs.iotools.files import atomic_path

            with atomic_path(plot) as tmp:
                tmp.write_bytes(drawn)
    return result
