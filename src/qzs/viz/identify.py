"""Figures of the identification: the spring fit, the friction fit, a transmissibility fit."""
import numpy as np

from qzs.viz.figures import new_figure, save_figure
from qzs.viz.transmissibility import plot_transmissibility

__all__ = ["plot_spring_fit", "plot_spring_law_fit", "plot_friction_fit",
           "plot_transmissibility_fit"]


def plot_spring_fit(displacement, force, spring_force, spring_shape, *, path=None, title=""):
    """MagSpring force against displacement with its tanh fit (paper Fig. 5).

    Parameters
    ----------
    displacement : array_like
        Spring displacement z [m] of the measured points.
    force : array_like
        Measured spring force [N].
    spring_force : float
        Fitted force amplitude a [N].
    spring_shape : float
        Fitted shape coefficient b [1/m].
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(1, height=3.8)
    ax = axes[0]
    z = np.linspace(np.min(displacement), np.max(displacement), 400)
    ax.plot(np.asarray(displacement) * 1e3, force, "o", ms=3.5, label="measured (synthetic)")
    ax.plot(z * 1e3, -spring_force * np.tanh(spring_shape * z), "-",
            label=f"fit: a = {spring_force:.2f} N, b = {spring_shape:.2f} 1/m")
    ax.set_xlabel("relative position z [mm]")
    ax.set_ylabel("spring force [N]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(title)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig


def plot_spring_law_fit(fit, *, path=None, title=""):
    """Force against displacement with the fitted law (and the other candidates of a
    ``law="best"`` fit, dashed), and the residuals against displacement.

    Parameters
    ----------
    fit : SpringFit or LawFit
        The fit (:func:`qzs.identify.fit_spring`, or one law of it: a
        :class:`~qzs.identify.spring_laws.LawFit`, which has no candidates).
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(2, height=3.0, height_ratios=(2.0, 1.0))
    top, bottom = axes
    z, force = fit.displacement, fit.force
    grid = np.linspace(z.min(), z.max(), 801)
    top.plot(z * 1e3, force, "o", ms=3.5, mfc="none", color="0.35", zorder=3,
             label=f"measured ({fit.n_points})")
    candidates = getattr(fit, "candidates", {})
    for kind, other in candidates.items():
        if kind != fit.kind:
            top.plot(grid * 1e3, other.predict(grid), "--", lw=1.0,
                     label=f"{kind}: BIC {other.criterion:.1f}")
    chosen = f", BIC {fit.criterion:.1f}" + (" (chosen)" if candidates else "")
    top.plot(grid * 1e3, fit.predict(grid), "-", color="C3", lw=1.4,
             label=f"{fit.kind} fit: rms residual {fit.residual_rms:.3g} N{chosen}")
    margin = 0.15 * max(np.ptp(force), 1e-9)  # a far-off candidate does not squash the data
    top.set_ylim(force.min() - margin, force.max() + margin)
    top.set_ylabel("spring force on the payload F [N]")
    top.legend(fontsize="small")
    bottom.plot(z * 1e3, fit.residual, "o", ms=3, color="C0")
    bottom.axhline(0.0, color="k", lw=0.6)
    for sign in (-1.0, 1.0):
        bottom.axhline(sign * fit.residual_rms, color="C3", lw=0.6, ls=":")
    bottom.set_xlabel("relative position z [mm] (model convention)")
    bottom.set_ylabel("residual [N]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    top.set_title(title)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig


def plot_friction_fit(fit, *, path=None, title=""):
    """Friction force against velocity with the fitted law, and the residuals against time.

    Parameters
    ----------
    fit : FrictionFit
        The fit (:func:`qzs.identify.fit_friction`).
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(2, height=3.0, sharex=False)
    top, bottom = axes
    v, used = fit.velocity, fit.used
    top.plot(v[~used] * 1e3, fit.friction[~used], ".", ms=2, color="0.7",
             label=f"excluded (stick, {fit.n_excluded})")
    top.plot(v[used] * 1e3, fit.friction[used], ".", ms=2, color="C0",
             label=f"measured ({fit.n_used})")
    grid = np.linspace(v.min(), v.max(), 801)
    grid = np.concatenate([grid[grid < 0], [np.nan], grid[grid > 0]])  # break at v = 0
    top.plot(grid * 1e3, -fit.friction_force(grid), "-", color="C3", lw=1.2,
             label=(f"fit: Fs = {fit.stiction_force:.3g} N, Fc = {fit.coulomb_force:.3g} N, "
                    f"Cbc = {fit.stribeck_decay:.3g} s/m, Cv = {fit.viscous_damping:.3g} N*s/m"))
    top.set_xlabel("velocity v [mm/s]")
    top.set_ylabel("force against friction -F_friction [N]")
    top.legend(fontsize="small", loc="upper left")
    bottom.plot(fit.time, fit.residual, ".", ms=2, color="C0")
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.set_xlabel("time [s]")
    bottom.set_ylabel(f"residual [N] (rms {fit.residual_rms:.3g})")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    top.set_title(title)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig


def plot_transmissibility_fit(fit, *, path=None, title="", frequency_scale=None):
    """Measured and fitted transmissibility curves of a :class:`~qzs.identify.TransmissibilityFit`.

    Parameters
    ----------
    fit : TransmissibilityFit
        The fit.
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str
        Figure title.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fitted = ", ".join(f"{k} = {v:.3g}" for k, v in fit.parameters.items())
    curves = [{"label": "measured", "frequency": fit.frequency, "magnitude": fit.measured},
              {"label": f"fitted model ({fitted})", "frequency": fit.frequency,
               "magnitude": fit.fitted}]
    return plot_transmissibility(curves, frequency_range=(0.0, float(fit.frequency[-1])),
                                 frequency_scale=frequency_scale, title=title, path=path)
