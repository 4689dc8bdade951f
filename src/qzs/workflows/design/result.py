"""The design's result: the chosen gains with the evidence for each choice, and its files."""
from dataclasses import dataclass, field

from qzs._format import json_ready, json_text
from qzs._version import __version__
from qzs.iotools.files import atomic_path
from qzs.workflows.design.report import _html, design_text

__all__ = ["DesignResult"]


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
    static: object
    pi_search: dict
    stability: object
    hunting: dict
    damping: dict
    margins: dict
    why: dict
    verification: dict
    seconds: dict
    series: dict = field(default_factory=dict, repr=False)

    def to_dict(self):
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

    def summary(self):
        """The design in a few lines of text (what ``qzs design`` prints).

        Returns
        -------
        str
        """
        return design_text(self)

    def plot(self, frequency_scale=None):
        """Draw every figure of the design.

        Parameters
        ----------
        frequency_scale : {"log", "linear"}, optional
            Frequency axis of the transmissibility figure; default
            ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        dict of str to matplotlib.figure.Figure
            Figure name -> figure.
        """
        from qzs.viz.design import plot_design

        return plot_design(self, frequency_scale=frequency_scale)

    def save(self, folder, frequency_scale=None):
        """Write ``report.html``, ``design.json`` and the figures (PNG and SVG) into ``folder``.

        Each file is written atomically (a temporary file renamed onto it).

        Parameters
        ----------
        folder : str or Path
            The output folder, created if missing.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis of the transmissibility figure; default
            ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        dict of str to Path
            ``report``, ``json`` and one entry per figure (its PNG).
        """
        import matplotlib.pyplot as plt

        from qzs.iotools.paths import check_output_path
        from qzs.viz.design import plot_design
        from qzs.viz.figures import save_figure

        folder = check_output_path(folder, argument="folder", suffixes=None, directory=True)
        folder.mkdir(parents=True, exist_ok=True)
        written = {}
        for name, figure in plot_design(self, frequency_scale=frequency_scale).items():
            path = folder / f"{name}.png"
            save_figure(figure, path, also_svg=True)
            plt.close(figure)
            written[name] = path
        record = self.to_dict()
        with atomic_path(folder / "design.json") as tmp:
            tmp.write_text(json_text(record), encoding="utf-8")
        written["json"] = folder / "design.json"
        with atomic_path(folder / "report.html") as tmp:
            tmp.write_text(_html(self, record, written), encoding="utf-8")
        written["report"] = folder / "report.html"
        return written

