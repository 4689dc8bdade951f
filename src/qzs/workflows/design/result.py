"""The design's result: the chosen gains with the evidence for each choice, and its files."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import json_ready, json_text
from qzs._version import __version__
from qzs.errors import DataError
from qzs.iotools.files import atomic_path
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension
from qzs.workflows.paper.curves import curves_dataset, write_curves
from qzs.workflows.design.report import _html, design_text

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.analysis.control_design import RouthHurwitz, StaticDesign

__all__ = ["DesignResult", "write_design"]


@dataclass(frozen=True)
class DesignResult:
    """What :func:`design_controller` found, with the evidence for each choice.

    Attributes
    ----------
    gains : dict
        The chosen ``pi_kp`` [N/m], ``pi_ki`` [N/(m*s)] and ``damping_gain`` [N*s/m].
    settings : dict
        The problem as solved: ranges, force steps, band, cost, rate, delay, step, excitation.
    static : StaticDesign
        The static design at the setpoint.
    pi_search : dict
        The PI search: ``table`` (one row per gain tried), ``pi_kp`` and the failing gain just
        below it, the cases and the band.
    stability : RouthHurwitz
        The linear stability of the chosen gains, closed form against python-control.
    hunting : dict
        Describing-function predictions and simulations at rest, per stiction value.
    damping : dict
        The damping search: a row per gain (``damping_gain`` [N*s/m], simulated and linear
        cost [-], ``motor_force_rms`` [N]), the bound [N*s/m] and why.
    margins : dict
        Margins of the sampled loop at the design's rate and delay, over rates, and the
        rate the design needs.
    why : dict
        The experiments on why damping did not help much, and the answer.
    verification : dict
        Every case of the PI search at the final gains.
    seconds : dict
        Wall time of each stage [s].
    series : dict
        Curves and time series for the figures (not in :meth:`to_dict`).
    """

    gains: dict
    settings: dict
    static: StaticDesign
    pi_search: dict
    stability: RouthHurwitz
    hunting: dict
    damping: dict
    margins: dict
    why: dict
    verification: dict
    seconds: dict
    series: dict = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """Everything but the figures' series, as JSON-ready data (NaN and inf as None).

        Returns
        -------
        dict
        """
        pi = {k: v for k, v in self.pi_search.items() if k != "details"}
        hunting = {k: v for k, v in self.hunting.items() if k != "loop"}
        return json_ready({"qzs_version": __version__, "gains": self.gains,
                           "settings": self.settings, "static": self.static.to_dict(),
                           "pi_search": pi, "stability": self.stability.to_dict(),
                           "hunting": hunting, "damping": self.damping,
                           "margins": self.margins, "why": self.why,
                           "verification": self.verification, "seconds": self.seconds})

    def summary(self) -> str:
        """The design in a few lines of text (what ``qzs design`` prints).

        Returns
        -------
        str
        """
        return design_text(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             figure: str = "static_design", frequency_scale: str | None = None) -> Figure:
        """Draw one figure of the design (:func:`qzs.viz.design.plot_design` draws them all;
        :meth:`save` writes them all).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there too (format from the suffix).
        title : str, optional
            Figure title; default the figure's own.
        figure : str
            Which: ``static_design``, ``pi_search``, ``hunting``, ``damping``, ``margins`` or
            ``damping_effect`` (``pi_search`` and ``damping`` when that search ran).
        frequency_scale : {"log", "linear"}, optional
            Frequency axis of the transmissibility figure; default
            ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        from qzs._validation import choice
        from qzs.viz.design import plot_design
        from qzs.viz.figures import save_figure

        figures = plot_design(self, frequency_scale=frequency_scale)
        for name, other in figures.items():
            if name != figure:
                plt.close(other)
        chosen = figures[choice("figure", figure, tuple(figures))]
        if title is not None:
            chosen.suptitle(title)
        if path is not None:
            save_figure(chosen, path)
        return chosen

    def curves(self) -> xr.Dataset | None:
        """The damping search's transmissibility curves as a dataset, one case per gain tried.

        The curves the ``damping`` figure draws (Kd = 0 and the chosen gain) among them, on
        ``case`` and ``frequency`` (:func:`qzs.workflows.paper.curves.curves_dataset`), with
        ``damping_gain`` [N*s/m], ``pi_kp`` [N/m] and ``pi_ki`` [N/(m*s)] as coordinates.

        Returns
        -------
        xarray.Dataset or None
            None when the search ran no simulation (no admissible damping gain).
        """
        estimates = self.series.get("damping_estimates") or {}
        if not estimates:
            return None
        gains = self.gains
        curves = [{"label": f"Kd = {kd:g} N*s/m", "frequency": e.frequency,
                   "magnitude": e.magnitude, "phase": e.phase, "coherence": e.coherence,
                   "trusted": e.trusted,
                   "parameters": {"damping_gain": kd, "pi_kp": gains["pi_kp"],
                                  "pi_ki": gains["pi_ki"]}}
                  for kd, e in sorted(estimates.items())]
        first = next(iter(estimates.values()))
        band = self.settings.get("band")
        attrs = {"title": "qzs design: transmissibility against the damping gain",
                 "source": f"qzs {__version__} (qzs design)", "fft_length": first.fft_length,
                 "n_averages": first.n_averages, "sample_rate": first.sample_rate,
                 "sample_rate_units": "Hz", "chosen_damping_gain": gains["damping_gain"],
                 "chosen_damping_gain_units": "N*s/m"}
        if band is not None:
            attrs.update({"band": np.asarray(band, dtype=float), "band_units": "Hz"})
        return curves_dataset(curves, attrs)

    def to_xarray(self) -> xr.Dataset | None:
        """The damping search's curves (:meth:`curves`): transmissibility [1] on ``case`` and
        ``frequency`` [Hz], the gains as coordinates with their units.

        Returns
        -------
        xarray.Dataset or None
            None when the search ran no simulation.
        """
        return self.curves()

    def _curves_to_save(self) -> xr.Dataset:
        curves = self.curves()
        if curves is None:
            raise DataError("this design's damping search ran no simulation (no admissible "
                            "damping gain), so it has no curves to write as .nc, .csv or "
                            ".mat; save it as .json or into a folder.")
        return curves

    #: The extensions :meth:`save` accepts (a path without one is a folder).
    save_suffixes = (".json", *DATASET_SUFFIXES)

    def save(self, path: str | Path, *, frequency_scale: str | None = None,
             progress: bool = False) -> Path:
        """Write the design atomically: ``.json`` (:meth:`to_dict`), ``.nc``, ``.csv`` or
        ``.mat`` (the damping search's curves, :meth:`curves`), or, for a path without an
        extension, the folder of ``report.html``, ``design.json``, the figures (PNG and
        SVG) and the curves (``damping_curves.nc``, ``.csv`` and ``.mat``).

        Each file is written atomically (a temporary file renamed onto it).

        Parameters
        ----------
        path : str or Path
            A file of :attr:`save_suffixes`, or the output folder (no extension; created
            if missing).
        frequency_scale : {"log", "linear"}, optional
            Frequency axis of the transmissibility figure; default
            ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
        progress : bool
            Show a progress bar: a step for the drawing, then one per file.

        Returns
        -------
        Path
            The folder (:func:`write_design` says which file is which).
        """
        if Path(path).suffix and not Path(path).is_dir():
            return save_by_extension(path, dataset=self._curves_to_save, record=self.to_dict)
        return write_design(self, path, frequency_scale=frequency_scale,
                            progress=progress)["report"].parent


