"""A run's figure drawn in a second process while this one integrates and writes the file.

A run streamed to a file (:func:`qzs.workflows.run.simulate_to_file`) keeps this process's
main thread busy writing while a thread integrates; its figure (matplotlib's import, then
layout, text and rendering: about a second) used to follow, matplotlib's import competing
with the writing for the interpreter. :func:`simulate_with_figure` forks a helper
(:func:`figure_helper`, a :class:`~qzs.workflows.forked.Forked`) before the run: it
imports matplotlib and warms its fonts and mathtext on the second core while the run goes on, then draws the preview this process
sends it when the run ends (:meth:`SimulationResult.plot`'s figure, the same bytes), while
this process closes its file; the bytes come back and are written here, atomically. A
failed helper falls back to drawing here; an interrupted run is drawn here too.

The helper holds no file, ignores Ctrl-C, is killed and waited for whenever this process
stops early and dies with it (:mod:`qzs.workflows.forked`), so an interrupt leaves neither
a temporary file nor an orphan.

>>> from qzs.engine.run_spec import resolve
>>> from qzs.workflows.figure_process import simulate_with_figure
>>> result = simulate_with_figure(resolve(), out="run.nc",
...                               plot="run.png")  # doctest: +SKIP
"""
from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from qzs.workflows import forked
from qzs.workflows.run import simulate_to_file

if TYPE_CHECKING:
    from qzs.engine.result import SimulationResult
    from qzs.engine.run_spec import ResolvedRun

__all__ = ["simulate_with_figure", "figure_helper"]

#: What the helper draws once, while it waits, so that fonts, glyphs and the mathtext
#: parser are loaded before the run's figure (labels of :func:`plot_simulation`'s kind).
_WARM_UP_LABELS = ("displacement [mm]", "acceleration [m/s$^2$]", "time [s]")


def _agg():
    """matplotlib without a window: the figure goes back as bytes."""
    import matplotlib

    matplotlib.use("Agg")


def _warm_up(suffix):
    """Draw a throw-away figure: matplotlib's fonts, glyph and text caches are then warm."""
    _agg()
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


def _draw(suffix, result):
    """The helper's job: the run's figure file as bytes (:meth:`SimulationResult.plot`'s)."""
    _agg()
    from qzs.viz.figures import figure_bytes
    from qzs.viz.simulation import plot_simulation

    return figure_bytes(plot_simulation(result), suffix)


def figure_helper(suffix: str) -> forked.Forked:
    """A :class:`~qzs.workflows.forked.Forked` helper that warms matplotlib up and draws
    the run it is sent into a figure file's bytes.

    Parameters
    ----------
    suffix : str
        The figure's format, a file suffix (``".png"``, ``".svg"``, ``".pdf"``).

    Returns
    -------
    Forked
        Its :meth:`~qzs.workflows.forked.Forked.result` is the file's bytes.
    """
    return forked.Forked(partial(_draw, suffix), prepare=partial(_warm_up, suffix),
                         name="qzs-figure")


def simulate_with_figure(resolved: ResolvedRun, *, out: str | Path | None = None,
                         plot: str | Path | None = None, progress: bool = False,
                         interruptible: bool = False, argument: str = "--out",
                         parallel: bool | None = None) -> SimulationResult:
    """Simulate a resolved run, stream it to ``out`` and write its figure to ``plot``.

    With a file and a figure, the figure is drawn by a :func:`figure_helper` on the second
    core (``parallel``; default where :func:`qzs.workflows.forked.available`): matplotlib loads
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
        :func:`qzs.workflows.forked.available`.

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
        parallel = out is not None and forked.available()
    helper = figure_helper(Path(plot).suffix) if parallel and plot is not None else None
    # without a helper, matplotlib (0.3-0.5 s) loads in a thread while the kernel integrates;
    # joined before returning, so that no import is left half done
    loading = (import_in_background("matplotlib.pyplot", "qzs.viz.simulation")
               if plot is not None and helper is None else None)

    def simulated(result):  # the samples are all in: drawing starts while the file closes
        if helper is not None and result.completed:
            helper.send(result)

    drawn = None
    try:
        if out is not None:
            result = simulate_to_file(out, resolved=resolved, progress=progress,
                                      interruptible=interruptible, argument=argument,
                                      on_simulated=simulated)
        else:
            result = resolved.simulate(progress=progress, interruptible=interruptible)
            simulated(result)
        if helper is not None and result.completed:
            try:
                drawn = helper.result()
            except Exception:  # noqa: BLE001 - the helper failed or died: drawn here
                drawn = None
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
