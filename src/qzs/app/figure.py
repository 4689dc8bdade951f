"""The tuning page's figure drawn with matplotlib, for its PNG export (docs/app.md).

The Bokeh toolbar's save button saves one plot at a time; the export draws every panel
of the page into one figure, with the pinned curves, and hands the bytes to the browser:
nothing is written on the server. The figure object is built without ``pyplot``, so it
may be drawn in any thread.
"""
import io

import numpy as np

from qzs.viz.figures import drawn, frequency_axis

__all__ = ["page_figure", "figure_png", "PIN_COLORS", "describe_request"]

#: Colours of pinned curves, in pin order (matplotlib's tab10 after its first two).
PIN_COLORS = ("#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f")
_MM = 1e3


def describe_request(request):
    """One line naming a request's main settings, for titles and pin labels.

    Parameters
    ----------
    request : PageRequest
        The setting.

    Returns
    -------
    str
    """
    isolator, controller = request.isolator, request.controller
    if request.excitation == "chirp":
        run = (f"chirp {request.amplitude * _MM:g} mm, {request.band[0]:g}-{request.band[1]:g} Hz "
               f"in {request.chirp_duration:g} s")
    else:
        run = (f"stepped sine {request.amplitude * _MM:g} mm, {request.frequency_count} "
               f"frequencies, {request.band[0]:g}-{request.band[1]:g} Hz")
    law = "" if isolator.spring is None else f"; {isolator.spring.kind} spring law"
    return (f"Fs = {isolator.stiction_force:g} N, Fc = {isolator.coulomb_force:g} N, "
            f"Kp = {controller.pi_kp:g} N/m, Ki = {controller.pi_ki:g} N/(m s), "
            f"Kd = {controller.damping_gain:g} N s/m; {run}{law}")


def page_figure(data, pinned=()):
    """Every panel of the page in one matplotlib figure.

    Parameters
    ----------
    data : PageData
        What :func:`qzs.app.compute.compute_page` returned.
    pinned : sequence of (str, ndarray, ndarray)
        Pinned curves: label, frequency [Hz], transmissibility [dB].

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(12.0, 8.0), layout="constrained")
    grid = figure.add_gridspec(2, 3)
    axes_t = figure.add_subplot(grid[0, :2])
    axes_locked = figure.add_subplot(grid[0, 2])
    axes_x = figure.add_subplot(grid[1, 0])
    axes_z = figure.add_subplot(grid[1, 1], sharex=axes_x)
    axes_f = figure.add_subplot(grid[1, 2], sharex=axes_x)
    request = data.request

    for (label, frequency, magnitude_db), color in zip(pinned, PIN_COLORS):
        keep = drawn(frequency)
        axes_t.plot(np.asarray(frequency)[keep], np.asarray(magnitude_db)[keep], color=color,
                    lw=1.0, alpha=0.8, label=f"pinned: {label}")
    kind = "chirp (trusted bins)" if request.excitation == "chirp" else "stepped sine"
    shown, linear = drawn(data.frequency), drawn(data.linear_frequency)
    axes_t.plot(data.frequency[shown], data.transmissibility_db[shown], color="#1f77b4", lw=1.6,
                marker="o" if request.excitation == "stepped" else None, ms=4,
                label=f"simulated, {kind}")
    axes_t.plot(data.linear_frequency[linear], data.linear_db[linear], color="#ff7f0e", lw=1.2,
                ls="--", label="linear model")
    axes_t.axhline(0.0, color="0.6", lw=0.6)
    frequency_axis(axes_t, (min(request.band), max(request.band)),
                   np.concatenate([data.frequency[shown], data.linear_frequency[linear]]),
                   label="frequency [Hz]")
    axes_t.set(ylabel="transmissibility [dB]",
               title="Transmissibility, payload over base acceleration")
    axes_t.legend(fontsize=8, loc="best")
    axes_t.grid(alpha=0.3, which="both")

    shares = [100 * data.locked_share["sine"], 100 * data.locked_share["excitation"]]
    names = [f"{request.sine_frequency:g} Hz sine",
             "chirp" if request.excitation == "chirp" else "stepped sine (mean)"]
    axes_locked.bar(names, np.nan_to_num(shares), color=["#1f77b4", "#7f7f7f"])
    axes_locked.set(ylim=(0, 100), ylabel="time locked [%]", title="Locked share")
    for i, share in enumerate(shares):
        axes_locked.text(i, min(np.nan_to_num(share) + 3, 92), f"{share:.1f} %", ha="center")

    time_, base = data.traces["base_displacement"]
    axes_x.plot(time_, base * _MM, color="0.5", lw=0.9, label="base y")
    time_, payload = data.traces["payload_displacement"]
    axes_x.plot(time_, payload * _MM, color="#1f77b4", lw=1.0, label="payload x")
    axes_x.set(xlabel="time [s]", ylabel="displacement from rest [mm]",
               title=f"Response to a {request.sine_frequency:g} Hz, "
                     f"{request.amplitude * _MM:g} mm sine")
    axes_x.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncols=2,
                  frameon=False)  # below the axes: the traces fill the whole frame

    time_, z = data.traces["relative_position"]
    axes_z.plot(time_, z * _MM, color="#1f77b4", lw=1.0, label="relative position z")
    for stop in (data.stop_low, data.stop_high):
        axes_z.axhline(stop * _MM, color="#d62728", lw=1.2)
    axes_z.axhline(data.position_setpoint * _MM, color="0.5", lw=0.8, ls=":")
    axes_z.set(xlabel="time [s]", ylabel="relative position z [mm]",
               title="Stroke used (red: the stops)")

    time_, force = data.traces["motor_force"]
    axes_f.plot(time_, force, color="#1f77b4", lw=1.0)
    for limit in (-data.motor_force_max, data.motor_force_max):
        axes_f.axhline(limit, color="#d62728", lw=1.2)
    axes_f.set(xlabel="time [s]", ylabel="motor force [N]",
               title="Motor force (red: its limit)")
    for axes in (axes_x, axes_z, axes_f):
        axes.grid(alpha=0.3)
    figure.suptitle(describe_request(request), fontsize=10)
    return figure


def figure_png(data, pinned=(), dpi=110):
    """The page's figure as PNG bytes (for a browser download).

    Parameters
    ----------
    data : PageData
        What :func:`qzs.app.compute.compute_page` returned.
    pinned : sequence of (str, ndarray, ndarray)
        Pinned curves: label, frequency [Hz], transmissibility [dB].
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    bytes
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure = page_figure(data, pinned)
    FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()