def write_design(result: DesignResult, folder: str | Path, *,
                 frequency_scale: str | None = None, progress: bool = False) -> dict[str, Path]:
    """Write what :meth:`DesignResult.save` writes; return each file by its role.

    Parameters
    ----------
    result : DesignResult
        The design.
    folder : str or Path
        The output folder, created if missing.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the transmissibility figure; default
        ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    progress : bool
        Show a progress bar: a step for the drawing, then one per file.

    Returns
    -------
    dict of str to Path
        ``report``, ``json``, one entry per figure (its PNG) and ``curves_nc``,
        ``curves_csv`` (when the damping search simulated).
    """
    import matplotlib.pyplot as plt

    from qzs.engine.progress import progress_bar
    from qzs.iotools.paths import check_output_path
    from qzs.viz.design import plot_design
    from qzs.viz.figures import save_figure

    folder = check_output_path(folder, argument="folder", suffixes=None, directory=True)
    folder.mkdir(parents=True, exist_ok=True)
    written = {}
    with progress_bar(total=None, unit="part", desc="figures and report",
                      disable=not progress, leave=False) as bar:
        figures = plot_design(result, frequency_scale=frequency_scale)
        bar.total = 1 + len(figures) + 3  # the drawing, each figure, curves, json, report
        bar.update(1)
        for name, figure in figures.items():
            path = folder / f"{name}.png"
            save_figure(figure, path, also_svg=True)
            plt.close(figure)
            written[name] = path
            bar.update(1)
        curves = result.curves()
        if curves is not None:
            for path in write_curves(curves, folder, "damping"):
                written[f"curves_{path.suffix.lstrip('.')}"] = path
        bar.update(1)
        record = result.to_dict()
        with atomic_path(folder / "design.json") as tmp:
            tmp.write_text(json_text(record), encoding="utf-8")
        written["json"] = folder / "design.json"
        bar.update(1)
        with atomic_path(folder / "report.html") as tmp:
            tmp.write_text(_html(result, record, written), encoding="utf-8")
        written["report"] = folder / "report.html"
        bar.update(1)
    return written
